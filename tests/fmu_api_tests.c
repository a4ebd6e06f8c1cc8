/* dyadfmu: the FMI entry points of the RRT FMUs called directly, as an importer
 * does: the binaries are loaded with dlopen, the variable table comes from the
 * same generated file the FMUs are built from, and every reaction is compared
 * with the C core called on the same inputs.
 *
 * Usage: fmu_api_tests FMI2_BINARY FMI3_BINARY [test-name ...]
 */
#define _POSIX_C_SOURCE 200809L

#include <dlfcn.h>
#include <stdarg.h>
#include <stdlib.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "fmu_dyad.h"
#include "named_tests.h"

/* ---- the importer's side: a logger that keeps the last message ---------------- */

typedef struct log_book {
    int count;
    int last_status;
    char last[600];
} log_book;

static void fmi2_logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                        fmi2String category, fmi2String message, ...)
{
    log_book* book = (log_book*)env;
    va_list args;
    (void)name;
    (void)category;
    va_start(args, message);
    vsnprintf(book->last, sizeof book->last, message, args);
    va_end(args);
    book->last_status = status;
    ++book->count;
}

static void fmi3_logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                        fmi3String message)
{
    log_book* book = (log_book*)env;
    (void)category;
    snprintf(book->last, sizeof book->last, "%s", message);
    book->last_status = status;
    ++book->count;
}

/* ---- loading ----------------------------------------------------------------- */

typedef struct fmi2_api {
    void* library;
    fmi2InstantiateTYPE* instantiate;
    fmi2FreeInstanceTYPE* free_instance;
    fmi2SetupExperimentTYPE* setup_experiment;
    fmi2EnterInitializationModeTYPE* enter_initialization;
    fmi2ExitInitializationModeTYPE* exit_initialization;
    fmi2DoStepTYPE* do_step;
    fmi2TerminateTYPE* terminate;
    fmi2ResetTYPE* reset;
    fmi2GetRealTYPE* get_real;
    fmi2SetRealTYPE* set_real;
    fmi2GetIntegerTYPE* get_integer;
    fmi2SetIntegerTYPE* set_integer;
    fmi2GetBooleanStatusTYPE* get_boolean_status;
    fmi2GetRealStatusTYPE* get_real_status;
    fmi2GetFMUstateTYPE* get_fmu_state;
} fmi2_api;

typedef struct fmi3_api {
    void* library;
    fmi3InstantiateCoSimulationTYPE* instantiate;
    fmi3InstantiateModelExchangeTYPE* instantiate_model_exchange;
    fmi3FreeInstanceTYPE* free_instance;
    fmi3EnterInitializationModeTYPE* enter_initialization;
    fmi3ExitInitializationModeTYPE* exit_initialization;
    fmi3DoStepTYPE* do_step;
    fmi3TerminateTYPE* terminate;
    fmi3ResetTYPE* reset;
    fmi3GetFloat64TYPE* get_float64;
    fmi3SetFloat64TYPE* set_float64;
    fmi3GetInt32TYPE* get_int32;
    fmi3GetBooleanTYPE* get_boolean;
    fmi3EnterEventModeTYPE* enter_event_mode;
} fmi3_api;

static int resolve(void* library, const char* name, void* function_pointer)
{
    void* symbol = dlsym(library, name);
    if (symbol == NULL) {
        printf("missing symbol %s\n", name);
        return 0;
    }
    memcpy(function_pointer, &symbol, sizeof symbol);
    return 1;
}

static int load_fmi2(const char* path, fmi2_api* api)
{
    int ok;
    api->library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (api->library == NULL) {
        printf("cannot load %s: %s\n", path, dlerror());
        return 0;
    }
    ok = resolve(api->library, "fmi2Instantiate", &api->instantiate) &
         resolve(api->library, "fmi2FreeInstance", &api->free_instance) &
         resolve(api->library, "fmi2SetupExperiment", &api->setup_experiment) &
         resolve(api->library, "fmi2EnterInitializationMode", &api->enter_initialization) &
         resolve(api->library, "fmi2ExitInitializationMode", &api->exit_initialization) &
         resolve(api->library, "fmi2DoStep", &api->do_step) &
         resolve(api->library, "fmi2Terminate", &api->terminate) &
         resolve(api->library, "fmi2Reset", &api->reset) &
         resolve(api->library, "fmi2GetReal", &api->get_real) &
         resolve(api->library, "fmi2SetReal", &api->set_real) &
         resolve(api->library, "fmi2GetInteger", &api->get_integer) &
         resolve(api->library, "fmi2SetInteger", &api->set_integer) &
         resolve(api->library, "fmi2GetBooleanStatus", &api->get_boolean_status) &
         resolve(api->library, "fmi2GetRealStatus", &api->get_real_status) &
         resolve(api->library, "fmi2GetFMUstate", &api->get_fmu_state);
    /* Nothing but the FMI API is exported. */
    if (dlsym(api->library, "dyad_solve_rrt") != NULL ||
        dlsym(api->library, "fmu_instantiate") != NULL) {
        printf("%s exports symbols beyond the FMI API\n", path);
        ok = 0;
    }
    return ok;
}

static int load_fmi3(const char* path, fmi3_api* api)
{
    api->library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (api->library == NULL) {
        printf("cannot load %s: %s\n", path, dlerror());
        return 0;
    }
    return resolve(api->library, "fmi3InstantiateCoSimulation", &api->instantiate) &
           resolve(api->library, "fmi3InstantiateModelExchange",
                   &api->instantiate_model_exchange) &
           resolve(api->library, "fmi3FreeInstance", &api->free_instance) &
           resolve(api->library, "fmi3EnterInitializationMode", &api->enter_initialization) &
           resolve(api->library, "fmi3ExitInitializationMode", &api->exit_initialization) &
           resolve(api->library, "fmi3DoStep", &api->do_step) &
           resolve(api->library, "fmi3Terminate", &api->terminate) &
           resolve(api->library, "fmi3Reset", &api->reset) &
           resolve(api->library, "fmi3GetFloat64", &api->get_float64) &
           resolve(api->library, "fmi3SetFloat64", &api->set_float64) &
           resolve(api->library, "fmi3GetInt32", &api->get_int32) &
           resolve(api->library, "fmi3GetBoolean", &api->get_boolean) &
           resolve(api->library, "fmi3EnterEventMode", &api->enter_event_mode);
}

static fmi2_api api2;
static fmi3_api api3;

/* ---- the model table ---------------------------------------------------------- */

static const fmu_variable* variable(const char* name)
{
    size_t k;
    for (k = 0; k < fmu_this_model.variable_count; ++k) {
        if (strcmp(fmu_this_model.variables[k].name, name) == 0) {
            return &fmu_this_model.variables[k];
        }
    }
    printf("no variable %s\n", name);
    return &fmu_this_model.variables[0];
}

static unsigned vr_of(const char* name)
{
    return variable(name)->vr;
}

/* The core's answer for the FMU's values (start values overridden by `set`). */
static dyad_result core_result(const unsigned vrs[], const double values[], size_t count)
{
    dyad_input in = dyad_input_default();
    dyad_result out;
    size_t k, j;
    for (k = 0; k < fmu_this_model.variable_count; ++k) {
        const fmu_variable* v = &fmu_this_model.variables[k];
        double value = v->start;
        char* member = (char*)&in + v->offset;
        for (j = 0; j < count; ++j) {
            if (vrs[j] == v->vr) {
                value = values[j];
            }
        }
        if (v->target == FMU_TARGET_INPUT_ANGLE) {
            ((dyad_vec2*)(void*)member)->x = cos(value);
            ((dyad_vec2*)(void*)member)->y = sin(value);
        } else if (v->target == FMU_TARGET_INPUT_REAL) {
            *(double*)(void*)member = value;
        }
    }
    ((const fmu_dyad_data*)fmu_this_model.data)->solve(&in, &out);
    return out;
}

/* Every Real output of the FMU against the core, bit for bit (NaN equals NaN). */
static int outputs_match(const double fmu_values[], const dyad_result* expected)
{
    size_t k, n = 0;
    for (k = 0; k < fmu_this_model.variable_count; ++k) {
        const fmu_variable* v = &fmu_this_model.variables[k];
        if (v->causality == FMU_OUTPUT && v->type == FMU_REAL) {
            const double want = *(const double*)(const void*)((const char*)expected + v->offset);
            const double got = fmu_values[n++];
            if (!(got == want || (isnan(got) && isnan(want)))) {
                printf("    %s = %.17g, core %.17g\n", v->name, got, want);
                return 0;
            }
        }
    }
    return 1;
}

static size_t real_outputs(unsigned vrs[])
{
    size_t k, n = 0;
    for (k = 0; k < fmu_this_model.variable_count; ++k) {
        const fmu_variable* v = &fmu_this_model.variables[k];
        if (v->causality == FMU_OUTPUT && v->type == FMU_REAL) {
            vrs[n++] = v->vr;
        }
    }
    return n;
}

/* ---- FMI 2 ---------------------------------------------------------------------- */

static fmi2Component new_fmi2(log_book* book, const char* name)
{
    fmi2CallbackFunctions callbacks;
    memset(&callbacks, 0, sizeof callbacks);
    callbacks.logger = fmi2_logger;
    callbacks.allocateMemory = calloc;
    callbacks.freeMemory = free;
    callbacks.componentEnvironment = book;
    return api2.instantiate(name, fmi2CoSimulation, fmu_this_model.token, "", &callbacks,
                            fmi2False, fmi2False);
}

static int initialise_fmi2(fmi2Component c)
{
    return api2.setup_experiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
           api2.enter_initialization(c) == fmi2OK && api2.exit_initialization(c) == fmi2OK;
}

static int test_fmi2_instances_independent(void)
{
    int fails = 0;
    log_book book_a = {0, 0, ""}, book_b = {0, 0, ""};
    fmi2Component a = new_fmi2(&book_a, "a");
    fmi2Component b = new_fmi2(&book_b, "b");
    const unsigned set_a[3] = {vr_of("link_n.angle"), vr_of("link_m.force.x"),
                               vr_of("link_n.omega")};
    const double val_a[3] = {0.3, -2500, 40};
    const double val_b[3] = {-0.5, 700, -15};
    unsigned outs[32];
    double got[32];
    const size_t n = real_outputs(outs);
    dyad_result want;
    int step;
    CHECK(a != NULL && b != NULL, "instantiate");
    CHECK(initialise_fmi2(a) && initialise_fmi2(b), "initialise");
    for (step = 0; step < 3; ++step) {
        CHECK(api2.set_real(a, set_a, 3, val_a) == fmi2OK, "set a");
        CHECK(api2.set_real(b, set_a, 3, val_b) == fmi2OK, "set b");
        CHECK(api2.do_step(a, step * 0.01, 0.01, fmi2True) == fmi2OK, "step a");
        CHECK(api2.do_step(b, step * 0.01, 0.01, fmi2True) == fmi2OK, "step b");
        CHECK(api2.get_real(a, outs, n, got) == fmi2OK, "get a");
        want = core_result(set_a, val_a, 3);
        CHECK(outputs_match(got, &want), "instance a differs from the core");
        CHECK(api2.get_real(b, outs, n, got) == fmi2OK, "get b");
        want = core_result(set_a, val_b, 3);
        CHECK(outputs_match(got, &want), "instance b differs from the core");
    }
    api2.free_instance(a);
    api2.free_instance(b);
    return fails;
}

static int test_fmi2_call_sequence(void)
{
    int fails = 0;
    log_book book = {0, 0, ""};
    fmi2Component c = new_fmi2(&book, "sequence");
    const unsigned mass = vr_of("link_m.mass");
    const unsigned out = vr_of("R_np.x");
    double value = 1;
    fmi2Boolean terminated;
    CHECK(api2.do_step(c, 0, 0.1, fmi2True) == fmi2Error, "doStep before initialization");
    CHECK(strstr(book.last, "illegal call sequence") != NULL, "message: %s", book.last);
    CHECK(api2.get_real(c, &out, 1, &value) == fmi2Error, "get in Instantiated");
    CHECK(api2.exit_initialization(c) == fmi2Error, "exit before enter");
    CHECK(initialise_fmi2(c), "initialise");
    CHECK(api2.setup_experiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2Error,
          "setupExperiment after initialization");
    CHECK(api2.set_real(c, &mass, 1, &value) == fmi2Error, "fixed parameter in step mode");
    CHECK(strstr(book.last, "link_m.mass") != NULL, "message names the parameter: %s", book.last);
    CHECK(api2.set_real(c, &out, 1, &value) == fmi2Error, "setting an output");
    CHECK(api2.do_step(c, 0, 0, fmi2True) == fmi2Error, "zero step size");
    CHECK(api2.do_step(c, 0, 0.1, fmi2True) == fmi2OK, "doStep");
    CHECK(api2.get_boolean_status(c, fmi2Terminated, &terminated) == fmi2OK && !terminated,
          "terminated status");
    CHECK(api2.get_fmu_state(c, NULL) == fmi2Error, "FMU state is not supported");
    CHECK(api2.terminate(c) == fmi2OK, "terminate");
    CHECK(api2.get_real(c, &out, 1, &value) == fmi2OK, "get after terminate");
    CHECK(api2.do_step(c, 0.1, 0.1, fmi2True) == fmi2Error, "doStep after terminate");
    CHECK(api2.terminate(c) == fmi2Error, "terminate twice");
    CHECK(api2.reset(c) == fmi2OK && initialise_fmi2(c), "reset and initialise again");
    CHECK(api2.do_step(NULL, 0, 0.1, fmi2True) == fmi2Error, "NULL instance");
    CHECK(api2.get_real(c, NULL, 1, &value) == fmi2Error, "NULL value references");
    api2.free_instance(c);
    api2.free_instance(NULL);
    return fails;
}

static int test_fmi2_invalid_values(void)
{
    int fails = 0;
    log_book book = {0, 0, ""};
    fmi2Component c = new_fmi2(&book, "100% %s %n");
    const unsigned force = vr_of("link_m.force.x");
    const unsigned mass = vr_of("link_n.mass");
    const unsigned length = vr_of("link_n.length");
    const unsigned status_vr = vr_of("status");
    const unsigned pair[2] = {vr_of("link_n.omega"), vr_of("link_n.epsilon")};
    const double pair_values[2] = {12, NAN};
    double value;
    int status;
    CHECK(c != NULL, "instantiate with '%%' in the name");
    value = -1;
    CHECK(api2.set_real(c, &mass, 1, &value) == fmi2Error, "negative mass");
    CHECK(strstr(book.last, "link_n.mass") != NULL && strstr(book.last, "-1") != NULL,
          "message names variable and value: %s", book.last);
    value = 0;
    CHECK(api2.set_real(c, &length, 1, &value) == fmi2Error, "zero rod length");
    CHECK(api2.set_real(c, pair, 2, pair_values) == fmi2Error, "NaN input");
    CHECK(strstr(book.last, "link_n.epsilon") != NULL, "message: %s", book.last);
    CHECK(initialise_fmi2(c), "initialise after rejected values");
    CHECK(api2.get_real(c, pair, 1, &value) == fmi2OK && value == variable("link_n.omega")->start,
          "a rejected call changes nothing: omega = %g", value);
    value = INFINITY;
    CHECK(api2.set_real(c, &force, 1, &value) == fmi2Error, "infinite force");
    value = 99;
    CHECK(api2.set_real(c, (const unsigned[]){9999}, 1, &value) == fmi2Error, "unknown vr");
    CHECK(strstr(book.last, "9999") != NULL, "message names the vr: %s", book.last);
    CHECK(api2.get_integer(c, &force, 1, &status) == fmi2Error, "Real vr read as Integer");
    CHECK(api2.do_step(c, 0, 0.01, fmi2True) == fmi2OK, "usable after the errors");
    CHECK(api2.get_integer(c, &status_vr, 1, &status) == fmi2OK && status == 0, "status %d",
          status);
    api2.free_instance(c);
    return fails;
}

static int test_fmi2_singular(void)
{
    int fails = 0;
    log_book book = {0, 0, ""};
    fmi2Component c = new_fmi2(&book, "singular");
    const unsigned rod = vr_of("link_n.angle");
    const unsigned status_vr = vr_of("status");
    const double normal = 1.5707963267948966; /* rod normal to the guide */
    const double fine = 0.4;
    unsigned outs[32];
    double got[32], last_time;
    const size_t n = real_outputs(outs);
    fmi2Boolean terminated;
    int status;
    size_t k;
    CHECK(initialise_fmi2(c), "initialise");
    CHECK(api2.do_step(c, 0, 0.01, fmi2True) == fmi2OK, "first step");
    CHECK(api2.set_real(c, &rod, 1, &normal) == fmi2OK, "set");
    CHECK(api2.do_step(c, 0.01, 0.01, fmi2True) == fmi2Discard, "singular step discarded");
    CHECK(book.last_status == fmi2Discard && strstr(book.last, "singular") != NULL,
          "logged reason: %s", book.last);
    CHECK(api2.get_real_status(c, fmi2LastSuccessfulTime, &last_time) == fmi2OK &&
              last_time == 0.01,
          "last successful time %g", last_time);
    CHECK(api2.get_boolean_status(c, fmi2Terminated, &terminated) == fmi2OK && terminated,
          "asks to terminate");
    api2.get_real(c, outs, n, got);
    for (k = 0; k < 6; ++k) {
        CHECK(isnan(got[k]), "reaction %zu = %g, expected NaN", k, got[k]);
    }
    CHECK(api2.get_integer(c, &status_vr, 1, &status) == fmi2OK && status == 1, "status %d",
          status);
    CHECK(api2.set_real(c, &rod, 1, &fine) == fmi2OK &&
              api2.do_step(c, 0.01, 0.01, fmi2True) == fmi2OK,
          "usable again once the input is fixed");
    api2.free_instance(c);
    return fails;
}

static int test_fmi2_wrong_token(void)
{
    int fails = 0;
    log_book book = {0, 0, ""};
    fmi2CallbackFunctions callbacks;
    memset(&callbacks, 0, sizeof callbacks);
    callbacks.logger = fmi2_logger;
    callbacks.componentEnvironment = &book;
    CHECK(api2.instantiate("x", fmi2CoSimulation, "{not-this-fmu}", "", &callbacks, 0, 0) == NULL,
          "wrong token accepted");
    CHECK(strstr(book.last, "token") != NULL, "message: %s", book.last);
    CHECK(api2.instantiate("x", fmi2ModelExchange, fmu_this_model.token, "", &callbacks, 0, 0) ==
              NULL,
          "model exchange accepted");
    CHECK(api2.instantiate("x", fmi2CoSimulation, fmu_this_model.token, "", NULL, 0, 0) == NULL,
          "NULL callbacks accepted");
    return fails;
}

/* The call-sequence rules of FMI 2.0 co-simulation, written out from the
 * standard's state machine (not from the FMU's table): for every state and
 * operation, whether the call is legal. */
enum { S_INSTANTIATED, S_INITIALIZATION, S_STEP, S_TERMINATED, STATE_COUNT };
static const char* const state_names[STATE_COUNT] = {"Instantiated", "Initialization",
                                                     "Step", "Terminated"};

typedef struct call_rule {
    const char* name;
    int legal[STATE_COUNT];
} call_rule;

static const call_rule fmi2_rules[] = {
    {"fmi2SetupExperiment", {1, 0, 0, 0}},
    {"fmi2EnterInitializationMode", {1, 0, 0, 0}},
    {"fmi2ExitInitializationMode", {0, 1, 0, 0}},
    {"fmi2DoStep", {0, 0, 1, 0}},
    {"fmi2Terminate", {0, 0, 1, 0}},
    {"fmi2GetReal (output)", {0, 1, 1, 1}},
    {"fmi2SetReal (input)", {1, 1, 1, 0}},
    {"fmi2SetReal (fixed parameter)", {1, 1, 0, 0}},
    {"fmi2GetBooleanStatus", {0, 0, 1, 1}},
    {"fmi2Reset", {1, 1, 1, 1}},
};

static fmi2Component fmi2_in_state(log_book* book, int state)
{
    fmi2Component c = new_fmi2(book, "states");
    if (state >= S_INITIALIZATION) {
        api2.setup_experiment(c, fmi2False, 0, 0, fmi2False, 0);
        api2.enter_initialization(c);
    }
    if (state >= S_STEP) {
        api2.exit_initialization(c);
    }
    if (state >= S_TERMINATED) {
        api2.terminate(c);
    }
    return c;
}

static fmi2Status fmi2_call(fmi2Component c, size_t rule)
{
    const unsigned output = vr_of("R_mk.x"), input = vr_of("link_m.omega");
    const unsigned parameter = vr_of("link_n.com.x");
    double value = 0.5;
    fmi2Boolean flag;
    switch (rule) {
    case 0: return api2.setup_experiment(c, fmi2False, 0, 0, fmi2False, 0);
    case 1: return api2.enter_initialization(c);
    case 2: return api2.exit_initialization(c);
    case 3: return api2.do_step(c, 0, 0.01, fmi2True);
    case 4: return api2.terminate(c);
    case 5: return api2.get_real(c, &output, 1, &value);
    case 6: return api2.set_real(c, &input, 1, &value);
    case 7: return api2.set_real(c, &parameter, 1, &value);
    case 8: return api2.get_boolean_status(c, fmi2Terminated, &flag);
    case 9: return api2.reset(c);
    }
    return fmi2Fatal;
}

static int test_fmi2_state_machine(void)
{
    int fails = 0, state;
    size_t rule;
    for (state = 0; state < STATE_COUNT; ++state) {
        for (rule = 0; rule < sizeof fmi2_rules / sizeof fmi2_rules[0]; ++rule) {
            log_book book = {0, 0, ""};
            fmi2Component c = fmi2_in_state(&book, state);
            const fmi2Status status = fmi2_call(c, rule);
            if (fmi2_rules[rule].legal[state]) {
                CHECK(status == fmi2OK, "%s in %s: status %d, expected OK (%s)",
                      fmi2_rules[rule].name, state_names[state], status, book.last);
            } else {
                CHECK(status == fmi2Error && book.last[0] != '\0',
                      "%s in %s: status %d, expected Error with a message (%s)",
                      fmi2_rules[rule].name, state_names[state], status, book.last);
            }
            api2.free_instance(c);
        }
    }
    return fails;
}

/* ---- FMI 3 ---------------------------------------------------------------------- */

static fmi3Instance new_fmi3(log_book* book, const char* name)
{
    return api3.instantiate(name, fmu_this_model.token, NULL, fmi3False, fmi3False, fmi3False,
                            fmi3False, NULL, 0, book, fmi3_logger, NULL);
}

static int test_fmi3_cosimulation(void)
{
    int fails = 0;
    log_book book = {0, 0, ""};
    fmi3Instance a = new_fmi3(&book, "a");
    fmi3Instance b = new_fmi3(&book, "b");
    const unsigned set[2] = {vr_of("link_n.angle"), vr_of("link_m.accel_d.x")};
    const double val_a[2] = {0.25, -900};
    const double val_b[2] = {2.9, 300};
    unsigned outs[32];
    double got[32];
    const size_t n = real_outputs(outs);
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    dyad_result want;
    CHECK(a != NULL && b != NULL, "instantiate");
    CHECK(api3.enter_initialization(a, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
              api3.exit_initialization(a) == fmi3OK,
          "initialise a");
    CHECK(api3.enter_initialization(b, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
              api3.exit_initialization(b) == fmi3OK,
          "initialise b");
    CHECK(api3.set_float64(a, set, 2, val_a, 2) == fmi3OK, "set a");
    CHECK(api3.set_float64(b, set, 2, val_b, 2) == fmi3OK, "set b");
    CHECK(api3.set_float64(a, set, 2, val_a, 1) == fmi3Error, "nValues != nValueReferences");
    CHECK(api3.do_step(a, 0, 0.01, fmi3True, &event, &terminate, &early, &last) == fmi3OK &&
              !terminate && last == 0.01,
          "step a");
    CHECK(api3.do_step(b, 0, 0.01, fmi3True, &event, &terminate, &early, &last) == fmi3OK,
          "step b");
    CHECK(api3.get_float64(a, outs, n, got, n) == fmi3OK, "get a");
    want = core_result(set, val_a, 2);
    CHECK(outputs_match(got, &want), "instance a differs from the core");
    CHECK(api3.get_float64(b, outs, n, got, n) == fmi3OK, "get b");
    want = core_result(set, val_b, 2);
    CHECK(outputs_match(got, &want), "instance b differs from the core");
    CHECK(api3.get_boolean(a, outs, 1, &event, 1) == fmi3Error, "no Boolean variables");
    CHECK(api3.enter_event_mode(a) == fmi3Error, "no event mode");
    CHECK(api3.terminate(a) == fmi3OK && api3.terminate(a) == fmi3Error, "terminate once");
    CHECK(api3.reset(a) == fmi3OK, "reset");
    CHECK(api3.do_step(a, 0, 0.01, fmi3True, &event, &terminate, &early, &last) == fmi3Error,
          "doStep after reset needs initialization");
    api3.free_instance(a);
    api3.free_instance(b);
    return fails;
}

static int test_fmi3_singular_and_invalid(void)
{
    int fails = 0;
    log_book book = {0, 0, ""};
    fmi3Instance c = new_fmi3(&book, "c");
    const unsigned rod = vr_of("link_n.angle");
    const unsigned inertia = vr_of("link_m.inertia");
    const unsigned status_vr = vr_of("status");
    const double normal = -1.5707963267948966, negative = -0.5;
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    fmi3Int32 status;
    CHECK(api3.set_float64(c, &inertia, 1, &negative, 1) == fmi3Error &&
              strstr(book.last, "link_m.inertia") != NULL,
          "negative inertia: %s", book.last);
    CHECK(api3.enter_initialization(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
              api3.exit_initialization(c) == fmi3OK,
          "initialise");
    CHECK(api3.set_float64(c, &rod, 1, &normal, 1) == fmi3OK, "set");
    CHECK(api3.do_step(c, 0, 0.01, fmi3True, &event, &terminate, &early, &last) == fmi3Discard &&
              terminate && last == 0,
          "singular step");
    CHECK(strstr(book.last, "singular") != NULL, "logged: %s", book.last);
    CHECK(api3.get_int32(c, &status_vr, 1, &status, 1) == fmi3OK && status == 1, "status %d",
          (int)status);
    CHECK(api3.instantiate("x", "{wrong}", NULL, 0, 0, 0, 0, NULL, 0, &book, fmi3_logger,
                           NULL) == NULL,
          "wrong token accepted");
    CHECK(api3.instantiate_model_exchange("x", fmu_this_model.token, NULL, 0, 0, &book,
                                          fmi3_logger) == NULL,
          "model exchange accepted");
    api3.free_instance(c);
    return fails;
}

/* The same for FMI 3.0 co-simulation without event mode. */
static const call_rule fmi3_rules[] = {
    {"fmi3EnterInitializationMode", {1, 0, 0, 0}},
    {"fmi3ExitInitializationMode", {0, 1, 0, 0}},
    {"fmi3DoStep", {0, 0, 1, 0}},
    {"fmi3Terminate", {0, 0, 1, 0}},
    {"fmi3GetFloat64 (output)", {0, 1, 1, 1}},
    {"fmi3SetFloat64 (input)", {1, 1, 1, 0}},
    {"fmi3SetFloat64 (fixed parameter)", {1, 1, 0, 0}},
    {"fmi3Reset", {1, 1, 1, 1}},
};

static fmi3Instance fmi3_in_state(log_book* book, int state)
{
    fmi3Instance c = new_fmi3(book, "states");
    if (state >= S_INITIALIZATION) {
        api3.enter_initialization(c, fmi3False, 0, 0, fmi3False, 0);
    }
    if (state >= S_STEP) {
        api3.exit_initialization(c);
    }
    if (state >= S_TERMINATED) {
        api3.terminate(c);
    }
    return c;
}

static fmi3Status fmi3_call(fmi3Instance c, size_t rule)
{
    const unsigned output = vr_of("R_mk.x"), input = vr_of("link_m.omega");
    const unsigned parameter = vr_of("link_n.com.x");
    double value = 0.5;
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    switch (rule) {
    case 0: return api3.enter_initialization(c, fmi3False, 0, 0, fmi3False, 0);
    case 1: return api3.exit_initialization(c);
    case 2: return api3.do_step(c, 0, 0.01, fmi3True, &event, &terminate, &early, &last);
    case 3: return api3.terminate(c);
    case 4: return api3.get_float64(c, &output, 1, &value, 1);
    case 5: return api3.set_float64(c, &input, 1, &value, 1);
    case 6: return api3.set_float64(c, &parameter, 1, &value, 1);
    case 7: return api3.reset(c);
    }
    return fmi3Fatal;
}

static int test_fmi3_state_machine(void)
{
    int fails = 0, state;
    size_t rule;
    for (state = 0; state < STATE_COUNT; ++state) {
        for (rule = 0; rule < sizeof fmi3_rules / sizeof fmi3_rules[0]; ++rule) {
            log_book book = {0, 0, ""};
            fmi3Instance c = fmi3_in_state(&book, state);
            const fmi3Status status = fmi3_call(c, rule);
            if (fmi3_rules[rule].legal[state]) {
                CHECK(status == fmi3OK, "%s in %s: status %d, expected OK (%s)",
                      fmi3_rules[rule].name, state_names[state], status, book.last);
            } else {
                CHECK(status == fmi3Error && book.last[0] != '\0',
                      "%s in %s: status %d, expected Error with a message (%s)",
                      fmi3_rules[rule].name, state_names[state], status, book.last);
            }
            api3.free_instance(c);
        }
    }
    return fails;
}

/* ---- runner --------------------------------------------------------------------- */

static const named_test tests[] = {
    {"fmi2_instances_independent", test_fmi2_instances_independent},
    {"fmi2_call_sequence", test_fmi2_call_sequence},
    {"fmi2_invalid_values", test_fmi2_invalid_values},
    {"fmi2_singular", test_fmi2_singular},
    {"fmi2_wrong_token", test_fmi2_wrong_token},
    {"fmi2_state_machine", test_fmi2_state_machine},
    {"fmi3_cosimulation", test_fmi3_cosimulation},
    {"fmi3_singular_and_invalid", test_fmi3_singular_and_invalid},
    {"fmi3_state_machine", test_fmi3_state_machine},
};

int main(int argc, char** argv)
{
    int failed;
    if (argc < 3) {
        printf("usage: fmu_api_tests FMI2_BINARY FMI3_BINARY [test-name ...]\n");
        return 2;
    }
    if (!load_fmi2(argv[1], &api2) || !load_fmi3(argv[2], &api3)) {
        printf("0 passed, 1 failed\n");
        return 1;
    }
    failed = run_named_tests(tests, sizeof tests / sizeof tests[0], fmu_this_model.identifier,
                             argv + 3, argc - 3);
    dlclose(api2.library);
    dlclose(api3.library);
    return failed == 0 ? 0 : 1;
}
