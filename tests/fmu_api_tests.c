/* dyadfmu: the FMI misuse matrix, on every FMU the build makes (a generic dyad,
 * a tailored scene, the drive): the FMI 2 and FMI 3 entry points called
 * directly, as an importer does, on the extracted FMU (model description and
 * binary, loaded with dlopen; tests/fmu_probe.c):
 *
 *   - every entry point in every state of the co-simulation state machine,
 *     against the standard's rules written out below;
 *   - NULL arguments the standard allows (accepted) and those it does not
 *     (Error, with a message where there is an instance to log through);
 *   - value references of the wrong type, unknown ones, FMI 3's nValues that
 *     does not match nValueReferences, and values outside the declared bounds:
 *     Error with a message, and nothing changes;
 *   - reset restores the start values, instances are independent.
 *
 * For the RRT FMUs the outputs are also compared with the C core on the same
 * inputs (the variable table of the same generated file the FMUs are built from).
 *
 * Usage: fmu_api_tests FMI2_FMU_DIR FMI3_FMU_DIR [test-name ...]
 */
#define _POSIX_C_SOURCE 200809L

#include <dlfcn.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dyadfmu/angle.h"
#include "fmu_dyad.h"
#include "fmu_probe.h"

/* Every entry of the matrix is one CHECK; counted so that a run says how many
 * it checked. */
static long checks_run;
#define NAMED_TESTS_ON_CHECK() (++checks_run)
#include "named_tests.h"

static probe_model md2, md3;
static probe_fmi2 api2;
static probe_fmi3 api3;

/* ---- what each test needs of a model -------------------------------------------------------- */

/* A variable of each role the calls below need; NULL where the model has none. */
typedef struct picks {
    const probe_variable* output;    /* a Real output */
    const probe_variable* input;     /* a Real input */
    const probe_variable* parameter; /* a fixed Real parameter */
    const probe_variable* status;    /* the Integer output `status` */
} picks;

static picks pick(const probe_model* md)
{
    picks p = {NULL, NULL, NULL, NULL};
    size_t k;
    for (k = 0; k < md->variable_count; ++k) {
        const probe_variable* v = &md->variables[k];
        if (v->type == PROBE_REAL && v->causality == PROBE_OUTPUT && p.output == NULL) {
            p.output = v;
        } else if (v->type == PROBE_REAL && v->causality == PROBE_INPUT && p.input == NULL) {
            p.input = v;
        } else if (v->type == PROBE_REAL && v->causality == PROBE_PARAMETER &&
                   v->variability == PROBE_FIXED && p.parameter == NULL) {
            p.parameter = v;
        } else if (v->type == PROBE_INTEGER && v->causality == PROBE_OUTPUT &&
                   strcmp(v->name, "status") == 0) {
            p.status = v;
        }
    }
    return p;
}

/* A value inside the bounds that differs from the start value. */
static double other_value(const probe_variable* v)
{
    double x = (v->has_start ? v->start : 0.0) + 0.375;
    if (v->has_max && x > v->max) {
        x = v->has_min ? 0.5 * (v->min + v->max) : v->max - 0.375;
    }
    return x;
}

static int logged_error(const probe_log_book* book, long count_before)
{
    return book->count > count_before && book->last_status == 3 && book->last[0] != '\0';
}

static int is_real_setting(const probe_variable* v)
{
    return v->type == PROBE_REAL &&
           (v->causality == PROBE_INPUT || v->causality == PROBE_PARAMETER);
}

/* ---- FMI 2 ---------------------------------------------------------------------------------- */

static fmi2Component new_fmi2(probe_log_book* book, const char* name)
{
    fmi2CallbackFunctions callbacks = probe_fmi2_callbacks(book);
    probe_log_book_clear(book);
    return api2.Instantiate(name, fmi2CoSimulation, md2.token, "", &callbacks, fmi2False,
                            fmi2False);
}

static int initialise_fmi2(fmi2Component c)
{
    return api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
           api2.EnterInitializationMode(c) == fmi2OK && api2.ExitInitializationMode(c) == fmi2OK;
}

/* The states of FMI 2.0 co-simulation (section 4.2.4), as reached here:
 * stepFailed after a doStep that returned Discard, error after one that
 * returned Error (a step size of -1). */
enum { S_INSTANTIATED, S_INITIALIZATION, S_STEP, S_FAILED, S_ERROR, S_TERMINATED, STATE_COUNT };
static const char* const state_names[STATE_COUNT] = {"Instantiated", "Initialization",
                                                     "StepComplete", "StepFailed/Discarded",
                                                     "Error",        "Terminated"};

/* Inputs all at one extreme value: a doStep that the model cannot complete
 * (the reactions or the state overflow) and must discard. Returns 1 if found. */
static const double extremes[] = {DBL_MAX, -DBL_MAX, 1e300, -1e300};

/* An input and an extreme value of it that make the step from 0 to 0.01 s one the
 * model cannot complete, left set; 1 if found. */
static int fmi2_find_discard(fmi2Component c, unsigned* vr, double* value)
{
    size_t e, k;
    for (k = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        if (v->type != PROBE_REAL || v->causality != PROBE_INPUT) {
            continue;
        }
        for (e = 0; e < sizeof extremes / sizeof extremes[0]; ++e) {
            api2.SetReal(c, &v->vr, 1, &extremes[e]);
            if (api2.DoStep(c, 0, 0.01, fmi2True) == fmi2Discard) {
                *vr = v->vr;
                *value = extremes[e];
                return 1;
            }
            /* back to the start values for the next try */
            if (api2.Reset(c) != 0 || !initialise_fmi2(c)) {
                return 0;
            }
        }
    }
    return 0;
}

/* A step the model cannot complete (fmi2_find_discard); 1 if found. */
static int fmi2_discard(fmi2Component c)
{
    unsigned vr;
    double value;
    return fmi2_find_discard(c, &vr, &value);
}

/* An instance in `state`, or NULL if this FMU cannot get there. */
static fmi2Component fmi2_in_state(probe_log_book* book, int state)
{
    fmi2Component c = new_fmi2(book, "states");
    int ok = c != NULL;
    if (ok && state >= S_INITIALIZATION) {
        ok = api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
             api2.EnterInitializationMode(c) == fmi2OK;
    }
    if (ok && state >= S_STEP) {
        ok = api2.ExitInitializationMode(c) == fmi2OK;
    }
    if (ok && state == S_FAILED) {
        ok = fmi2_discard(c);
    }
    if (ok && state == S_ERROR) {
        ok = api2.DoStep(c, 0, -1, fmi2True) == fmi2Error;
    }
    if (ok && state == S_TERMINATED) {
        ok = api2.Terminate(c) == fmi2OK;
    }
    if (!ok && c != NULL) {
        api2.FreeInstance(c);
        c = NULL;
    }
    probe_log_book_clear(book);
    return c;
}

/* What the standard says of a call in a state:
 *   L  legal: OK (a getter may warn that the model is singular, Warning);
 *   I  illegal: Error with an "illegal call sequence" message;
 *   P  a fixed parameter after initialization: Error with a message naming it;
 *   U  unsupported by this FMU (its capability flags say so): Error with a message;
 *   x  the standard forbids it after a failed step, the FMU allows it so that an
 *      importer can recover (README: "Once the inputs leave the singular position
 *      the next doStep succeeds"): OK, Discard or Error with a message. */
typedef struct call_rule {
    const char* name;
    const char* expect; /* one letter per state, in the order of state_names */
} call_rule;

static const call_rule fmi2_rules[] = {
    {"fmi2SetDebugLogging", "LLLLLL"},
    {"fmi2SetupExperiment", "LIIIII"},
    {"fmi2EnterInitializationMode", "LIIIII"},
    {"fmi2ExitInitializationMode", "ILIIII"},
    {"fmi2DoStep", "IILxxI"},
    {"fmi2Terminate", "IILLxI"},
    {"fmi2Reset", "LLLLLL"},
    {"fmi2GetReal (output)", "ILLLLL"},
    {"fmi2GetReal (input)", "ILLLLL"},
    {"fmi2GetInteger (status)", "ILLLLL"},
    {"fmi2GetBoolean (none)", "ILLLLL"},
    {"fmi2GetString (none)", "ILLLLL"},
    {"fmi2SetReal (input)", "LLLxxI"},
    {"fmi2SetReal (fixed parameter)", "LLPPPI"},
    {"fmi2SetInteger (none)", "LLLxxI"},
    {"fmi2SetBoolean (none)", "LLLxxI"},
    {"fmi2SetString (none)", "LLLxxI"},
    {"fmi2GetFMUstate", "LLLLLL"},
    {"fmi2SetFMUstate", "UUUUUU"},
    {"fmi2FreeFMUstate", "LLLLLL"},
    {"fmi2SerializedFMUstateSize", "UUUUUU"},
    {"fmi2SerializeFMUstate", "UUUUUU"},
    {"fmi2DeSerializeFMUstate", "UUUUUU"},
    {"fmi2GetDirectionalDerivative", "ILLxLL"},
    {"fmi2SetRealInputDerivatives", "LLLxxI"}, /* where the model interpolates */
    {"fmi2GetRealOutputDerivatives", "ILLxxL"},
    {"fmi2CancelStep", "UUUUUU"}, /* only while a step is pending, never here */
    {"fmi2GetStatus", "UUUUUU"},  /* only fmi2DoStepStatus, after fmi2Pending */
    {"fmi2GetRealStatus", "IILLxL"},
    {"fmi2GetIntegerStatus", "UUUUUU"},
    {"fmi2GetBooleanStatus", "IILLxL"},
    {"fmi2GetStringStatus", "UUUUUU"},
};
enum { FMI2_RULES = sizeof fmi2_rules / sizeof fmi2_rules[0] };

/* Calls entry point `rule` with valid arguments. Returns -1 where the model
 * lacks what the call needs (no parameter, no status output). */
static int fmi2_call(fmi2Component c, size_t rule, const picks* p)
{
    const fmi2ValueReference out = p->output->vr;
    const fmi2ValueReference in = p->input != NULL ? p->input->vr : 0;
    double value = p->input != NULL ? other_value(p->input) : 0, seed = 1, rate = 0, time = 0;
    fmi2Integer integer = 0, order = 1;
    fmi2Boolean flag = fmi2False;
    fmi2Status kind = fmi2OK;
    fmi2String string = NULL;
    fmi2FMUstate state = NULL;
    fmi2Byte bytes[8] = {0};
    size_t size = 0;
    switch (rule) {
    case 0: return api2.SetDebugLogging(c, fmi2True, 0, NULL);
    case 1: return api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0);
    case 2: return api2.EnterInitializationMode(c);
    case 3: return api2.ExitInitializationMode(c);
    case 4: return api2.DoStep(c, 0, 0.01, fmi2True);
    case 5: return api2.Terminate(c);
    case 6: return api2.Reset(c);
    case 7: return api2.GetReal(c, &out, 1, &value);
    case 8: return p->input != NULL ? (int)api2.GetReal(c, &in, 1, &value) : -1;
    case 9: return p->status != NULL ? (int)api2.GetInteger(c, &p->status->vr, 1, &integer) : -1;
    case 10: return api2.GetBoolean(c, NULL, 0, NULL);
    case 11: return api2.GetString(c, NULL, 0, NULL);
    case 12: return p->input != NULL ? (int)api2.SetReal(c, &in, 1, &value) : -1;
    case 13:
        if (p->parameter == NULL) {
            return -1;
        }
        value = other_value(p->parameter);
        return api2.SetReal(c, &p->parameter->vr, 1, &value);
    case 14: return api2.SetInteger(c, NULL, 0, NULL);
    case 15: return api2.SetBoolean(c, NULL, 0, NULL);
    case 16: return api2.SetString(c, NULL, 0, NULL);
    case 17: return api2.GetFMUstate(c, &state);
    case 18: return api2.SetFMUstate(c, state);
    case 19: return api2.FreeFMUstate(c, &state);
    case 20: return api2.SerializedFMUstateSize(c, state, &size);
    case 21: return api2.SerializeFMUstate(c, state, bytes, sizeof bytes);
    case 22: return api2.DeSerializeFMUstate(c, bytes, sizeof bytes, &state);
    case 23:
        return p->input != NULL
                   ? (int)api2.GetDirectionalDerivative(c, &out, 1, &in, 1, &seed, &rate)
                   : -1;
    case 24: return api2.SetRealInputDerivatives(c, &in, 1, &order, &rate);
    case 25: return api2.GetRealOutputDerivatives(c, &out, 1, &order, &rate);
    case 26: return api2.CancelStep(c);
    case 27: return api2.GetStatus(c, fmi2DoStepStatus, &kind);
    case 28: return api2.GetRealStatus(c, fmi2LastSuccessfulTime, &time);
    case 29: return api2.GetIntegerStatus(c, fmi2LastSuccessfulTime, &integer);
    case 30: return api2.GetBooleanStatus(c, fmi2Terminated, &flag);
    case 31: return api2.GetStringStatus(c, fmi2PendingStatus, &string);
    }
    return -2;
}

/* Checks one outcome against its expectation letter; returns 0 if it holds. */
static int judge(const char* call, const char* state, char expect, int status,
                 const probe_log_book* book, long count_before, const char* name)
{
    int fails = 0;
    switch (expect) {
    case 'L':
        CHECK(status == 0 || status == 1, "%s in %s: status %d, expected OK (%s)", call, state,
              status, book->last);
        break;
    case 'I':
        CHECK(status == 3 && logged_error(book, count_before) &&
                  strstr(book->last, "illegal call sequence") != NULL,
              "%s in %s: status %d, expected Error with an illegal call sequence message (%s)",
              call, state, status, book->last);
        break;
    case 'P':
        CHECK(status == 3 && logged_error(book, count_before) && name != NULL &&
                  strstr(book->last, name) != NULL,
              "%s in %s: status %d, expected Error naming %s (%s)", call, state, status,
              name != NULL ? name : "?", book->last);
        break;
    case 'U':
        CHECK(status == 3 && logged_error(book, count_before),
              "%s in %s: status %d, expected Error with a message (%s)", call, state, status,
              book->last);
        break;
    case 'x':
        CHECK(status == 0 || status == 2 || (status == 3 && logged_error(book, count_before)),
              "%s in %s: status %d, expected OK, Discard, or Error with a message (%s)", call,
              state, status, book->last);
        break;
    }
    return fails;
}

static int test_fmi2_state_machine(void)
{
    int fails = 0, state;
    const picks p = pick(&md2);
    size_t rule;
    long calls = 0;
    for (state = 0; state < STATE_COUNT; ++state) {
        probe_log_book probe;
        fmi2Component reachable = fmi2_in_state(&probe, state);
        if (reachable == NULL) {
            printf("    %s: no %s state (no input value makes a step fail)\n", md2.identifier,
                   state_names[state]);
            CHECK(state == S_FAILED, "cannot reach %s", state_names[state]);
            continue;
        }
        api2.FreeInstance(reachable);
        for (rule = 0; rule < FMI2_RULES; ++rule) {
            probe_log_book book;
            fmi2Component c = fmi2_in_state(&book, state);
            const int status = fmi2_call(c, rule, &p);
            char expect = fmi2_rules[rule].expect[state];
            if (rule == 23 && !md2.provides_directional_derivatives && expect != 'I') {
                expect = 'U';
            }
            if ((rule == 24 || rule == 25) && !md2.interpolates && expect != 'I') {
                expect = 'U';
            }
            if (status >= 0) {
                ++calls;
                fails += judge(fmi2_rules[rule].name, state_names[state], expect, status, &book, 0,
                               rule == 13 ? p.parameter->name : NULL);
            }
            api2.FreeInstance(c);
        }
    }
    printf("    %ld calls in %d states\n", calls, STATE_COUNT);
    return fails;
}

static int test_fmi2_null_instance(void)
{
    int fails = 0;
    fmi2Status s;
    fmi2Real r;
    fmi2Integer i;
    fmi2Boolean b;
    fmi2String str;
    CHECK(strcmp(api2.GetVersion(), "2.0") == 0, "fmi2GetVersion: %s", api2.GetVersion());
    CHECK(strcmp(api2.GetTypesPlatform(), "default") == 0, "fmi2GetTypesPlatform");
    api2.FreeInstance(NULL); /* ignored */
    CHECK(api2.SetDebugLogging(NULL, fmi2True, 0, NULL) == fmi2Error, "SetDebugLogging");
    CHECK(api2.SetupExperiment(NULL, 0, 0, 0, 0, 0) == fmi2Error, "SetupExperiment");
    CHECK(api2.EnterInitializationMode(NULL) == fmi2Error, "EnterInitializationMode");
    CHECK(api2.ExitInitializationMode(NULL) == fmi2Error, "ExitInitializationMode");
    CHECK(api2.Terminate(NULL) == fmi2Error, "Terminate");
    CHECK(api2.Reset(NULL) == fmi2Error, "Reset");
    CHECK(api2.GetReal(NULL, NULL, 0, NULL) == fmi2Error, "GetReal");
    CHECK(api2.GetInteger(NULL, NULL, 0, NULL) == fmi2Error, "GetInteger");
    CHECK(api2.GetBoolean(NULL, NULL, 0, NULL) == fmi2Error, "GetBoolean");
    CHECK(api2.GetString(NULL, NULL, 0, NULL) == fmi2Error, "GetString");
    CHECK(api2.SetReal(NULL, NULL, 0, NULL) == fmi2Error, "SetReal");
    CHECK(api2.SetInteger(NULL, NULL, 0, NULL) == fmi2Error, "SetInteger");
    CHECK(api2.SetBoolean(NULL, NULL, 0, NULL) == fmi2Error, "SetBoolean");
    CHECK(api2.SetString(NULL, NULL, 0, NULL) == fmi2Error, "SetString");
    CHECK(api2.GetFMUstate(NULL, NULL) == fmi2Error, "GetFMUstate");
    CHECK(api2.SetFMUstate(NULL, NULL) == fmi2Error, "SetFMUstate");
    CHECK(api2.FreeFMUstate(NULL, NULL) == fmi2Error, "FreeFMUstate");
    CHECK(api2.SerializedFMUstateSize(NULL, NULL, NULL) == fmi2Error, "SerializedFMUstateSize");
    CHECK(api2.SerializeFMUstate(NULL, NULL, NULL, 0) == fmi2Error, "SerializeFMUstate");
    CHECK(api2.DeSerializeFMUstate(NULL, NULL, 0, NULL) == fmi2Error, "DeSerializeFMUstate");
    CHECK(api2.GetDirectionalDerivative(NULL, NULL, 0, NULL, 0, NULL, NULL) == fmi2Error,
          "GetDirectionalDerivative");
    CHECK(api2.SetRealInputDerivatives(NULL, NULL, 0, NULL, NULL) == fmi2Error,
          "SetRealInputDerivatives");
    CHECK(api2.GetRealOutputDerivatives(NULL, NULL, 0, NULL, NULL) == fmi2Error,
          "GetRealOutputDerivatives");
    CHECK(api2.DoStep(NULL, 0, 0.1, fmi2True) == fmi2Error, "DoStep");
    CHECK(api2.CancelStep(NULL) == fmi2Error, "CancelStep");
    CHECK(api2.GetStatus(NULL, fmi2DoStepStatus, &s) == fmi2Error, "GetStatus");
    CHECK(api2.GetRealStatus(NULL, fmi2LastSuccessfulTime, &r) == fmi2Error, "GetRealStatus");
    CHECK(api2.GetIntegerStatus(NULL, fmi2LastSuccessfulTime, &i) == fmi2Error, "GetIntegerStatus");
    CHECK(api2.GetBooleanStatus(NULL, fmi2Terminated, &b) == fmi2Error, "GetBooleanStatus");
    CHECK(api2.GetStringStatus(NULL, fmi2PendingStatus, &str) == fmi2Error, "GetStringStatus");
    return fails;
}

static int test_fmi2_null_arguments(void)
{
    int fails = 0;
    probe_log_book book;
    const picks p = pick(&md2);
    fmi2CallbackFunctions callbacks = probe_fmi2_callbacks(&book);
    fmi2Component c;
    const char* no_category = NULL;
    double value = 0;
    long count;
    fmi2Real* no_reals = NULL;
    probe_log_book_clear(&book);
    /* allowed: no resources, no environment, no stepFinished */
    callbacks.componentEnvironment = NULL;
    c = api2.Instantiate("nulls", fmi2CoSimulation, md2.token, NULL, &callbacks, fmi2False,
                         fmi2False);
    CHECK(c != NULL, "fmuResourceLocation and componentEnvironment NULL refused");
    api2.FreeInstance(c);
    callbacks = probe_fmi2_callbacks(&book);
    CHECK(api2.Instantiate(NULL, fmi2CoSimulation, md2.token, "", &callbacks, 0, 0) == NULL &&
              book.count > 0,
          "NULL instance name accepted or not logged");
    CHECK(api2.Instantiate("x", fmi2CoSimulation, NULL, "", &callbacks, 0, 0) == NULL,
          "NULL GUID accepted");
    CHECK(api2.Instantiate("x", fmi2CoSimulation, md2.token, "", NULL, 0, 0) == NULL,
          "NULL callbacks accepted");
    c = new_fmi2(&book, "nulls");
    CHECK(api2.SetDebugLogging(c, fmi2True, 0, NULL) == fmi2OK, "no categories, NULL array");
    count = book.count;
    CHECK(api2.SetDebugLogging(c, fmi2True, 1, NULL) == fmi2Error && logged_error(&book, count),
          "one category, NULL array");
    count = book.count;
    CHECK(api2.SetDebugLogging(c, fmi2True, 1, &no_category) == fmi2Error &&
              logged_error(&book, count),
          "a NULL category");
    CHECK(api2.SetReal(c, NULL, 0, NULL) == fmi2OK, "SetReal of nothing with NULL arrays");
    CHECK(initialise_fmi2(c), "initialise");
    CHECK(api2.GetReal(c, NULL, 0, NULL) == fmi2OK, "GetReal of nothing with NULL arrays");
    CHECK(api2.GetInteger(c, NULL, 0, NULL) == fmi2OK, "GetInteger of nothing");
    if (md2.provides_directional_derivatives) {
        CHECK(api2.GetDirectionalDerivative(c, NULL, 0, NULL, 0, NULL, NULL) == fmi2OK,
              "GetDirectionalDerivative of nothing");
        count = book.count;
        CHECK(api2.GetDirectionalDerivative(c, &p.output->vr, 1, &p.input->vr, 1, NULL, &value) ==
                      fmi2Error &&
                  logged_error(&book, count),
              "GetDirectionalDerivative with a NULL seed");
    }
    count = book.count;
    CHECK(api2.GetReal(c, NULL, 1, &value) == fmi2Error && logged_error(&book, count),
          "GetReal with NULL value references");
    count = book.count;
    CHECK(api2.GetReal(c, &p.output->vr, 1, no_reals) == fmi2Error && logged_error(&book, count),
          "GetReal with a NULL value array");
    count = book.count;
    CHECK(p.input == NULL ||
              (api2.SetReal(c, &p.input->vr, 1, NULL) == fmi2Error && logged_error(&book, count)),
          "SetReal with a NULL value array");
    count = book.count;
    CHECK(p.status == NULL || (api2.GetInteger(c, &p.status->vr, 1, NULL) == fmi2Error &&
                               logged_error(&book, count)),
          "GetInteger with a NULL value array");
    CHECK(api2.DoStep(c, 0, 0.01, fmi2True) != fmi2Error, "step");
    count = book.count;
    CHECK(api2.GetRealStatus(c, fmi2LastSuccessfulTime, NULL) == fmi2Error &&
              logged_error(&book, count),
          "GetRealStatus into NULL");
    count = book.count;
    CHECK(api2.GetBooleanStatus(c, fmi2Terminated, NULL) == fmi2Error && logged_error(&book, count),
          "GetBooleanStatus into NULL");
    api2.FreeInstance(c);
    return fails;
}

/* Every Real and Integer variable read in one go, after initialization. */
typedef struct values_read {
    double reals[512];
    int integers[64];
    size_t n_reals, n_integers;
} values_read;

static int fmi2_read_all(fmi2Component c, values_read* r)
{
    fmi2ValueReference reals[512], integers[64];
    size_t k;
    r->n_reals = r->n_integers = 0;
    for (k = 0; k < md2.variable_count && r->n_reals < 512 && r->n_integers < 64; ++k) {
        if (md2.variables[k].type == PROBE_REAL) {
            reals[r->n_reals++] = md2.variables[k].vr;
        } else if (md2.variables[k].type == PROBE_INTEGER) {
            integers[r->n_integers++] = md2.variables[k].vr;
        }
    }
    return api2.GetReal(c, reals, r->n_reals, r->reals) <= fmi2Warning &&
           api2.GetInteger(c, integers, r->n_integers, r->integers) == fmi2OK;
}

static int same_values(const values_read* a, const values_read* b)
{
    size_t k;
    for (k = 0; k < a->n_reals; ++k) {
        if (probe_bits(a->reals[k]) != probe_bits(b->reals[k])) {
            return 0;
        }
    }
    for (k = 0; k < a->n_integers; ++k) {
        if (a->integers[k] != b->integers[k]) {
            return 0;
        }
    }
    return a->n_reals == b->n_reals && a->n_integers == b->n_integers;
}

static int test_fmi2_wrong_types_and_unknown_vrs(void)
{
    int fails = 0;
    probe_log_book book;
    fmi2Component c = new_fmi2(&book, "types");
    const picks p = pick(&md2);
    const fmi2ValueReference unknown[3] = {probe_unused_vr(&md2), UINT_MAX, 0};
    values_read before, after;
    double value = 1;
    fmi2Integer integer = 0;
    fmi2Boolean boolean = fmi2False;
    fmi2String string = "x";
    size_t k;
    long count;
    CHECK(initialise_fmi2(c) && fmi2_read_all(c, &before), "initialise");
    for (k = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        count = book.count;
        if (v->type == PROBE_REAL) {
            CHECK(api2.GetInteger(c, &v->vr, 1, &integer) == fmi2Error &&
                      logged_error(&book, count) && strstr(book.last, v->name) != NULL,
                  "Real %s read as Integer: %s", v->name, book.last);
            count = book.count;
            CHECK(api2.SetInteger(c, &v->vr, 1, &integer) == fmi2Error &&
                      logged_error(&book, count),
                  "Real %s set as Integer", v->name);
        } else if (v->type == PROBE_INTEGER || v->type == PROBE_ENUMERATION) {
            CHECK(api2.GetReal(c, &v->vr, 1, &value) == fmi2Error && logged_error(&book, count) &&
                      strstr(book.last, v->name) != NULL,
                  "Integer %s read as Real: %s", v->name, book.last);
            count = book.count;
            CHECK(api2.SetReal(c, &v->vr, 1, &value) == fmi2Error && logged_error(&book, count),
                  "Integer %s set as Real", v->name);
        }
        count = book.count;
        if (v->causality == PROBE_OUTPUT && v->type == PROBE_REAL) {
            CHECK(api2.SetReal(c, &v->vr, 1, &value) == fmi2Error && logged_error(&book, count) &&
                      strstr(book.last, v->name) != NULL,
                  "output %s set: %s", v->name, book.last);
        } else if (v->causality == PROBE_OUTPUT && v->type == PROBE_INTEGER) {
            CHECK(api2.SetInteger(c, &v->vr, 1, &integer) == fmi2Error &&
                      logged_error(&book, count) && strstr(book.last, v->name) != NULL,
                  "output %s set: %s", v->name, book.last);
        }
        count = book.count;
        CHECK(api2.GetBoolean(c, &v->vr, 1, &boolean) == fmi2Error && logged_error(&book, count),
              "%s read as Boolean", v->name);
        count = book.count;
        CHECK(api2.GetString(c, &v->vr, 1, &string) == fmi2Error && logged_error(&book, count),
              "%s read as String", v->name);
        count = book.count;
        CHECK(api2.SetBoolean(c, &v->vr, 1, &boolean) == fmi2Error && logged_error(&book, count),
              "%s set as Boolean", v->name);
        count = book.count;
        CHECK(api2.SetString(c, &v->vr, 1, &string) == fmi2Error && logged_error(&book, count),
              "%s set as String", v->name);
    }
    for (k = 0; k < 3; ++k) {
        char number[16];
        sprintf(number, "%u", unknown[k]);
        count = book.count;
        CHECK(api2.GetReal(c, &unknown[k], 1, &value) == fmi2Error && logged_error(&book, count) &&
                  strstr(book.last, number) != NULL,
              "unknown value reference %u read: %s", unknown[k], book.last);
        count = book.count;
        CHECK(api2.SetReal(c, &unknown[k], 1, &value) == fmi2Error && logged_error(&book, count),
              "unknown value reference %u set", unknown[k]);
        count = book.count;
        CHECK(api2.GetInteger(c, &unknown[k], 1, &integer) == fmi2Error &&
                  logged_error(&book, count),
              "unknown value reference %u read as Integer", unknown[k]);
    }
    if (p.input != NULL) {
        /* a good value and a bad reference in one call: neither is taken */
        const fmi2ValueReference pair[2] = {p.input->vr, unknown[0]};
        const double values[2] = {other_value(p.input), 1};
        CHECK(api2.SetReal(c, pair, 2, values) == fmi2Error, "a call with an unknown reference");
    }
    CHECK(fmi2_read_all(c, &after) && same_values(&before, &after),
          "a refused call changed a value");
    api2.FreeInstance(c);
    return fails;
}

/* NaN, infinities and values just outside the declared bounds of every input
 * and parameter: Error naming the variable, and nothing stored. */
static int test_fmi2_invalid_values(void)
{
    int fails = 0;
    probe_log_book book;
    fmi2Component c = new_fmi2(&book, "100% %s %n");
    values_read before, after;
    size_t k, j;
    long count;
    for (k = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        double bad[5] = {NAN, INFINITY, -INFINITY, 0, 0};
        size_t n = 3;
        if (!is_real_setting(v)) {
            continue;
        }
        if (v->has_min) {
            bad[n++] = nextafter(v->min, -INFINITY);
        }
        if (v->has_max) {
            bad[n++] = nextafter(v->max, INFINITY);
        }
        for (j = 0; j < n; ++j) {
            count = book.count;
            CHECK(api2.SetReal(c, &v->vr, 1, &bad[j]) == fmi2Error && logged_error(&book, count) &&
                      strstr(book.last, v->name) != NULL,
                  "%s = %g: %s", v->name, bad[j], book.last);
        }
    }
    CHECK(api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
              api2.EnterInitializationMode(c) == fmi2OK,
          "initialise after refused values");
    CHECK(fmi2_read_all(c, &before), "read");
    for (k = 0, j = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        if (v->type == PROBE_REAL) {
            CHECK(!is_real_setting(v) || !v->has_start ||
                      probe_bits(before.reals[j]) == probe_bits(v->start),
                  "%s = %.17g after refused values, start %.17g", v->name, before.reals[j],
                  v->start);
            ++j;
        }
    }
    CHECK(api2.ExitInitializationMode(c) <= fmi2Warning && fmi2_read_all(c, &after),
          "usable after the refusals");
    api2.FreeInstance(c);
    return fails;
}

/* The same set or get again (an importer's every step) keeps every check: a parameter
 * set in initialization is refused once it closes, an invalid value among valid ones
 * stores none of them (a repeated reference included), and a get reads the new values. */
static int test_fmi2_repeated_calls_keep_their_checks(void)
{
    int fails = 0;
    probe_log_book book;
    fmi2Component c = new_fmi2(&book, "repeated");
    unsigned inputs[4], parameter = 0;
    double values[4], got[4], before[4];
    size_t n = 0, k;
    int have_parameter = 0;
    for (k = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        if (v->type == PROBE_REAL && v->causality == PROBE_INPUT && n < 3) {
            inputs[n] = v->vr;
            values[n++] = other_value(v);
        } else if (v->type == PROBE_REAL && v->causality == PROBE_PARAMETER && !have_parameter) {
            parameter = v->vr;
            have_parameter = 1;
        }
    }
    if (n < 3 || !have_parameter) {
        api2.FreeInstance(c);
        return fails; /* a model without three inputs and a parameter */
    }
    inputs[n] = inputs[0]; /* a repeated reference */
    values[n++] = values[0];
    CHECK(api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
              api2.EnterInitializationMode(c) == fmi2OK,
          "initialise");
    for (k = 0; k < 2; ++k) {
        const double value = 0.5 + (double)k;
        CHECK(api2.SetReal(c, &parameter, 1, &value) == fmi2OK, "parameter set %zu", k);
    }
    CHECK(api2.ExitInitializationMode(c) <= fmi2Warning, "exit");
    CHECK(api2.SetReal(c, &parameter, 1, &(double){2.5}) == fmi2Error,
          "a closed parameter accepted by a repeated call");
    CHECK(api2.GetReal(c, &parameter, 1, got) == fmi2OK && got[0] == 1.5, "parameter %g", got[0]);
    for (k = 0; k < 3; ++k) {
        CHECK(api2.SetReal(c, inputs, n, values) == fmi2OK, "inputs set, round %zu", k);
        CHECK(api2.GetReal(c, inputs, n, got) == fmi2OK && got[1] == values[1] &&
                  got[n - 1] == values[0],
              "inputs read back, round %zu", k);
        values[1] += 0.125;
    }
    CHECK(api2.GetReal(c, inputs, n, before) == fmi2OK, "read");
    values[0] += 0.25;
    values[2] = NAN;
    CHECK(api2.SetReal(c, inputs, n, values) == fmi2Error, "NaN among valid values accepted");
    CHECK(api2.GetReal(c, inputs, n, got) == fmi2OK && memcmp(got, before, sizeof got) == 0,
          "a refused set changed a value");
    api2.FreeInstance(c);
    return fails;
}

/* The Real inputs (their values as read after initialization) and Real outputs of an
 * instance, for an importer's every step. */
typedef struct step_calls {
    fmi2ValueReference inputs[64], outputs[64];
    double values[64], got[64];
    size_t n_inputs, n_outputs;
} step_calls;

static int find_step_calls(fmi2Component c, step_calls* calls)
{
    size_t k;
    calls->n_inputs = calls->n_outputs = 0;
    for (k = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        if (v->type == PROBE_REAL && v->causality == PROBE_INPUT && calls->n_inputs < 64) {
            calls->inputs[calls->n_inputs++] = v->vr;
        } else if (v->type == PROBE_REAL && v->causality == PROBE_OUTPUT && calls->n_outputs < 64) {
            calls->outputs[calls->n_outputs++] = v->vr;
        }
    }
    return api2.GetReal(c, calls->inputs, calls->n_inputs, calls->values) == fmi2OK;
}

/* Sets, steps and gets `rounds` times (an importer's every step); 1 if each call says
 * OK, so that the repeated calls take their common path. */
static int step_rounds(fmi2Component c, step_calls* calls, int rounds, double* t)
{
    int ok = 1, k;
    for (k = 0; k < rounds; ++k, *t += 1e-3) {
        ok &= api2.SetReal(c, calls->inputs, calls->n_inputs, calls->values) == fmi2OK;
        ok &= api2.DoStep(c, *t, 1e-3, fmi2True) == fmi2OK;
        ok &= api2.GetReal(c, calls->outputs, calls->n_outputs, calls->got) == fmi2OK;
    }
    return ok;
}

/* A parameter set twice in initialization (the second time by the same call, as an
 * importer repeats it) leaves every value as one set of its last value does: the
 * states restart from it too. */
static int check_parameter_set_twice(const probe_variable* p)
{
    int fails = 0, exit_twice, exit_once;
    probe_log_book book;
    values_read twice, once;
    const double first = p->has_start ? p->start : 0.0, last = other_value(p);
    fmi2Component a = new_fmi2(&book, "twice"), b = new_fmi2(&book, "once");
    CHECK(api2.SetupExperiment(a, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
              api2.EnterInitializationMode(a) == fmi2OK &&
              api2.SetReal(a, &p->vr, 1, &first) == fmi2OK &&
              api2.SetReal(a, &p->vr, 1, &last) == fmi2OK,
          "%s set twice in initialization", p->name);
    CHECK(api2.SetupExperiment(b, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
              api2.EnterInitializationMode(b) == fmi2OK &&
              api2.SetReal(b, &p->vr, 1, &last) == fmi2OK,
          "%s set once in initialization", p->name);
    exit_twice = (int)api2.ExitInitializationMode(a);
    exit_once = (int)api2.ExitInitializationMode(b);
    CHECK(exit_twice == exit_once, "%s: exit %d after two sets, %d after one", p->name, exit_twice,
          exit_once);
    if (exit_twice <= fmi2Warning && exit_once <= fmi2Warning) {
        CHECK(fmi2_read_all(a, &twice) && fmi2_read_all(b, &once) && same_values(&twice, &once),
              "%s = %g set after %g: not the values of %g set once", p->name, last, first, last);
    }
    api2.FreeInstance(a);
    api2.FreeInstance(b);
    return fails;
}

/* What lets a set, get or doStep take its common path follows every change of the
 * instance: logCalls switched on logs each repeated call (and off, none); a state
 * restored from before initialization refuses a step and a get again; a parameter set
 * twice in initialization restarts the states as often. */
static int test_fmi2_common_paths_follow_the_instance(void)
{
    int fails = 0;
    probe_log_book book;
    const char* const calls_category[] = {"logCalls"};
    fmi2Component c = new_fmi2(&book, "paths");
    fmi2FMUstate before_initialization = NULL;
    step_calls calls;
    double t = 0;
    long count;
    size_t k;
    CHECK(api2.GetFMUstate(c, &before_initialization) == fmi2OK, "state before initialization");
    CHECK(initialise_fmi2(c) && find_step_calls(c, &calls), "initialise");
    CHECK(step_rounds(c, &calls, 3, &t), "steps");
    CHECK(api2.SetDebugLogging(c, fmi2True, 1, calls_category) == fmi2OK, "logCalls on");
    count = book.count;
    CHECK(step_rounds(c, &calls, 2, &t) && book.count >= count + 6,
          "logCalls on: %ld messages for 6 calls", book.count - count);
    CHECK(api2.SetDebugLogging(c, fmi2False, 1, calls_category) == fmi2OK, "logCalls off");
    count = book.count;
    CHECK(step_rounds(c, &calls, 2, &t) && book.count == count,
          "logCalls off: %ld messages for 6 calls", book.count - count);
    CHECK(api2.SetFMUstate(c, before_initialization) == fmi2OK, "state restored");
    CHECK(api2.DoStep(c, t, 1e-3, fmi2True) == fmi2Error,
          "a step accepted in the restored Instantiated state");
    CHECK(api2.GetReal(c, calls.outputs, calls.n_outputs, calls.got) == fmi2Error,
          "a get accepted in the restored Instantiated state");
    api2.FreeFMUstate(c, &before_initialization);
    api2.FreeInstance(c);
    for (k = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        if (v->type == PROBE_REAL && v->causality == PROBE_PARAMETER &&
            v->variability == PROBE_FIXED) {
            fails += check_parameter_set_twice(v);
        }
    }
    return fails;
}

/* Reset brings back every start value and the Instantiated state. */
static int test_fmi2_reset(void)
{
    int fails = 0;
    probe_log_book book;
    fmi2Component c = new_fmi2(&book, "reset");
    values_read fresh, again;
    size_t k;
    CHECK(api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
              api2.EnterInitializationMode(c) == fmi2OK && fmi2_read_all(c, &fresh),
          "read the start values");
    for (k = 0; k < md2.variable_count; ++k) {
        const probe_variable* v = &md2.variables[k];
        const double value = other_value(v);
        if (is_real_setting(v)) {
            CHECK(api2.SetReal(c, &v->vr, 1, &value) == fmi2OK, "set %s", v->name);
        }
    }
    CHECK(api2.ExitInitializationMode(c) != fmi2Error, "exit");
    api2.DoStep(c, 0, 0.01, fmi2True);
    CHECK(api2.Reset(c) == fmi2OK, "reset");
    CHECK(api2.GetReal(c, &md2.variables[0].vr, 1, &(double){0}) == fmi2Error,
          "reset leaves Instantiated, where nothing can be read");
    CHECK(api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
              api2.EnterInitializationMode(c) == fmi2OK && fmi2_read_all(c, &again),
          "initialise again");
    CHECK(same_values(&fresh, &again), "reset did not restore every start value");
    api2.FreeInstance(c);
    return fails;
}

static int test_fmi2_instantiate_refusals(void)
{
    int fails = 0;
    probe_log_book book;
    fmi2CallbackFunctions callbacks = probe_fmi2_callbacks(&book);
    probe_log_book_clear(&book);
    CHECK(api2.Instantiate("x", fmi2CoSimulation, "{not-this-fmu}", "", &callbacks, 0, 0) == NULL,
          "wrong GUID accepted");
    CHECK(strstr(book.last, "token") != NULL, "message: %s", book.last);
    probe_log_book_clear(&book);
    CHECK(api2.Instantiate("x", fmi2ModelExchange, md2.token, "", &callbacks, 0, 0) == NULL &&
              book.count == 1,
          "model exchange accepted");
    probe_log_book_clear(&book);
    CHECK(api2.Instantiate("", fmi2CoSimulation, md2.token, "", &callbacks, 0, 0) == NULL &&
              book.count == 1,
          "empty instance name accepted");
    return fails;
}

/* ---- FMI 3 ---------------------------------------------------------------------------------- */

static fmi3Instance new_fmi3(probe_log_book* book, const char* name)
{
    probe_log_book_clear(book);
    return api3.InstantiateCoSimulation(name, md3.token, NULL, fmi3False, fmi3False, fmi3False,
                                        fmi3False, NULL, 0, book, probe_fmi3_logger, NULL);
}

static fmi3Status step3(fmi3Instance c, double t, double h)
{
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    return api3.DoStep(c, t, h, fmi3True, &event, &terminate, &early, &last);
}

static int initialise_fmi3(fmi3Instance c)
{
    return api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
           api3.ExitInitializationMode(c) == fmi3OK;
}

static int fmi3_find_discard(fmi3Instance c, unsigned* vr, double* value)
{
    size_t e, k;
    for (k = 0; k < md3.variable_count; ++k) {
        const probe_variable* v = &md3.variables[k];
        if (v->type != PROBE_REAL || v->causality != PROBE_INPUT) {
            continue;
        }
        for (e = 0; e < sizeof extremes / sizeof extremes[0]; ++e) {
            api3.SetFloat64(c, &v->vr, 1, &extremes[e], 1);
            if (step3(c, 0, 0.01) == fmi3Discard) {
                *vr = v->vr;
                *value = extremes[e];
                return 1;
            }
            /* back to the start values for the next try */
            if (api3.Reset(c) != 0 || !initialise_fmi3(c)) {
                return 0;
            }
        }
    }
    return 0;
}

static int fmi3_discard(fmi3Instance c)
{
    unsigned vr;
    double value;
    return fmi3_find_discard(c, &vr, &value);
}

static fmi3Instance fmi3_in_state(probe_log_book* book, int state)
{
    fmi3Instance c = new_fmi3(book, "states");
    int ok = c != NULL;
    if (ok && state >= S_INITIALIZATION) {
        ok = api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK;
    }
    if (ok && state >= S_STEP) {
        ok = api3.ExitInitializationMode(c) == fmi3OK;
    }
    if (ok && state == S_FAILED) {
        ok = fmi3_discard(c);
    }
    if (ok && state == S_ERROR) {
        ok = step3(c, 0, -1) == fmi3Error;
    }
    if (ok && state == S_TERMINATED) {
        ok = api3.Terminate(c) == fmi3OK;
    }
    if (!ok && c != NULL) {
        api3.FreeInstance(c);
        c = NULL;
    }
    probe_log_book_clear(book);
    return c;
}

/* FMI 3.0 co-simulation without event mode (eventModeUsed false), the same
 * letters as for FMI 2. The FMU has no clocks, structural parameters, event
 * mode, model exchange, FMU state or adjoints: those entry points are U. */
static const call_rule fmi3_rules[] = {
    {"fmi3SetDebugLogging", "LLLLLL"},
    {"fmi3EnterInitializationMode", "LIIIII"},
    {"fmi3ExitInitializationMode", "ILIIII"},
    {"fmi3EnterEventMode", "UUUUUU"},
    {"fmi3Terminate", "IILLxI"},
    {"fmi3Reset", "LLLLLL"},
    {"fmi3GetFloat64 (output)", "ILLLLL"},
    {"fmi3GetFloat64 (input)", "ILLLLL"},
    {"fmi3GetFloat64 (time)", "ILLLLL"},
    {"fmi3GetInt32 (status)", "ILLLLL"},
    {"fmi3GetFloat32 (none)", "ILLLLL"},
    {"fmi3GetInt8 (none)", "ILLLLL"},
    {"fmi3GetUInt8 (none)", "ILLLLL"},
    {"fmi3GetInt16 (none)", "ILLLLL"},
    {"fmi3GetUInt16 (none)", "ILLLLL"},
    {"fmi3GetUInt32 (none)", "ILLLLL"},
    {"fmi3GetInt64 (none)", "ILLLLL"},
    {"fmi3GetUInt64 (none)", "ILLLLL"},
    {"fmi3GetBoolean (none)", "ILLLLL"},
    {"fmi3GetString (none)", "ILLLLL"},
    {"fmi3GetBinary (none)", "ILLLLL"},
    {"fmi3GetClock (none)", "xxxxxx"}, /* clocks only in event mode */
    {"fmi3SetFloat64 (input)", "LLLxxI"},
    {"fmi3SetFloat64 (fixed parameter)", "LLPPPI"},
    {"fmi3SetFloat32 (none)", "LLLxxI"},
    {"fmi3SetInt8 (none)", "LLLxxI"},
    {"fmi3SetUInt8 (none)", "LLLxxI"},
    {"fmi3SetInt16 (none)", "LLLxxI"},
    {"fmi3SetUInt16 (none)", "LLLxxI"},
    {"fmi3SetInt32 (none)", "LLLxxI"},
    {"fmi3SetUInt32 (none)", "LLLxxI"},
    {"fmi3SetInt64 (none)", "LLLxxI"},
    {"fmi3SetUInt64 (none)", "LLLxxI"},
    {"fmi3SetBoolean (none)", "LLLxxI"},
    {"fmi3SetString (none)", "LLLxxI"},
    {"fmi3SetBinary (none)", "LLLxxI"},
    {"fmi3SetClock (none)", "xxxxxx"},
    {"fmi3GetNumberOfVariableDependencies", "UUUUUU"},
    {"fmi3GetVariableDependencies", "UUUUUU"},
    {"fmi3GetFMUState", "LLLLLL"},
    {"fmi3SetFMUState", "UUUUUU"},
    {"fmi3FreeFMUState", "LLLLLL"},
    {"fmi3SerializedFMUStateSize", "UUUUUU"},
    {"fmi3SerializeFMUState", "UUUUUU"},
    {"fmi3DeserializeFMUState", "UUUUUU"},
    {"fmi3GetDirectionalDerivative", "ILLxLL"},
    {"fmi3GetAdjointDerivative", "UUUUUU"},
    {"fmi3EnterConfigurationMode", "UUUUUU"},
    {"fmi3ExitConfigurationMode", "UUUUUU"},
    {"fmi3GetIntervalDecimal", "UUUUUU"},
    {"fmi3GetIntervalFraction", "UUUUUU"},
    {"fmi3GetShiftDecimal", "UUUUUU"},
    {"fmi3GetShiftFraction", "UUUUUU"},
    {"fmi3SetIntervalDecimal", "UUUUUU"},
    {"fmi3SetIntervalFraction", "UUUUUU"},
    {"fmi3SetShiftDecimal", "UUUUUU"},
    {"fmi3SetShiftFraction", "UUUUUU"},
    {"fmi3EvaluateDiscreteStates", "UUUUUU"},
    {"fmi3UpdateDiscreteStates", "UUUUUU"},
    {"fmi3EnterContinuousTimeMode", "UUUUUU"},
    {"fmi3CompletedIntegratorStep", "UUUUUU"},
    {"fmi3SetTime", "UUUUUU"},
    {"fmi3SetContinuousStates", "UUUUUU"},
    {"fmi3GetContinuousStateDerivatives", "UUUUUU"},
    {"fmi3GetEventIndicators", "UUUUUU"},
    {"fmi3GetContinuousStates", "UUUUUU"},
    {"fmi3GetNominalsOfContinuousStates", "UUUUUU"},
    {"fmi3GetNumberOfEventIndicators", "UUUUUU"},
    {"fmi3GetNumberOfContinuousStates", "UUUUUU"},
    {"fmi3EnterStepMode", "UUUUUU"},
    {"fmi3GetOutputDerivatives", "ILLxxL"}, /* where the model interpolates */
    {"fmi3DoStep", "IILxxI"},
    {"fmi3ActivateModelPartition", "UUUUUU"},
};
enum { FMI3_RULES = sizeof fmi3_rules / sizeof fmi3_rules[0] };

static int fmi3_call(fmi3Instance c, size_t rule, const picks* p)
{
    const fmi3ValueReference out = p->output->vr, time_vr = 0;
    const fmi3ValueReference in = p->input != NULL ? p->input->vr : 0;
    double value = p->input != NULL ? other_value(p->input) : 0, seed = 1, rate = 0;
    fmi3Int32 i32 = 0, order = 1;
    fmi3Boolean flag = fmi3False, flags[6];
    fmi3FMUState state = NULL;
    fmi3Byte bytes[8] = {0};
    fmi3UInt64 counter = 0, resolution = 0;
    fmi3IntervalQualifier qualifier;
    size_t size = 0, element = 0;
    fmi3ValueReference dependent = 0;
    fmi3DependencyKind kind;
    switch (rule) {
    case 0: return api3.SetDebugLogging(c, fmi3True, 0, NULL);
    case 1: return api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0);
    case 2: return api3.ExitInitializationMode(c);
    case 3: return api3.EnterEventMode(c);
    case 4: return api3.Terminate(c);
    case 5: return api3.Reset(c);
    case 6: return api3.GetFloat64(c, &out, 1, &value, 1);
    case 7: return p->input != NULL ? (int)api3.GetFloat64(c, &in, 1, &value, 1) : -1;
    case 8: return api3.GetFloat64(c, &time_vr, 1, &value, 1);
    case 9: return p->status != NULL ? (int)api3.GetInt32(c, &p->status->vr, 1, &i32, 1) : -1;
    case 10: return api3.GetFloat32(c, NULL, 0, NULL, 0);
    case 11: return api3.GetInt8(c, NULL, 0, NULL, 0);
    case 12: return api3.GetUInt8(c, NULL, 0, NULL, 0);
    case 13: return api3.GetInt16(c, NULL, 0, NULL, 0);
    case 14: return api3.GetUInt16(c, NULL, 0, NULL, 0);
    case 15: return api3.GetUInt32(c, NULL, 0, NULL, 0);
    case 16: return api3.GetInt64(c, NULL, 0, NULL, 0);
    case 17: return api3.GetUInt64(c, NULL, 0, NULL, 0);
    case 18: return api3.GetBoolean(c, NULL, 0, NULL, 0);
    case 19: return api3.GetString(c, NULL, 0, NULL, 0);
    case 20: return api3.GetBinary(c, NULL, 0, NULL, NULL, 0);
    case 21: return api3.GetClock(c, NULL, 0, NULL);
    case 22: return p->input != NULL ? (int)api3.SetFloat64(c, &in, 1, &value, 1) : -1;
    case 23:
        if (p->parameter == NULL) {
            return -1;
        }
        value = other_value(p->parameter);
        return api3.SetFloat64(c, &p->parameter->vr, 1, &value, 1);
    case 24: return api3.SetFloat32(c, NULL, 0, NULL, 0);
    case 25: return api3.SetInt8(c, NULL, 0, NULL, 0);
    case 26: return api3.SetUInt8(c, NULL, 0, NULL, 0);
    case 27: return api3.SetInt16(c, NULL, 0, NULL, 0);
    case 28: return api3.SetUInt16(c, NULL, 0, NULL, 0);
    case 29: return api3.SetInt32(c, NULL, 0, NULL, 0);
    case 30: return api3.SetUInt32(c, NULL, 0, NULL, 0);
    case 31: return api3.SetInt64(c, NULL, 0, NULL, 0);
    case 32: return api3.SetUInt64(c, NULL, 0, NULL, 0);
    case 33: return api3.SetBoolean(c, NULL, 0, NULL, 0);
    case 34: return api3.SetString(c, NULL, 0, NULL, 0);
    case 35: return api3.SetBinary(c, NULL, 0, NULL, NULL, 0);
    case 36: return api3.SetClock(c, NULL, 0, NULL);
    case 37: return api3.GetNumberOfVariableDependencies(c, out, &size);
    case 38: return api3.GetVariableDependencies(c, out, &element, &dependent, &element, &kind, 1);
    case 39: return api3.GetFMUState(c, &state);
    case 40: return api3.SetFMUState(c, state);
    case 41: return api3.FreeFMUState(c, &state);
    case 42: return api3.SerializedFMUStateSize(c, state, &size);
    case 43: return api3.SerializeFMUState(c, state, bytes, sizeof bytes);
    case 44: return api3.DeserializeFMUState(c, bytes, sizeof bytes, &state);
    case 45:
        return p->input != NULL
                   ? (int)api3.GetDirectionalDerivative(c, &out, 1, &in, 1, &seed, 1, &rate, 1)
                   : -1;
    case 46: return api3.GetAdjointDerivative(c, &out, 1, &in, 1, &seed, 1, &rate, 1);
    case 47: return api3.EnterConfigurationMode(c);
    case 48: return api3.ExitConfigurationMode(c);
    case 49: return api3.GetIntervalDecimal(c, &out, 1, &rate, &qualifier);
    case 50: return api3.GetIntervalFraction(c, &out, 1, &counter, &resolution, &qualifier);
    case 51: return api3.GetShiftDecimal(c, &out, 1, &rate);
    case 52: return api3.GetShiftFraction(c, &out, 1, &counter, &resolution);
    case 53: return api3.SetIntervalDecimal(c, &out, 1, &rate);
    case 54: return api3.SetIntervalFraction(c, &out, 1, &counter, &resolution);
    case 55: return api3.SetShiftDecimal(c, &out, 1, &rate);
    case 56: return api3.SetShiftFraction(c, &out, 1, &counter, &resolution);
    case 57: return api3.EvaluateDiscreteStates(c);
    case 58:
        return api3.UpdateDiscreteStates(c, &flags[0], &flags[1], &flags[2], &flags[3], &flags[4],
                                         &rate);
    case 59: return api3.EnterContinuousTimeMode(c);
    case 60: return api3.CompletedIntegratorStep(c, fmi3True, &flags[0], &flags[1]);
    case 61: return api3.SetTime(c, 0);
    case 62: return api3.SetContinuousStates(c, &rate, 1);
    case 63: return api3.GetContinuousStateDerivatives(c, &rate, 1);
    case 64: return api3.GetEventIndicators(c, &rate, 1);
    case 65: return api3.GetContinuousStates(c, &rate, 1);
    case 66: return api3.GetNominalsOfContinuousStates(c, &rate, 1);
    case 67: return api3.GetNumberOfEventIndicators(c, &size);
    case 68: return api3.GetNumberOfContinuousStates(c, &size);
    case 69: return api3.EnterStepMode(c);
    case 70: return api3.GetOutputDerivatives(c, &out, 1, &order, &rate, 1);
    case 71: return step3(c, 0, 0.01);
    case 72: return api3.ActivateModelPartition(c, out, 0);
    }
    (void)flag;
    return -2;
}

static int test_fmi3_state_machine(void)
{
    int fails = 0, state;
    const picks p = pick(&md3);
    size_t rule;
    long calls = 0;
    for (state = 0; state < STATE_COUNT; ++state) {
        probe_log_book probe;
        fmi3Instance reachable = fmi3_in_state(&probe, state);
        if (reachable == NULL) {
            printf("    %s: no %s state (no input value makes a step fail)\n", md3.identifier,
                   state_names[state]);
            CHECK(state == S_FAILED, "cannot reach %s", state_names[state]);
            continue;
        }
        api3.FreeInstance(reachable);
        for (rule = 0; rule < FMI3_RULES; ++rule) {
            probe_log_book book;
            fmi3Instance c = fmi3_in_state(&book, state);
            const int status = fmi3_call(c, rule, &p);
            char expect = fmi3_rules[rule].expect[state];
            if (rule == 45 && !md3.provides_directional_derivatives && expect != 'I') {
                expect = 'U';
            }
            if (rule == 70 && !md3.interpolates && expect != 'I') {
                expect = 'U';
            }
            if (status >= 0) {
                ++calls;
                fails += judge(fmi3_rules[rule].name, state_names[state], expect, status, &book, 0,
                               rule == 23 ? p.parameter->name : NULL);
            }
            api3.FreeInstance(c);
        }
    }
    printf("    %ld calls in %d states\n", calls, STATE_COUNT);
    return fails;
}

static int test_fmi3_null_instance(void)
{
    int fails = 0;
    fmi3Boolean b[6];
    fmi3Float64 r = 0;
    size_t n = 0;
    CHECK(strcmp(api3.GetVersion(), "3.0") == 0, "fmi3GetVersion: %s", api3.GetVersion());
    api3.FreeInstance(NULL); /* ignored, says the standard */
    CHECK(api3.SetDebugLogging(NULL, fmi3True, 0, NULL) == fmi3Error, "SetDebugLogging");
    CHECK(api3.EnterInitializationMode(NULL, 0, 0, 0, 0, 0) == fmi3Error,
          "EnterInitializationMode");
    CHECK(api3.ExitInitializationMode(NULL) == fmi3Error, "ExitInitializationMode");
    CHECK(api3.EnterEventMode(NULL) == fmi3Error, "EnterEventMode");
    CHECK(api3.Terminate(NULL) == fmi3Error, "Terminate");
    CHECK(api3.Reset(NULL) == fmi3Error, "Reset");
    CHECK(api3.GetFloat64(NULL, NULL, 0, NULL, 0) == fmi3Error, "GetFloat64");
    CHECK(api3.GetInt32(NULL, NULL, 0, NULL, 0) == fmi3Error, "GetInt32");
    CHECK(api3.GetFloat32(NULL, NULL, 0, NULL, 0) == fmi3Error, "GetFloat32");
    CHECK(api3.GetBoolean(NULL, NULL, 0, NULL, 0) == fmi3Error, "GetBoolean");
    CHECK(api3.GetString(NULL, NULL, 0, NULL, 0) == fmi3Error, "GetString");
    CHECK(api3.GetBinary(NULL, NULL, 0, NULL, NULL, 0) == fmi3Error, "GetBinary");
    CHECK(api3.SetFloat64(NULL, NULL, 0, NULL, 0) == fmi3Error, "SetFloat64");
    CHECK(api3.SetInt32(NULL, NULL, 0, NULL, 0) == fmi3Error, "SetInt32");
    CHECK(api3.SetBoolean(NULL, NULL, 0, NULL, 0) == fmi3Error, "SetBoolean");
    CHECK(api3.GetFMUState(NULL, NULL) == fmi3Error, "GetFMUState");
    CHECK(api3.GetDirectionalDerivative(NULL, NULL, 0, NULL, 0, NULL, 0, NULL, 0) == fmi3Error,
          "GetDirectionalDerivative");
    CHECK(api3.GetNumberOfContinuousStates(NULL, &n) == fmi3Error, "GetNumberOfContinuousStates");
    CHECK(api3.UpdateDiscreteStates(NULL, &b[0], &b[1], &b[2], &b[3], &b[4], &r) == fmi3Error,
          "UpdateDiscreteStates");
    CHECK(api3.DoStep(NULL, 0, 0.1, fmi3True, &b[0], &b[1], &b[2], &r) == fmi3Error, "DoStep");
    return fails;
}

static int test_fmi3_null_arguments(void)
{
    int fails = 0;
    probe_log_book book;
    const picks p = pick(&md3);
    fmi3Instance c;
    fmi3Boolean event, terminate, early;
    fmi3Float64 last, value = 0;
    long count;
    const char* no_category = NULL;
    probe_log_book_clear(&book);
    /* allowed: no resources, no environment, no logger, no intermediate update */
    c = api3.InstantiateCoSimulation("nulls", md3.token, NULL, fmi3False, fmi3False, fmi3False,
                                     fmi3False, NULL, 0, NULL, NULL, NULL);
    CHECK(c != NULL, "NULL resourcePath, environment, logMessage, intermediateUpdate refused");
    CHECK(c == NULL || (initialise_fmi3(c) && step3(c, 0, -1) == fmi3Error),
          "an instance without a logger still refuses bad calls");
    api3.FreeInstance(c);
    CHECK(api3.InstantiateCoSimulation(NULL, md3.token, NULL, 0, 0, 0, 0, NULL, 0, &book,
                                       probe_fmi3_logger, NULL) == NULL &&
              book.count > 0,
          "NULL instance name accepted or not logged");
    CHECK(api3.InstantiateCoSimulation("x", NULL, NULL, 0, 0, 0, 0, NULL, 0, &book,
                                       probe_fmi3_logger, NULL) == NULL,
          "NULL token accepted");
    c = new_fmi3(&book, "nulls");
    CHECK(api3.SetDebugLogging(c, fmi3True, 0, NULL) == fmi3OK, "no categories, NULL array");
    count = book.count;
    CHECK(api3.SetDebugLogging(c, fmi3True, 1, &no_category) == fmi3Error &&
              logged_error(&book, count),
          "a NULL category");
    CHECK(api3.SetFloat64(c, NULL, 0, NULL, 0) == fmi3OK, "SetFloat64 of nothing");
    CHECK(initialise_fmi3(c), "initialise");
    CHECK(api3.GetFloat64(c, NULL, 0, NULL, 0) == fmi3OK, "GetFloat64 of nothing");
    CHECK(api3.GetInt32(c, NULL, 0, NULL, 0) == fmi3OK, "GetInt32 of nothing");
    if (md3.provides_directional_derivatives) {
        CHECK(api3.GetDirectionalDerivative(c, NULL, 0, NULL, 0, NULL, 0, NULL, 0) == fmi3OK,
              "GetDirectionalDerivative of nothing");
    }
    count = book.count;
    CHECK(api3.GetFloat64(c, NULL, 1, &value, 1) == fmi3Error && logged_error(&book, count),
          "GetFloat64 with NULL value references");
    count = book.count;
    CHECK(api3.GetFloat64(c, &p.output->vr, 1, NULL, 1) == fmi3Error && logged_error(&book, count),
          "GetFloat64 with a NULL value array");
    count = book.count;
    CHECK(p.input == NULL || (api3.SetFloat64(c, &p.input->vr, 1, NULL, 1) == fmi3Error &&
                              logged_error(&book, count)),
          "SetFloat64 with a NULL value array");
    count = book.count;
    CHECK(api3.DoStep(c, 0, 0.01, fmi3True, NULL, &terminate, &early, &last) == fmi3Error &&
              logged_error(&book, count),
          "DoStep with a NULL eventHandlingNeeded");
    count = book.count;
    CHECK(api3.DoStep(c, 0, 0.01, fmi3True, &event, &terminate, &early, NULL) == fmi3Error &&
              logged_error(&book, count),
          "DoStep with a NULL lastSuccessfulTime");
    api3.FreeInstance(c);
    return fails;
}

static int fmi3_read_all(fmi3Instance c, values_read* r)
{
    fmi3ValueReference reals[512], integers[64];
    size_t k;
    r->n_reals = r->n_integers = 0;
    for (k = 0; k < md3.variable_count && r->n_reals < 512 && r->n_integers < 64; ++k) {
        if (md3.variables[k].type == PROBE_REAL) {
            reals[r->n_reals++] = md3.variables[k].vr;
        } else if (md3.variables[k].type == PROBE_INTEGER) {
            integers[r->n_integers++] = md3.variables[k].vr;
        }
    }
    return api3.GetFloat64(c, reals, r->n_reals, r->reals, r->n_reals) <= fmi3Warning &&
           api3.GetInt32(c, integers, r->n_integers, r->integers, r->n_integers) == fmi3OK;
}

/* Every getter and setter of a type the variable is not. */
static int fmi3_wrong_type_calls(fmi3Instance c, const probe_variable* v, probe_log_book* book)
{
    int fails = 0;
    const fmi3ValueReference vr = v->vr;
    union {
        fmi3Float64 f64;
        fmi3Float32 f32;
        fmi3Int64 i64;
        fmi3UInt64 u64;
        fmi3Int32 i32;
        fmi3String s;
        fmi3Binary b;
        fmi3Clock clock;
    } any;
    const int settable = v->causality == PROBE_INPUT || v->causality == PROBE_PARAMETER;
    size_t size = 0, k;
    for (k = 0; k < 26; ++k) {
        const long count = book->count;
        int status = 0;
        memset(&any, 0, sizeof any);
        switch (k) {
        case 0:
            status = v->type == PROBE_REAL ? -1 : (int)api3.GetFloat64(c, &vr, 1, &any.f64, 1);
            break;
        case 1:
            status = v->type == PROBE_INTEGER ? -1 : (int)api3.GetInt32(c, &vr, 1, &any.i32, 1);
            break;
        case 2: status = api3.GetFloat32(c, &vr, 1, &any.f32, 1); break;
        case 3: status = api3.GetInt8(c, &vr, 1, (fmi3Int8*)&any, 1); break;
        case 4: status = api3.GetUInt8(c, &vr, 1, (fmi3UInt8*)&any, 1); break;
        case 5: status = api3.GetInt16(c, &vr, 1, (fmi3Int16*)&any, 1); break;
        case 6: status = api3.GetUInt16(c, &vr, 1, (fmi3UInt16*)&any, 1); break;
        case 7: status = api3.GetUInt32(c, &vr, 1, (fmi3UInt32*)&any, 1); break;
        case 8:
            status = v->type == PROBE_ENUMERATION ? -1 : (int)api3.GetInt64(c, &vr, 1, &any.i64, 1);
            break;
        case 9: status = api3.GetUInt64(c, &vr, 1, &any.u64, 1); break;
        case 10: status = api3.GetBoolean(c, &vr, 1, (fmi3Boolean*)&any, 1); break;
        case 11: status = api3.GetString(c, &vr, 1, &any.s, 1); break;
        case 12: status = api3.GetBinary(c, &vr, 1, &size, &any.b, 1); break;
        case 13: status = api3.GetClock(c, &vr, 1, &any.clock); break;
        /* a setter of the variable's own type is wrong only for an output or time */
        case 14:
            status = v->type == PROBE_REAL && settable
                         ? -1
                         : (int)api3.SetFloat64(c, &vr, 1, &any.f64, 1);
            break;
        case 15:
            status = v->type == PROBE_INTEGER && settable
                         ? -1
                         : (int)api3.SetInt32(c, &vr, 1, &any.i32, 1);
            break;
        case 16: status = api3.SetFloat32(c, &vr, 1, &any.f32, 1); break;
        case 17: status = api3.SetInt8(c, &vr, 1, (fmi3Int8*)&any, 1); break;
        case 18: status = api3.SetUInt8(c, &vr, 1, (fmi3UInt8*)&any, 1); break;
        case 19: status = api3.SetInt16(c, &vr, 1, (fmi3Int16*)&any, 1); break;
        case 20: status = api3.SetUInt16(c, &vr, 1, (fmi3UInt16*)&any, 1); break;
        case 21: status = api3.SetUInt32(c, &vr, 1, (fmi3UInt32*)&any, 1); break;
        case 22:
            status = v->type == PROBE_ENUMERATION && settable
                         ? -1
                         : (int)api3.SetInt64(c, &vr, 1, &any.i64, 1);
            break;
        case 23: status = api3.SetUInt64(c, &vr, 1, &any.u64, 1); break;
        case 24: status = api3.SetBoolean(c, &vr, 1, (fmi3Boolean*)&any, 1); break;
        case 25:
            any.s = "x";
            status = api3.SetString(c, &vr, 1, &any.s, 1);
            break;
        }
        if (status >= 0) {
            CHECK(status == fmi3Error && logged_error(book, count),
                  "%s (vr %u) through call %zu of another type: status %d (%s)", v->name, vr, k,
                  status, book->last);
        }
    }
    return fails;
}

static int test_fmi3_wrong_types_and_unknown_vrs(void)
{
    int fails = 0;
    probe_log_book book;
    fmi3Instance c = new_fmi3(&book, "types");
    const picks p = pick(&md3);
    const fmi3ValueReference unknown[2] = {probe_unused_vr(&md3), UINT_MAX};
    const fmi3ValueReference time_vr = 0;
    values_read before, after;
    fmi3Float64 value = 1;
    fmi3Int32 integer = 0;
    size_t k;
    long count;
    CHECK(api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
              fmi3_read_all(c, &before),
          "initialise");
    for (k = 0; k < md3.variable_count; ++k) {
        const probe_variable* v = &md3.variables[k];
        fails += fmi3_wrong_type_calls(c, v, &book);
        if (v->type == PROBE_REAL && v->causality != PROBE_INDEPENDENT) {
            count = book.count;
            CHECK(api3.GetInt32(c, &v->vr, 1, &integer, 1) == fmi3Error &&
                      strstr(book.last, v->name) != NULL && logged_error(&book, count),
                  "Float64 %s read as Int32: %s", v->name, book.last);
        }
    }
    count = book.count;
    CHECK(api3.SetFloat64(c, &time_vr, 1, &value, 1) == fmi3Error && logged_error(&book, count) &&
              strstr(book.last, "time") != NULL,
          "time set: %s", book.last);
    for (k = 0; k < 2; ++k) {
        char number[16];
        sprintf(number, "%u", unknown[k]);
        count = book.count;
        CHECK(api3.GetFloat64(c, &unknown[k], 1, &value, 1) == fmi3Error &&
                  logged_error(&book, count) && strstr(book.last, number) != NULL,
              "unknown value reference %u read: %s", unknown[k], book.last);
        count = book.count;
        CHECK(api3.SetFloat64(c, &unknown[k], 1, &value, 1) == fmi3Error &&
                  logged_error(&book, count),
              "unknown value reference %u set", unknown[k]);
        count = book.count;
        CHECK(api3.GetInt32(c, &unknown[k], 1, &integer, 1) == fmi3Error &&
                  logged_error(&book, count),
              "unknown value reference %u read as Int32", unknown[k]);
    }
    if (p.input != NULL) {
        const fmi3ValueReference pair[2] = {p.input->vr, unknown[0]};
        const double values[2] = {other_value(p.input), 1};
        CHECK(api3.SetFloat64(c, pair, 2, values, 2) == fmi3Error,
              "a call with an unknown reference");
    }
    CHECK(fmi3_read_all(c, &after) && same_values(&before, &after),
          "a refused call changed a value");
    api3.FreeInstance(c);
    return fails;
}

/* nValues must equal nValueReferences (every variable is a scalar); a refused
 * call writes nothing, not even within the smaller of the two sizes. */
static int test_fmi3_size_mismatch(void)
{
    int fails = 0;
    probe_log_book book;
    fmi3Instance c = new_fmi3(&book, "sizes");
    const picks p = pick(&md3);
    const double canary = -7.25;
    fmi3ValueReference vrs[2];
    fmi3Float64 reals[4], seed[2] = {1, 1};
    fmi3Int32 integers[4];
    values_read before, after;
    size_t n_values, k;
    long count;
    vrs[0] = p.output->vr;
    vrs[1] = p.input != NULL ? p.input->vr : p.output->vr;
    CHECK(initialise_fmi3(c) && fmi3_read_all(c, &before), "initialise");
    for (n_values = 0; n_values <= 3; n_values += 1) {
        if (n_values == 2) {
            continue;
        }
        for (k = 0; k < 4; ++k) {
            reals[k] = canary;
            integers[k] = 77;
        }
        count = book.count;
        CHECK(api3.GetFloat64(c, vrs, 2, reals, n_values) == fmi3Error &&
                  logged_error(&book, count) && reals[0] == canary && reals[1] == canary,
              "GetFloat64 of 2 into %zu values: %s", n_values, book.last);
        count = book.count;
        CHECK(api3.SetFloat64(c, &vrs[1], 1, reals, n_values == 0 ? 0 : 2) == fmi3Error &&
                  logged_error(&book, count),
              "SetFloat64 of 1 from %zu values", n_values == 0 ? 0 : (size_t)2);
        if (p.status != NULL) {
            const fmi3ValueReference status_vrs[2] = {p.status->vr, p.status->vr};
            count = book.count;
            CHECK(api3.GetInt32(c, status_vrs, 2, integers, n_values) == fmi3Error &&
                      logged_error(&book, count) && integers[0] == 77,
                  "GetInt32 of 2 into %zu values", n_values);
            count = book.count;
            CHECK(api3.SetInt32(c, status_vrs, 1, integers, 2) == fmi3Error &&
                      logged_error(&book, count),
                  "SetInt32 of 1 from 2 values");
        }
        if (md3.provides_directional_derivatives && p.input != NULL) {
            const size_t n_seed = n_values == 1 ? 2 : n_values; /* never the one that fits */
            count = book.count;
            CHECK(api3.GetDirectionalDerivative(c, vrs, 1, &vrs[1], 1, seed, n_seed, reals, 1) ==
                          fmi3Error &&
                      logged_error(&book, count) && reals[0] == canary,
                  "GetDirectionalDerivative with nSeed %zu for 1 known", n_seed);
            count = book.count;
            CHECK(api3.GetDirectionalDerivative(c, vrs, 1, &vrs[1], 1, seed, 1, reals, n_seed) ==
                          fmi3Error &&
                      logged_error(&book, count) && reals[0] == canary,
                  "GetDirectionalDerivative with nSensitivity %zu for 1 unknown", n_seed);
        }
    }
    CHECK(fmi3_read_all(c, &after) && same_values(&before, &after),
          "a refused call changed a value");
    api3.FreeInstance(c);
    return fails;
}

static int test_fmi3_invalid_values(void)
{
    int fails = 0;
    probe_log_book book;
    fmi3Instance c = new_fmi3(&book, "100% %s %n");
    values_read before;
    size_t k, j;
    long count;
    for (k = 0; k < md3.variable_count; ++k) {
        const probe_variable* v = &md3.variables[k];
        double bad[5] = {NAN, INFINITY, -INFINITY, 0, 0};
        size_t n = 3;
        if (!is_real_setting(v)) {
            continue;
        }
        if (v->has_min) {
            bad[n++] = nextafter(v->min, -INFINITY);
        }
        if (v->has_max) {
            bad[n++] = nextafter(v->max, INFINITY);
        }
        for (j = 0; j < n; ++j) {
            count = book.count;
            CHECK(api3.SetFloat64(c, &v->vr, 1, &bad[j], 1) == fmi3Error &&
                      logged_error(&book, count) && strstr(book.last, v->name) != NULL,
                  "%s = %g: %s", v->name, bad[j], book.last);
        }
    }
    CHECK(api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
              fmi3_read_all(c, &before),
          "initialise after refused values");
    for (k = 0, j = 0; k < md3.variable_count; ++k) {
        const probe_variable* v = &md3.variables[k];
        if (v->type == PROBE_REAL) {
            CHECK(!is_real_setting(v) || !v->has_start ||
                      probe_bits(before.reals[j]) == probe_bits(v->start),
                  "%s = %.17g after refused values, start %.17g", v->name, before.reals[j],
                  v->start);
            ++j;
        }
    }
    api3.FreeInstance(c);
    return fails;
}

static int test_fmi3_reset(void)
{
    int fails = 0;
    probe_log_book book;
    fmi3Instance c = new_fmi3(&book, "reset");
    values_read fresh, again;
    size_t k;
    CHECK(api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
              fmi3_read_all(c, &fresh),
          "read the start values");
    for (k = 0; k < md3.variable_count; ++k) {
        const probe_variable* v = &md3.variables[k];
        const double value = other_value(v);
        if (is_real_setting(v)) {
            CHECK(api3.SetFloat64(c, &v->vr, 1, &value, 1) == fmi3OK, "set %s", v->name);
        }
    }
    CHECK(api3.ExitInitializationMode(c) != fmi3Error, "exit");
    step3(c, 0, 0.01);
    CHECK(api3.Reset(c) == fmi3OK, "reset");
    CHECK(step3(c, 0, 0.01) == fmi3Error, "doStep after reset needs initialization");
    CHECK(api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK &&
              fmi3_read_all(c, &again),
          "initialise again");
    CHECK(same_values(&fresh, &again), "reset did not restore every start value");
    api3.FreeInstance(c);
    return fails;
}

static int test_fmi3_instantiate_refusals(void)
{
    int fails = 0;
    probe_log_book book;
    const fmi3ValueReference one = 0;
    probe_log_book_clear(&book);
    CHECK(api3.InstantiateCoSimulation("x", "{wrong}", NULL, 0, 0, 0, 0, NULL, 0, &book,
                                       probe_fmi3_logger, NULL) == NULL &&
              strstr(book.last, "token") != NULL,
          "wrong token accepted: %s", book.last);
    probe_log_book_clear(&book);
    CHECK(api3.InstantiateModelExchange("x", md3.token, NULL, 0, 0, &book, probe_fmi3_logger) ==
                  NULL &&
              book.count == 1,
          "model exchange accepted");
    probe_log_book_clear(&book);
    CHECK(api3.InstantiateScheduledExecution("x", md3.token, NULL, 0, 0, &book, probe_fmi3_logger,
                                             NULL, NULL, NULL) == NULL &&
              book.count == 1,
          "scheduled execution accepted");
    probe_log_book_clear(&book);
    CHECK(api3.InstantiateCoSimulation("x", md3.token, NULL, 0, 0, fmi3True, 0, NULL, 0, &book,
                                       probe_fmi3_logger, NULL) == NULL &&
              book.count == 1,
          "eventModeUsed accepted without an event mode");
    probe_log_book_clear(&book);
    CHECK(api3.InstantiateCoSimulation("x", md3.token, NULL, 0, 0, 0, 0, &one, 1, &book,
                                       probe_fmi3_logger, NULL) == NULL &&
              book.count == 1,
          "required intermediate variables accepted");
    probe_log_book_clear(&book);
    CHECK(api3.InstantiateCoSimulation("", md3.token, NULL, 0, 0, 0, 0, NULL, 0, &book,
                                       probe_fmi3_logger, NULL) == NULL &&
              book.count == 1,
          "empty instance name accepted");
    return fails;
}

/* ---- both: instances are independent -------------------------------------------------------- */

/* Steps instances with their own inputs, interleaved, and again each alone: the
 * outputs agree bit for bit. */
static int run_interleaved(int version, int together, uint64_t traces[2])
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    probe_log_book books[2];
    void* c[2] = {NULL, NULL};
    values_read r;
    int i, step, round, status, ok = 1;
    for (round = 0; round < (together ? 1 : 2); ++round) {
        for (i = 0; i < 2; ++i) {
            if (!together && i != round) {
                continue;
            }
            c[i] = version == 2 ? new_fmi2(&books[i], i == 0 ? "a" : "b")
                                : new_fmi3(&books[i], i == 0 ? "a" : "b");
            ok &= version == 2 ? initialise_fmi2(c[i]) : initialise_fmi3(c[i]);
            traces[i] = PROBE_HASH_START;
        }
        for (step = 0; step < 20; ++step) {
            for (i = 0; i < 2; ++i) {
                size_t k;
                if (!together && i != round) {
                    continue;
                }
                for (k = 0; k < md->variable_count; ++k) {
                    const probe_variable* v = &md->variables[k];
                    if (v->type == PROBE_REAL && v->causality == PROBE_INPUT) {
                        const double value =
                            (v->has_start ? v->start : 0) + (i == 0 ? 0.01 : 0.03) * step;
                        if (version == 2) {
                            api2.SetReal(c[i], &v->vr, 1, &value);
                        } else {
                            api3.SetFloat64(c[i], &v->vr, 1, &value, 1);
                        }
                    }
                }
                status = version == 2 ? (int)api2.DoStep(c[i], step * 0.01, 0.01, fmi2True)
                                      : (int)step3(c[i], step * 0.01, 0.01);
                traces[i] = probe_hash_u64(traces[i], (uint64_t)status);
                ok &= version == 2 ? fmi2_read_all(c[i], &r) : fmi3_read_all(c[i], &r);
                for (k = 0; k < r.n_reals; ++k) {
                    traces[i] = probe_hash_double(traces[i], r.reals[k]);
                }
            }
        }
        for (i = 0; i < 2; ++i) {
            if (c[i] != NULL) {
                if (version == 2) {
                    api2.FreeInstance(c[i]);
                } else {
                    api3.FreeInstance(c[i]);
                }
                c[i] = NULL;
            }
        }
    }
    return ok;
}

/* ---- on_singular: what doStep does where the model has no answer ----------------------------- */

/* Whether the declaration of on_singular is the one the FMU layer reads: a fixed
 * Enumeration parameter whose default is 1 (discard). Every model without states has
 * it; the failed steps of one with states (the drive, a plant) cannot go on. */
static int declares_on_singular(const probe_model* md, const probe_variable* v, int* fails_out)
{
    int fails = 0;
    if (v == NULL) {
        CHECK(probe_has_states(md), "%s has no on_singular", md->identifier);
        *fails_out += fails;
        return 0;
    }
    CHECK(v->type == PROBE_ENUMERATION && v->causality == PROBE_PARAMETER &&
              v->variability == PROBE_FIXED && v->has_start && v->start == 1,
          "on_singular is not a fixed Enumeration parameter starting at 1 (discard)");
    *fails_out += fails;
    return fails == 0;
}

/* After a continued step: the status says why, no output is infinite, and the
 * reactions (some Real output at least) are NaN. */
static int continued_outputs(const values_read* r, int status, int fmi_version)
{
    int fails = 0;
    size_t k, nan = 0;
    for (k = 0; k < r->n_reals; ++k) {
        CHECK(!isinf(r->reals[k]), "FMI %d: continued step: output %zu is infinite", fmi_version,
              k);
        nan += isnan(r->reals[k]) != 0;
    }
    CHECK(nan > 0, "FMI %d: continued step: no output is NaN", fmi_version);
    CHECK(status != 0, "FMI %d: continued step: status 0", fmi_version);
    return fails;
}

static int test_fmi2_on_singular(void)
{
    int fails = 0;
    probe_log_book book;
    const probe_variable* v = probe_variable_named(&md2, "on_singular");
    const picks p = pick(&md2);
    const fmi2Integer refused[3] = {0, 3, -1}, go_on = 2, discard = 1;
    fmi2Component c;
    fmi2Integer item = 0, status = 0;
    fmi2Boolean terminated = fmi2True;
    unsigned vr = 0;
    double value = 0, last = 0;
    values_read r;
    size_t k;
    long count;
    if (!declares_on_singular(&md2, v, &fails) || p.status == NULL) {
        return fails;
    }
    c = new_fmi2(&book, "discard");
    CHECK(initialise_fmi2(c) && fmi2_find_discard(c, &vr, &value), "no input discards a step");
    api2.FreeInstance(c);
    if (fails) {
        return fails;
    }
    c = new_fmi2(&book, "continue");
    for (k = 0; k < 3; ++k) {
        count = book.count;
        CHECK(api2.SetInteger(c, &v->vr, 1, &refused[k]) == fmi2Error &&
                  logged_error(&book, count) && strstr(book.last, "1 (discard) or 2 (continue)"),
              "on_singular = %d: %s", refused[k], book.last);
    }
    CHECK(api2.SetInteger(c, &v->vr, 1, &go_on) == fmi2OK, "on_singular = 2 refused");
    CHECK(initialise_fmi2(c), "initialise");
    CHECK(api2.GetInteger(c, &v->vr, 1, &item) == fmi2OK && item == 2, "on_singular reads %d",
          item);
    count = book.count;
    CHECK(api2.SetInteger(c, &v->vr, 1, &discard) == fmi2Error && logged_error(&book, count),
          "on_singular set after initialization");
    CHECK(api2.SetReal(c, &vr, 1, &value) == fmi2OK, "set the failing input");
    count = book.count;
    CHECK(api2.DoStep(c, 0, 0.01, fmi2True) == fmi2OK, "the step did not go on");
    CHECK(book.count > count && book.last_status == fmi2Warning, "not logged as a warning: %s",
          book.last);
    CHECK(api2.GetRealStatus(c, fmi2LastSuccessfulTime, &last) == fmi2OK && last == 0.01,
          "last successful time %g", last);
    CHECK(api2.GetBooleanStatus(c, fmi2Terminated, &terminated) == fmi2OK && !terminated,
          "asks to terminate");
    CHECK(fmi2_read_all(c, &r) && api2.GetInteger(c, &p.status->vr, 1, &status) == fmi2OK,
          "read the outputs");
    fails += continued_outputs(&r, status, 2);
    CHECK(api2.DoStep(c, 0.01, 0.01, fmi2True) == fmi2OK, "the next step did not go on");
    CHECK(api2.Reset(c) == fmi2OK && initialise_fmi2(c) &&
              api2.GetInteger(c, &v->vr, 1, &item) == fmi2OK && item == 1,
          "reset leaves on_singular = %d", item);
    api2.FreeInstance(c);
    return fails;
}

static int test_fmi3_on_singular(void)
{
    int fails = 0;
    probe_log_book book;
    const probe_variable* v = probe_variable_named(&md3, "on_singular");
    const picks p = pick(&md3);
    const fmi3Int64 refused[3] = {0, 3, INT64_MAX}, go_on = 2, discard = 1;
    fmi3Instance c;
    fmi3Int64 item = 0;
    fmi3Int32 status = 0;
    fmi3Boolean event, terminate = fmi3True, early;
    fmi3Float64 last = 0;
    unsigned vr = 0;
    double value = 0;
    values_read r;
    size_t k;
    long count;
    if (!declares_on_singular(&md3, v, &fails) || p.status == NULL) {
        return fails;
    }
    c = new_fmi3(&book, "discard");
    CHECK(initialise_fmi3(c) && fmi3_find_discard(c, &vr, &value), "no input discards a step");
    api3.FreeInstance(c);
    if (fails) {
        return fails;
    }
    c = new_fmi3(&book, "continue");
    for (k = 0; k < 3; ++k) {
        count = book.count;
        CHECK(api3.SetInt64(c, &v->vr, 1, &refused[k], 1) == fmi3Error &&
                  logged_error(&book, count) && strstr(book.last, "1 (discard) or 2 (continue)"),
              "on_singular = %lld: %s", (long long)refused[k], book.last);
    }
    count = book.count;
    CHECK(api3.SetInt32(c, &v->vr, 1, &status, 1) == fmi3Error && logged_error(&book, count),
          "on_singular set as Int32");
    CHECK(api3.SetInt64(c, &v->vr, 1, &go_on, 1) == fmi3OK, "on_singular = 2 refused");
    CHECK(initialise_fmi3(c), "initialise");
    CHECK(api3.GetInt64(c, &v->vr, 1, &item, 1) == fmi3OK && item == 2, "on_singular reads %lld",
          (long long)item);
    count = book.count;
    CHECK(api3.SetInt64(c, &v->vr, 1, &discard, 1) == fmi3Error && logged_error(&book, count),
          "on_singular set after initialization");
    CHECK(api3.SetFloat64(c, &vr, 1, &value, 1) == fmi3OK, "set the failing input");
    count = book.count;
    CHECK(api3.DoStep(c, 0, 0.01, fmi3True, &event, &terminate, &early, &last) == fmi3OK &&
              !terminate && last == 0.01,
          "the step did not go on");
    CHECK(book.count > count && book.last_status == fmi3Warning, "not logged as a warning: %s",
          book.last);
    CHECK(fmi3_read_all(c, &r) && api3.GetInt32(c, &p.status->vr, 1, &status, 1) == fmi3OK,
          "read the outputs");
    fails += continued_outputs(&r, status, 3);
    CHECK(step3(c, 0.01, 0.01) == fmi3OK, "the next step did not go on");
    CHECK(api3.Reset(c) == fmi3OK && initialise_fmi3(c) &&
              api3.GetInt64(c, &v->vr, 1, &item, 1) == fmi3OK && item == 1,
          "reset leaves on_singular = %lld", (long long)item);
    api3.FreeInstance(c);
    return fails;
}

static int test_instances_independent(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        uint64_t together[2], alone[2];
        CHECK(run_interleaved(version, 1, together) && run_interleaved(version, 0, alone),
              "FMI %d: run", version);
        CHECK(together[0] == alone[0] && together[1] == alone[1],
              "FMI %d: interleaved instances differ from each alone", version);
        CHECK(together[0] != together[1], "FMI %d: different inputs gave the same trace", version);
    }
    return fails;
}

/* ---- both: FMU state --------------------------------------------------------------------------
 */

static void free_either(int version, void* c);

/* ---- both: a directional derivative along a huge seed -------------------------------------- */

static int derivative_either(int version, void* c, const unsigned outputs[], size_t n_outputs,
                             const unsigned knowns[], const double seed[], size_t n_knowns,
                             double rates[])
{
    return version == 2
               ? (int)api2.GetDirectionalDerivative(c, outputs, n_outputs, knowns, n_knowns, seed,
                                                    rates)
               : (int)api3.GetDirectionalDerivative(c, outputs, n_outputs, knowns, n_knowns, seed,
                                                    n_knowns, rates, n_outputs);
}

/* One derivative of every Real output along `seed` for the knowns (an input named once
 * or twice): OK with every rate finite, or Discard with every rate NaN and the reason
 * logged. *discarded counts the Discards. */
static int check_huge_seed(int version, void* c, probe_log_book* book, const unsigned outputs[],
                           size_t n_outputs, const unsigned knowns[], const double seed[],
                           size_t n_knowns, const char* input, int* discarded)
{
    double* rates = (double*)malloc((n_outputs + 1) * sizeof *rates);
    const long logged = book->count;
    size_t k, finite = 0, nan = 0;
    int fails = 0, status;
    if (rates == NULL) {
        return 1;
    }
    for (k = 0; k < n_outputs; ++k) {
        rates[k] = 12345.0;
    }
    status = derivative_either(version, c, outputs, n_outputs, knowns, seed, n_knowns, rates);
    for (k = 0; k < n_outputs; ++k) {
        finite += isfinite(rates[k]) ? 1u : 0u;
        nan += isnan(rates[k]) ? 1u : 0u;
    }
    *discarded += status == 2;
    CHECK((status == 0 && finite == n_outputs) ||
              (status == 2 && nan == n_outputs && book->count > logged && book->last_status == 2 &&
               book->last[0] != '\0'),
          "FMI %d: derivative along %s x %zu (seed %g): status %d, %zu of %zu rates finite, "
          "%zu NaN, log '%s'",
          version, input, n_knowns, seed[0], status, finite, n_outputs, nan,
          book->count > logged ? book->last : "");
    free(rates);
    return fails;
}

/* A seed of DBL_MAX, or 1e308 given twice for one known (inf once added up), overflows
 * the derivative: Discard with a reason and NaN rates, never OK with NaN. Every Real
 * input in turn; at least one of them must overflow. */
static int test_huge_seed_discards(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        const probe_model* md = version == 2 ? &md2 : &md3;
        unsigned* outputs = (unsigned*)malloc((md->variable_count + 1) * sizeof *outputs);
        size_t n_outputs = 0, k;
        int discarded = 0, inputs = 0;
        probe_log_book book;
        void* c;
        if (!md->provides_directional_derivatives || outputs == NULL) {
            free(outputs);
            continue;
        }
        c = version == 2 ? new_fmi2(&book, "seed") : new_fmi3(&book, "seed");
        CHECK(c != NULL && (version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)),
              "FMI %d: initialise", version);
        for (k = 0; k < md->variable_count; ++k) {
            if (md->variables[k].type == PROBE_REAL && md->variables[k].causality == PROBE_OUTPUT) {
                outputs[n_outputs++] = md->variables[k].vr;
            }
        }
        for (k = 0; c != NULL && k < md->variable_count; ++k) {
            const probe_variable* v = &md->variables[k];
            const unsigned twice[2] = {v->vr, v->vr};
            const double max[1] = {DBL_MAX}, halves[2] = {1e308, 1e308};
            if (v->type != PROBE_REAL || v->causality != PROBE_INPUT) {
                continue;
            }
            ++inputs;
            fails += check_huge_seed(version, c, &book, outputs, n_outputs, twice, max, 1, v->name,
                                     &discarded);
            fails += check_huge_seed(version, c, &book, outputs, n_outputs, twice, halves, 2,
                                     v->name, &discarded);
        }
        CHECK(inputs == 0 || discarded > 0, "FMI %d: no huge seed of %d inputs overflowed", version,
              inputs);
        if (c != NULL) {
            free_either(version, c);
        }
        free(outputs);
    }
    return fails;
}

/* Sets every Real input to its start plus a ramp and steps from step * 0.01 s. */
static int step_with_inputs(int version, void* c, int step)
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    size_t k;
    for (k = 0; k < md->variable_count; ++k) {
        const probe_variable* v = &md->variables[k];
        if (v->type == PROBE_REAL && v->causality == PROBE_INPUT) {
            const double value = (v->has_start ? v->start : 0) + 0.01 * step;
            if (version == 2) {
                api2.SetReal(c, &v->vr, 1, &value);
            } else {
                api3.SetFloat64(c, &v->vr, 1, &value, 1);
            }
        }
    }
    return version == 2 ? (int)api2.DoStep(c, step * 0.01, 0.01, fmi2True)
                        : (int)step3(c, step * 0.01, 0.01);
}

/* Steps [from, to): every status and output, hashed. */
static uint64_t trace_steps(int version, void* c, int from, int to)
{
    uint64_t h = PROBE_HASH_START;
    values_read r;
    int step;
    size_t k;
    for (step = from; step < to; ++step) {
        h = probe_hash_u64(h, (uint64_t)step_with_inputs(version, c, step));
        h = probe_hash_u64(h,
                           (uint64_t)(version == 2 ? fmi2_read_all(c, &r) : fmi3_read_all(c, &r)));
        for (k = 0; k < r.n_reals; ++k) {
            h = probe_hash_double(h, r.reals[k]);
        }
        for (k = 0; k < r.n_integers; ++k) {
            h = probe_hash_u64(h, (uint64_t)(unsigned)r.integers[k]);
        }
    }
    return h;
}

static int get_state(int version, void* c, void** state)
{
    return version == 2 ? (int)api2.GetFMUstate(c, state) : (int)api3.GetFMUState(c, state);
}

static int set_state(int version, void* c, void* state)
{
    return version == 2 ? (int)api2.SetFMUstate(c, state) : (int)api3.SetFMUState(c, state);
}

static int serialize(int version, void* c, void* state, unsigned char** bytes, size_t* size)
{
    int status = version == 2 ? (int)api2.SerializedFMUstateSize(c, state, size)
                              : (int)api3.SerializedFMUStateSize(c, state, size);
    *bytes = status == 0 ? (unsigned char*)malloc(*size) : NULL;
    if (*bytes == NULL) {
        return 3;
    }
    return version == 2 ? (int)api2.SerializeFMUstate(c, state, (fmi2Byte*)*bytes, *size)
                        : (int)api3.SerializeFMUState(c, state, *bytes, *size);
}

static int deserialize(int version, void* c, const unsigned char* bytes, size_t size, void** state)
{
    return version == 2 ? (int)api2.DeSerializeFMUstate(c, (const fmi2Byte*)bytes, size, state)
                        : (int)api3.DeserializeFMUState(c, bytes, size, state);
}

/* How many times the state's payload holds the value `from`. */
static size_t occurrences(const unsigned char* bytes, size_t size, double from)
{
    const size_t header = 32;
    size_t k, found = 0;
    for (k = header; k + sizeof from <= size; ++k) {
        found += memcmp(bytes + k, &from, sizeof from) == 0;
    }
    return found;
}

/* The state's checksum made good again for its payload, as one who crafts it would. */
static void seal(unsigned char* bytes, size_t size)
{
    const size_t header = 32;
    uint64_t h = 0xcbf29ce484222325ULL;
    size_t k;
    for (k = header; k < size; ++k) {
        h = (h ^ bytes[k]) * 0x100000001b3ULL; /* FNV-1a, as fmu_state.c */
    }
    memcpy(bytes + 24, &h, sizeof h);
}

/* The state's bytes with every value `from` replaced by `to`, and the checksum made
 * good again. */
static void replace_and_seal(unsigned char* bytes, size_t size, double from, double to)
{
    const size_t header = 32;
    size_t k;
    for (k = header; k + sizeof from <= size; ++k) {
        if (memcmp(bytes + k, &from, sizeof from) == 0) {
            memcpy(bytes + k, &to, sizeof to);
        }
    }
    seal(bytes, size);
}

/* The state's bytes with its value `from` of a parameter or input (found once in the
 * payload) replaced by `to`, and the checksum made good again: a crafted state. */
static int craft_state(unsigned char* bytes, size_t size, double from, double to)
{
    if (occurrences(bytes, size, from) != 1) {
        return 0;
    }
    replace_and_seal(bytes, size, from, to);
    return 1;
}

/* A state whose checksum is good but one of whose values could never have been set,
 * below its variable's lower bound: refused, naming the variable (the FMU solves its
 * values without checking them again). The first parameter or input with a lower
 * bound whose value the state holds once is the one changed. One must be found where
 * a parameter has a bound: an input may have been set again since the state was taken
 * (a cylinder's length, the only bound of a scene without tunable numbers). */
static int check_crafted_state(int version, void* c, const unsigned char* bytes, size_t size,
                               const probe_log_book* book)
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    unsigned char* crafted = (unsigned char*)malloc(size);
    int fails = 0, tried = 0;
    size_t k;
    for (k = 0; k < md->variable_count && crafted != NULL; ++k) {
        const probe_variable* v = &md->variables[k];
        const unsigned vr = v->vr;
        double now = NAN;
        void* bad = NULL;
        if (v->type != PROBE_REAL || !v->has_min ||
            (v->causality != PROBE_PARAMETER && v->causality != PROBE_INPUT)) {
            continue;
        }
        tried += v->causality == PROBE_PARAMETER;
        memcpy(crafted, bytes, size);
        if ((version == 2 ? (int)api2.GetReal(c, &vr, 1, &now)
                          : (int)api3.GetFloat64(c, &vr, 1, &now, 1)) != 0 ||
            !craft_state(crafted, size, now, v->min - 1)) {
            continue;
        }
        CHECK(deserialize(version, c, crafted, size, &bad) == 3 && bad == NULL &&
                  strstr(book->last, "refused: ") != NULL && strstr(book->last, v->name) != NULL,
              "FMI %d: a state with %s = %g accepted: %s", version, v->name, v->min - 1,
              book->last);
        tried = -1;
        break;
    }
    /* a tailored FMU may hold every bounded value more than once (a length equal to
     * another): the generic dyads and the scenes must be checked */
    if (tried > 0 && strncmp(md->identifier, "tailored_", 9) == 0) {
        printf("    FMI %d: no bounded value held once in the state: not crafted\n", version);
    } else {
        CHECK(tried <= 0, "FMI %d: no bounded value found once in the state to change", version);
    }
    free(crafted);
    return fails;
}

/* A state whose checksum is good but which holds NaN for an input: refused, naming it
 * (as a set refuses it: the FMU solves its inputs without checking them again). The
 * input is set to a value of its own first, so that the state holds that value once. */
static int check_crafted_nan(int version)
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    const double mark = 0.6180339887498949;
    const probe_variable* v = NULL;
    probe_log_book book;
    void* c = version == 2 ? (void*)new_fmi2(&book, "nan") : (void*)new_fmi3(&book, "nan");
    void *state = NULL, *bad = NULL;
    unsigned char* bytes = NULL;
    size_t size = 0, k;
    int fails = 0, set;
    for (k = 0; k < md->variable_count && v == NULL; ++k) {
        if (md->variables[k].type == PROBE_REAL && md->variables[k].causality == PROBE_INPUT) {
            v = &md->variables[k];
        }
    }
    if (v != NULL && (version == 2 ? initialise_fmi2(c) : initialise_fmi3(c))) {
        set = version == 2 ? (int)api2.SetReal(c, &v->vr, 1, &mark)
                           : (int)api3.SetFloat64(c, &v->vr, 1, &mark, 1);
        CHECK(set == 0 && get_state(version, c, &state) == 0 &&
                  serialize(version, c, state, &bytes, &size) == 0 &&
                  craft_state(bytes, size, mark, NAN),
              "FMI %d: no state holding %s = %.17g once", version, v->name, mark);
        CHECK(bytes == NULL || deserialize(version, c, bytes, size, &bad) == 3,
              "FMI %d: a state with %s = NaN accepted", version, v->name);
        CHECK(bad == NULL && strstr(book.last, "refused: ") != NULL &&
                  strstr(book.last, v->name) != NULL,
              "FMI %d: the NaN in %s not named: %s", version, v->name, book.last);
    } else {
        CHECK(v == NULL, "FMI %d: initialise", version);
    }
    free(bytes);
    free_either(version, c);
    return fails;
}

/* Bytes that are not this FMU's state: damaged, cut short, or another instance's; and a
 * crafted one (check_crafted_state). */
static int check_refused_states(int version, void* c, void* other, unsigned char* bytes,
                                size_t size, probe_log_book* book)
{
    int fails = 0;
    void* state = NULL;
    bytes[size - 1] ^= 1;
    CHECK(deserialize(version, c, bytes, size, &state) == 3 && state == NULL,
          "FMI %d: a damaged state accepted", version);
    bytes[size - 1] ^= 1;
    CHECK(deserialize(version, c, bytes, size - 1, &state) == 3 && state == NULL,
          "FMI %d: a state cut short accepted", version);
    CHECK(deserialize(version, c, bytes, size, &state) == 0 && state != NULL,
          "FMI %d: its own state refused", version);
    CHECK(set_state(version, other, state) == 3, "FMI %d: another instance's state set", version);
    fails += check_crafted_state(version, c, bytes, size, book);
    fails += check_crafted_nan(version);
    return fails;
}

/* Save a state, run on, restore it and run again: the same statuses and outputs bit
 * for bit (for the drive, a roll back of its states); the same through serialized
 * bytes; and states that are not this instance's refused. States left unfreed go
 * with their instance (the ASan build's leak check). */
/* A plant's tolerances, set apart from each other (both are 1e-10 by default), so that
 * the state holds each bounded value once for check_crafted_state. */
static int tolerances_apart(int version, void* c)
{
    const probe_variable* rtol = probe_variable_named(version == 2 ? &md2 : &md3, "solver.rtol");
    const double value = 3e-10;
    if (rtol == NULL) {
        return 1;
    }
    return (version == 2 ? (int)api2.SetReal(c, &rtol->vr, 1, &value)
                         : (int)api3.SetFloat64(c, &rtol->vr, 1, &value, 1)) == 0;
}

static int test_fmu_state_round_trip(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book, other_book;
        void* c = version == 2 ? new_fmi2(&book, "state") : new_fmi3(&book, "state");
        void* other =
            version == 2 ? new_fmi2(&other_book, "other") : new_fmi3(&other_book, "other");
        void *saved = NULL, *restored = NULL;
        unsigned char* bytes = NULL;
        size_t size = 0;
        uint64_t first, again, from_bytes;
        CHECK(tolerances_apart(version, c) &&
                  (version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) && other != NULL,
              "FMI %d: set up", version);
        trace_steps(version, c, 0, 5);
        CHECK(get_state(version, c, &saved) == 0 && saved != NULL, "FMI %d: get state", version);
        first = trace_steps(version, c, 5, 15);
        CHECK(set_state(version, c, saved) == 0, "FMI %d: set state", version);
        again = trace_steps(version, c, 5, 15);
        CHECK(first == again, "FMI %d: the steps after a restored state differ", version);
        CHECK(serialize(version, c, saved, &bytes, &size) == 0 && size > 32, "FMI %d: serialize",
              version);
        CHECK(deserialize(version, c, bytes, size, &restored) == 0 &&
                  set_state(version, c, restored) == 0,
              "FMI %d: deserialize and set", version);
        from_bytes = trace_steps(version, c, 5, 15);
        CHECK(first == from_bytes, "FMI %d: the steps after a deserialized state differ", version);
        CHECK((version == 2 ? (int)api2.FreeFMUstate(c, &saved)
                            : (int)api3.FreeFMUState(c, &saved)) == 0 &&
                  saved == NULL,
              "FMI %d: free state", version);
        CHECK(get_state(version, c, &restored) == 0, "FMI %d: get into a state", version);
        if (bytes != NULL) {
            fails += check_refused_states(version, c, other, bytes, size, &book);
        }
        free(bytes);
        free_either(version, other);
        free_either(version, c);
    }
    return fails;
}

/* ---- the RRT FMUs against the C core -------------------------------------------------------- */

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
            /* as the FMU converts an angle */
            dyad_cos_sin(value, &((dyad_vec2*)(void*)member)->x, &((dyad_vec2*)(void*)member)->y);
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

/* The name without a trailing ".x" or ".y": the variables of one vector field. */
static size_t field_stem_length(const char* name)
{
    const size_t n = strlen(name);
    return n > 2 && name[n - 2] == '.' && (name[n - 1] == 'x' || name[n - 1] == 'y') ? n - 2 : n;
}

/* Every input and parameter made non-finite in turn, straight in the input block:
 * the model refuses it and blames a variable of the same field (the variable
 * itself, or the x of its vector), whatever the core's field numbering. */
static int test_rrt_bad_input_names_its_variable(void)
{
    int fails = 0;
    size_t k;
    for (k = 0; k < fmu_this_model.variable_count; ++k) {
        const fmu_variable* v = &fmu_this_model.variables[k];
        dyad_input in = dyad_input_default();
        dyad_result out;
        fmu_evaluation evaluation;
        size_t j;
        if (v->causality == FMU_OUTPUT || v->target == FMU_TARGET_SETTING) {
            continue; /* a setting is the FMU layer's: the model never reads it */
        }
        for (j = 0; j < fmu_this_model.variable_count; ++j) {
            const fmu_variable* w = &fmu_this_model.variables[j];
            char* member = (char*)&in + w->offset;
            const double value = j == k ? (double)NAN : w->start;
            if (w->target == FMU_TARGET_INPUT_ANGLE) {
                dyad_cos_sin(value, &((dyad_vec2*)(void*)member)->x,
                             &((dyad_vec2*)(void*)member)->y);
            } else if (w->target == FMU_TARGET_INPUT_REAL) {
                *(double*)(void*)member = value;
            }
        }
        fmu_this_model.behaviour->evaluate(&fmu_this_model, &in, &out, &evaluation);
        CHECK(evaluation.status == FMU_ERROR && evaluation.bad_variable >= 0,
              "%s = NaN: status %d, blamed variable %d", v->name, (int)evaluation.status,
              evaluation.bad_variable);
        if (evaluation.status == FMU_ERROR && evaluation.bad_variable >= 0) {
            const char* blamed = fmu_this_model.variables[evaluation.bad_variable].name;
            const size_t stem = field_stem_length(v->name);
            CHECK(field_stem_length(blamed) == stem && strncmp(blamed, v->name, stem) == 0,
                  "%s = NaN blames %s", v->name, blamed);
        }
    }
    return fails;
}

static int test_rrt_fmi2_core(void)
{
    int fails = 0;
    probe_log_book book_a, book_b;
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
        CHECK(api2.SetReal(a, set_a, 3, val_a) == fmi2OK, "set a");
        CHECK(api2.SetReal(b, set_a, 3, val_b) == fmi2OK, "set b");
        CHECK(api2.DoStep(a, step * 0.01, 0.01, fmi2True) == fmi2OK, "step a");
        CHECK(api2.DoStep(b, step * 0.01, 0.01, fmi2True) == fmi2OK, "step b");
        CHECK(api2.GetReal(a, outs, n, got) == fmi2OK, "get a");
        want = core_result(set_a, val_a, 3);
        CHECK(outputs_match(got, &want), "instance a differs from the core");
        CHECK(api2.GetReal(b, outs, n, got) == fmi2OK, "get b");
        want = core_result(set_a, val_b, 3);
        CHECK(outputs_match(got, &want), "instance b differs from the core");
    }
    api2.FreeInstance(a);
    api2.FreeInstance(b);
    return fails;
}

typedef int (*rows_entry)(const char* token, const unsigned int vr_p[], size_t n_p,
                          const double p[], const unsigned int vr_i[], size_t n_i, const double x[],
                          const unsigned int vr_o[], size_t n_o, double y[], int status[],
                          size_t rows);

/* dyadfmu_evaluate_rows of one binary: each row as the core solves it, a row with a NaN
 * input refused alone (status error, NaN outputs), a bad call refused whole. */
static int rows_match_the_core(void* library, const char* token)
{
    int fails = 0;
    rows_entry evaluate;
    const unsigned set[3] = {vr_of("link_n.angle"), vr_of("link_m.force.x"), vr_of("link_n.omega")};
    const double x[3][3] = {{0.3, -2500, 40}, {-0.5, 700, -15}, {0.1, NAN, 3}};
    unsigned outs[32];
    double y[3 * 32]; /* rows of n outputs */
    int status[3] = {-1, -1, -1};
    const size_t n = real_outputs(outs);
    size_t k;
    *(void**)(&evaluate) = dlsym(library, "dyadfmu_evaluate_rows");
    CHECK(evaluate != NULL, "dyadfmu_evaluate_rows is not exported");
    if (evaluate == NULL) {
        return fails;
    }
    CHECK(evaluate(token, NULL, 0, NULL, set, 3, &x[0][0], outs, n, y, status, 3) == 0,
          "a valid call");
    for (k = 0; k < 2; ++k) {
        const dyad_result want = core_result(set, x[k], 3);
        CHECK(status[k] == 0 && outputs_match(y + k * n, &want), "row %zu differs from the core",
              k);
    }
    CHECK(status[2] == 3 && isnan(y[2 * n]) && isnan(y[3 * n - 1]), "a NaN input: status %d",
          status[2]);
    CHECK(evaluate(token, NULL, 0, NULL, outs, 1, &x[0][0], outs, n, y, status, 1) == 3,
          "an output set is refused");
    CHECK(evaluate("not the token", NULL, 0, NULL, set, 3, &x[0][0], outs, n, y, status, 1) == 4,
          "a wrong token is refused");
    return fails;
}

typedef int (*columns_entry)(const char* token, const unsigned int vr_x[], size_t n_x,
                             const double* const x[], const ptrdiff_t x_step[],
                             const unsigned int vr_y[], size_t n_y, double* const y[],
                             const ptrdiff_t y_step[], int status[], size_t count);

/* dyadfmu_evaluate_columns of one binary: the inputs read from the rows of one matrix (a
 * stride of 3) and one held for every sample (a step of 0), the outputs written into the
 * columns of another, each sample what dyadfmu_evaluate_rows gives bit for bit (a NaN
 * input too: status error, NaN outputs); a bad call refused whole, nothing written. */
static int columns_match_the_rows(void* library, const char* token)
{
    int fails = 0;
    columns_entry columns;
    rows_entry rows;
    const unsigned set[3] = {vr_of("link_n.angle"), vr_of("link_m.force.x"), vr_of("link_n.omega")};
    const double x[3][3] = {{0.3, -2500, 40}, {-0.5, 700, 40}, {0.1, NAN, 40}};
    const double* const from[3] = {&x[0][0], &x[0][1], &x[0][2]};
    const ptrdiff_t x_step[3] = {3, 3, 0};
    unsigned outs[32];
    double y[3 * 32], want[3 * 32];
    double* into[32];
    ptrdiff_t y_step[32];
    int status[3] = {-1, -1, -1}, want_status[3] = {-1, -1, -1};
    const size_t n = real_outputs(outs);
    size_t k;
    *(void**)(&columns) = dlsym(library, "dyadfmu_evaluate_columns");
    *(void**)(&rows) = dlsym(library, "dyadfmu_evaluate_rows");
    CHECK(columns != NULL && rows != NULL, "dyadfmu_evaluate_columns is not exported");
    if (columns == NULL || rows == NULL) {
        return fails;
    }
    for (k = 0; k < n; ++k) {
        into[k] = y + k; /* the samples' rows of n outputs */
        y_step[k] = (ptrdiff_t)n;
    }
    CHECK(rows(token, NULL, 0, NULL, set, 3, &x[0][0], outs, n, want, want_status, 3) == 0 &&
              columns(token, set, 3, from, x_step, outs, n, into, y_step, status, 3) == 0,
          "valid calls");
    CHECK(memcmp(status, want_status, sizeof status) == 0 && status[2] == 3, "statuses %d %d %d",
          status[0], status[1], status[2]);
    for (k = 0; k < 3 * n; ++k) {
        CHECK(memcmp(&y[k], &want[k], sizeof y[k]) == 0, "value %zu: %g, not %g", k, y[k], want[k]);
    }
    y[0] = 12345.0;
    status[0] = -1;
    CHECK(columns(token, outs, 1, from, x_step, outs, n, into, y_step, status, 1) == 3,
          "an output set is refused");
    CHECK(columns("not the token", set, 3, from, x_step, outs, n, into, y_step, status, 1) == 4,
          "a wrong token is refused");
    CHECK(columns(token, set, 3, from, x_step, outs, n, into, y_step, NULL, 1) == 3,
          "no status array is refused");
    CHECK(y[0] == 12345.0 && status[0] == -1, "a refused call wrote");
    return fails;
}

static int test_rrt_columns_match_the_rows(void)
{
    return columns_match_the_rows(api2.library, md2.token) +
           columns_match_the_rows(api3.library, md3.token);
}

static int test_rrt_rows_match_the_core(void)
{
    return rows_match_the_core(api2.library, md2.token) +
           rows_match_the_core(api3.library, md3.token);
}

static int test_rrt_fmi2_singular(void)
{
    int fails = 0;
    probe_log_book book;
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
    CHECK(api2.DoStep(c, 0, 0.01, fmi2True) == fmi2OK, "first step");
    CHECK(api2.SetReal(c, &rod, 1, &normal) == fmi2OK, "set");
    CHECK(api2.DoStep(c, 0.01, 0.01, fmi2True) == fmi2Discard, "singular step discarded");
    CHECK(book.last_status == fmi2Discard && strstr(book.last, "singular") != NULL,
          "logged reason: %s", book.last);
    CHECK(api2.GetRealStatus(c, fmi2LastSuccessfulTime, &last_time) == fmi2OK && last_time == 0.01,
          "last successful time %g", last_time);
    CHECK(api2.GetBooleanStatus(c, fmi2Terminated, &terminated) == fmi2OK && terminated,
          "asks to terminate");
    api2.GetReal(c, outs, n, got);
    for (k = 0; k < 6; ++k) {
        CHECK(isnan(got[k]), "reaction %zu = %g, expected NaN", k, got[k]);
    }
    CHECK(api2.GetInteger(c, &status_vr, 1, &status) == fmi2OK && status == 1, "status %d", status);
    CHECK(api2.SetReal(c, &rod, 1, &fine) == fmi2OK &&
              api2.DoStep(c, 0.01, 0.01, fmi2True) == fmi2OK,
          "usable again once the input is fixed");
    api2.FreeInstance(c);
    return fails;
}

static int test_rrt_fmi3_core(void)
{
    int fails = 0;
    probe_log_book book;
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
    CHECK(initialise_fmi3(a) && initialise_fmi3(b), "initialise");
    CHECK(api3.SetFloat64(a, set, 2, val_a, 2) == fmi3OK, "set a");
    CHECK(api3.SetFloat64(b, set, 2, val_b, 2) == fmi3OK, "set b");
    CHECK(api3.DoStep(a, 0, 0.01, fmi3True, &event, &terminate, &early, &last) == fmi3OK &&
              !terminate && last == 0.01,
          "step a");
    CHECK(step3(b, 0, 0.01) == fmi3OK, "step b");
    CHECK(api3.GetFloat64(a, outs, n, got, n) == fmi3OK, "get a");
    want = core_result(set, val_a, 2);
    CHECK(outputs_match(got, &want), "instance a differs from the core");
    CHECK(api3.GetFloat64(b, outs, n, got, n) == fmi3OK, "get b");
    want = core_result(set, val_b, 2);
    CHECK(outputs_match(got, &want), "instance b differs from the core");
    api3.FreeInstance(a);
    api3.FreeInstance(b);
    return fails;
}

static int test_rrt_fmi3_singular(void)
{
    int fails = 0;
    probe_log_book book;
    fmi3Instance c = new_fmi3(&book, "c");
    const unsigned rod = vr_of("link_n.angle");
    const unsigned status_vr = vr_of("status");
    const double normal = -1.5707963267948966;
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    fmi3Int32 status;
    CHECK(initialise_fmi3(c), "initialise");
    CHECK(api3.SetFloat64(c, &rod, 1, &normal, 1) == fmi3OK, "set");
    CHECK(api3.DoStep(c, 0, 0.01, fmi3True, &event, &terminate, &early, &last) == fmi3Discard &&
              terminate && last == 0,
          "singular step");
    CHECK(strstr(book.last, "singular") != NULL, "logged: %s", book.last);
    CHECK(api3.GetInt32(c, &status_vr, 1, &status, 1) == fmi3OK && status == 1, "status %d",
          (int)status);
    api3.FreeInstance(c);
    return fails;
}

/* ---- both: exports and bad communication steps ---------------------------------------------- */

static int test_exports_only_fmi(void)
{
    static const char* const internal[] = {
        "fmu_instantiate",   "fmu_this_model",      "fmu_log",           "fmu_do_step",
        "fmu_dyad_evaluate", "fmu_drive_behaviour", "dyad_solve_rrr",    "dyad_solve_rrt",
        "dyad_solve_rtr",    "dyad_solve_trt",      "dyad_solve_rtt",    "dyad_react_rrr",
        "dyad_react_rrt",    "dyad_field_name",     "dyad_input_default"};
    int fails = 0;
    size_t k;
    for (k = 0; k < sizeof internal / sizeof internal[0]; ++k) {
        CHECK(dlsym(api2.library, internal[k]) == NULL && dlsym(api3.library, internal[k]) == NULL,
              "%s is exported: the binaries export the FMI API only", internal[k]);
    }
    return fails;
}

typedef struct bad_step {
    double t, h; /* s */
} bad_step;

/* Communication points and step sizes doStep must refuse with Error and a
 * message, changing nothing: among them end times t + h that overflow or round
 * back to t (issue 12, finding 7). */
static const bad_step bad_steps[] = {
    {0, 0},           {0, -0.0},          {0, -1e-3},
    {0, NAN},         {0, INFINITY},      {0, -INFINITY},
    {NAN, 1e-3},      {INFINITY, 1e-3},   {-INFINITY, 1e-3},
    {DBL_MAX, 1e300}, {DBL_MAX, DBL_MAX}, {-DBL_MAX, -1e-3},
    {1e300, 1e-3},
};

static void free_either(int version, void* c)
{
    if (version == 2) {
        api2.FreeInstance(c);
    } else {
        api3.FreeInstance(c);
    }
}

static int test_bad_steps(void)
{
    int fails = 0, version;
    size_t k;
    for (version = 2; version <= 3; ++version) {
        for (k = 0; k < sizeof bad_steps / sizeof bad_steps[0]; ++k) {
            const bad_step* b = &bad_steps[k];
            probe_log_book book;
            values_read before, after;
            void* c = version == 2 ? new_fmi2(&book, "steps") : new_fmi3(&book, "steps");
            int status, read;
            if (version == 2) {
                read = initialise_fmi2(c) && fmi2_read_all(c, &before);
                status = api2.DoStep(c, b->t, b->h, fmi2True);
                read &= fmi2_read_all(c, &after);
            } else {
                read = initialise_fmi3(c) && fmi3_read_all(c, &before);
                status = step3(c, b->t, b->h);
                read &= fmi3_read_all(c, &after);
            }
            CHECK(read && status == 3 && logged_error(&book, 0) && same_values(&before, &after),
                  "FMI %d doStep(%g, %g): status %d, expected Error, a message and no change (%s)",
                  version, b->t, b->h, status, book.last);
            free_either(version, c);
        }
    }
    return fails;
}

/* An experiment announced from `start` to `stop` (stop_defined): FMI 2's
 * setupExperiment, FMI 3's enterInitializationMode; its status. */
static int announce(int version, void* c, double start, int stop_defined, double stop)
{
    if (version == 2) {
        return (int)api2.SetupExperiment(c, fmi2False, 0, start, stop_defined, stop);
    }
    return (int)api3.EnterInitializationMode(c, fmi3False, 0, start, stop_defined, stop);
}

static int step_either(int version, void* c, double t, double h)
{
    return version == 2 ? (int)api2.DoStep(c, t, h, fmi2True) : (int)step3(c, t, h);
}

static int initialise_from(int version, void* c, double start, double stop)
{
    if (announce(version, c, start, 1, stop) != 0) {
        return 0;
    }
    return version == 2 ? api2.EnterInitializationMode(c) == fmi2OK &&
                              api2.ExitInitializationMode(c) == fmi2OK
                        : api3.ExitInitializationMode(c) == fmi3OK;
}

/* An experiment whose stop is before its start, or whose times are not finite, is
 * refused with a message. */
static int check_bad_experiments(int version)
{
    static const double experiments[][2] = {{1, 0.5},      {0, -1e-300}, {NAN, 1},
                                            {INFINITY, 1}, {0, NAN},     {0, INFINITY}};
    int fails = 0;
    size_t k;
    for (k = 0; k < sizeof experiments / sizeof experiments[0]; ++k) {
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "experiment") : new_fmi3(&book, "experiment");
        const int status = announce(version, c, experiments[k][0], 1, experiments[k][1]);
        CHECK(status == 3 && logged_error(&book, 0),
              "FMI %d: startTime %g, stopTime %g: status %d, expected Error and a message (%s)",
              version, experiments[k][0], experiments[k][1], status, book.last);
        free_either(version, c);
    }
    return fails;
}

/* Ten steps of a tenth of the span from 0 reach a stop at the span (their sum rounds
 * below it), and a step of the whole interval does too; a step past the stop is
 * refused with a message and changes nothing. The span is 1 s, or 0.05 s for a plant:
 * with no effort the leg falls to a dead centre in 0.08 s. */
static int check_steps_to_the_stop(int version)
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    const double span = probe_variable_named(md, "solver.rtol") != NULL ? 0.05 : 1;
    int fails = 0, ok = 1, k, status;
    double t = 0;
    probe_log_book book;
    values_read before, after;
    void* c = version == 2 ? new_fmi2(&book, "stop") : new_fmi3(&book, "stop");
    CHECK(initialise_from(version, c, 0, span), "FMI %d: initialised with a stop", version);
    for (k = 0; k < 10; ++k, t += span / 10) {
        ok &= step_either(version, c, t, span / 10) == 0;
    }
    CHECK(ok && t < span, "FMI %d: ten steps of %g s to the stop at %g s, their sum %.17g (%s)",
          version, span / 10, span, t, book.last);
    ok = version == 2 ? fmi2_read_all(c, &before) : fmi3_read_all(c, &before);
    status = step_either(version, c, t, 1e-3);
    ok &= version == 2 ? fmi2_read_all(c, &after) : fmi3_read_all(c, &after);
    CHECK(ok && status == 3 && strstr(book.last, "stopTime") != NULL &&
              same_values(&before, &after),
          "FMI %d: doStep(%.17g, 1e-3) past the stop: status %d, expected Error naming stopTime "
          "and no change (%s)",
          version, t, status, book.last);
    free_either(version, c);
    c = version == 2 ? new_fmi2(&book, "stop") : new_fmi3(&book, "stop");
    CHECK(initialise_from(version, c, -3, -3 + span) && step_either(version, c, -3, span) == 0,
          "FMI %d: one step over the whole experiment (%s)", version, book.last);
    free_either(version, c);
    return fails;
}

static int test_experiment_stop(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        fails += check_bad_experiments(version);
        fails += check_steps_to_the_stop(version);
    }
    return fails;
}

/* ---- the drive ------------------------------------------------------------------------------ */

/* Inputs the drive refuses only when it evaluates them (inertia + load.inertia
 * must be positive): every call that returns Error says why, not only the
 * first one after the inputs changed. */
static int test_drive_errors_logged_every_time(void)
{
    int fails = 0, version, k;
    for (version = 2; version <= 3; ++version) {
        const probe_model* md = version == 2 ? &md2 : &md3;
        const probe_variable* load = probe_variable_named(md, "load.inertia");
        const probe_variable* epsilon = probe_variable_named(md, "crank.epsilon");
        const double negative = -1;
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "drive") : new_fmi3(&book, "drive");
        double value;
        CHECK(load != NULL && epsilon != NULL, "no load.inertia or crank.epsilon");
        if (load == NULL || epsilon == NULL) {
            free_either(version, c);
            continue;
        }
        if (version == 2) {
            CHECK(api2.SetReal(c, &load->vr, 1, &negative) == fmi2OK &&
                      api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
                      api2.EnterInitializationMode(c) == fmi2OK,
                  "FMI 2: set up");
        } else {
            CHECK(api3.SetFloat64(c, &load->vr, 1, &negative, 1) == fmi3OK &&
                      api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK,
                  "FMI 3: set up");
        }
        for (k = 0; k < 3; ++k) {
            long count = book.count;
            const int exit_status = version == 2 ? (int)api2.ExitInitializationMode(c)
                                                 : (int)api3.ExitInitializationMode(c);
            CHECK(exit_status == 3 && logged_error(&book, count) &&
                      strstr(book.last, "load.inertia") != NULL,
                  "FMI %d: exitInitializationMode %d: status %d, message '%s'", version, k + 1,
                  exit_status, book.last);
            count = book.count;
            CHECK((version == 2 ? (int)api2.GetReal(c, &epsilon->vr, 1, &value)
                                : (int)api3.GetFloat64(c, &epsilon->vr, 1, &value, 1)) == 3 &&
                      logged_error(&book, count) && isnan(value),
                  "FMI %d: get crank.epsilon %d: message '%s'", version, k + 1, book.last);
        }
        free_either(version, c);
    }
    return fails;
}

/* Sets one Real variable by name before initialization; 1 if accepted. */
static int set_named(int version, void* c, const char* name, double value)
{
    const probe_variable* v = probe_variable_named(version == 2 ? &md2 : &md3, name);
    if (v == NULL) {
        return 0;
    }
    return version == 2 ? api2.SetReal(c, &v->vr, 1, &value) == fmi2OK
                        : api3.SetFloat64(c, &v->vr, 1, &value, 1) == fmi3OK;
}

static double get_named(int version, void* c, const char* name)
{
    const probe_variable* v = probe_variable_named(version == 2 ? &md2 : &md3, name);
    double value = -12345.678;
    if (v != NULL) {
        (void)(version == 2 ? (int)api2.GetReal(c, &v->vr, 1, &value)
                            : (int)api3.GetFloat64(c, &v->vr, 1, &value, 1));
    }
    return value;
}

static int get_status_output(int version, void* c)
{
    const probe_variable* v = probe_variable_named(version == 2 ? &md2 : &md3, "status");
    int value = -1;
    if (v != NULL) {
        (void)(version == 2 ? (int)api2.GetInteger(c, &v->vr, 1, &value)
                            : (int)api3.GetInt32(c, &v->vr, 1, &value, 1));
    }
    return value;
}

static int enter_initialization(int version, void* c)
{
    return version == 2 ? api2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK &&
                              api2.EnterInitializationMode(c) == fmi2OK
                        : api3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK;
}

/* A step that needs more substeps than the drive's cap (1e6; h = 1e16 s with
 * the start values, issue 12 finding 5) is refused with Error and a message,
 * and the state stays where it was; a step within the cap moves it. */
static int test_drive_step_beyond_cap(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "cap") : new_fmi3(&book, "cap");
        const int ready = version == 2 ? initialise_fmi2(c) : initialise_fmi3(c);
        const double angle = get_named(version, c, "crank.angle");
        const double omega = get_named(version, c, "crank.omega");
        const long count = book.count;
        const int status =
            version == 2 ? (int)api2.DoStep(c, 0, 1e16, fmi2True) : (int)step3(c, 0, 1e16);
        CHECK(ready && status == 3 && logged_error(&book, count) &&
                  strstr(book.last, "substeps") != NULL &&
                  probe_bits(get_named(version, c, "crank.angle")) == probe_bits(angle) &&
                  probe_bits(get_named(version, c, "crank.omega")) == probe_bits(omega),
              "FMI %d: doStep(0, 1e16): status %d, message '%s'", version, status, book.last);
        free_either(version, c);
        c = version == 2 ? new_fmi2(&book, "cap") : new_fmi3(&book, "cap");
        CHECK((version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) &&
                  (version == 2 ? (int)api2.DoStep(c, 0, 1, fmi2True) : (int)step3(c, 0, 1)) == 0 &&
                  get_named(version, c, "crank.angle") != angle,
              "FMI %d: doStep(0, 1) within the cap: '%s'", version, book.last);
        free_either(version, c);
    }
    return fails;
}

/* No drive output is ever infinite: a load torque of -DBL_MAX passes the
 * setter and overflows the acceleration (issue 12 finding 6): status 3,
 * crank.epsilon NaN; a motor torque that overflows itself is NaN even when the
 * inertia check fails first (status 2); crank.angle and crank.omega are the
 * states, finite whatever the status. */
static int test_drive_outputs_never_infinite(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "finite") : new_fmi3(&book, "finite");
        double epsilon, torque;
        int status;
        CHECK(set_named(version, c, "load.torque", -DBL_MAX) && enter_initialization(version, c),
              "FMI %d: set load.torque = -DBL_MAX", version);
        (void)(version == 2 ? (int)api2.ExitInitializationMode(c)
                            : (int)api3.ExitInitializationMode(c));
        epsilon = get_named(version, c, "crank.epsilon");
        status = get_status_output(version, c);
        CHECK(status == 3 && isnan(epsilon) && isfinite(get_named(version, c, "crank.angle")) &&
                  isfinite(get_named(version, c, "crank.omega")),
              "FMI %d: load.torque = -DBL_MAX: status %d, crank.epsilon %g", version, status,
              epsilon);
        free_either(version, c);

        c = version == 2 ? new_fmi2(&book, "finite") : new_fmi3(&book, "finite");
        /* speed / no_load_speed = 30 / DBL_MIN overflows the motor torque */
        CHECK(set_named(version, c, "motor.no_load_speed", DBL_MIN) &&
                  set_named(version, c, "load.inertia", -1) && enter_initialization(version, c),
              "FMI %d: set no_load_speed = DBL_MIN, load.inertia = -1", version);
        torque = get_named(version, c, "motor.torque");
        status = get_status_output(version, c);
        CHECK(status == 2 && isnan(torque) && isnan(get_named(version, c, "crank.epsilon")) &&
                  isfinite(get_named(version, c, "crank.angle")) &&
                  isfinite(get_named(version, c, "crank.omega")),
              "FMI %d: an overflowing motor torque with an invalid inertia: status %d, "
              "motor.torque %g",
              version, status, torque);
        CHECK(set_named(version, c, "load.inertia", 0) &&
                  isnan(get_named(version, c, "motor.torque")) &&
                  get_status_output(version, c) == 3,
              "FMI %d: the same with a valid inertia: status %d", version,
              get_status_output(version, c));
        free_either(version, c);
    }
    return fails;
}

/* A step whose end state is finite but whose outputs there overflow (a crank's
 * centre of mass 1e308 m out, turned by the step into the direction gravity
 * acts on) is discarded, and the state is kept, as the last successful time
 * says: the next step starts where this one did. */
static int test_drive_discard_keeps_state(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "keep") : new_fmi3(&book, "keep");
        double angle, omega;
        int status;
        CHECK(set_named(version, c, "motor.stall_torque", 1.6361668717536812e-76) &&
                  set_named(version, c, "crank.mass", 1.132571408184845) &&
                  set_named(version, c, "crank.com.y", 1e308) &&
                  set_named(version, c, "load.inertia", 0.99527050589162336) &&
                  set_named(version, c, "start.speed", 1e-300) &&
                  (version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) &&
                  get_status_output(version, c) == 0,
              "FMI %d: set up", version);
        angle = get_named(version, c, "crank.angle");
        omega = get_named(version, c, "crank.omega");
        status = version == 2 ? (int)api2.DoStep(c, 0, 0.0022494449308296154, fmi2True)
                              : (int)step3(c, 0, 0.0022494449308296154);
        CHECK(status == 2 &&
                  probe_bits(get_named(version, c, "crank.angle")) == probe_bits(angle) &&
                  probe_bits(get_named(version, c, "crank.omega")) == probe_bits(omega) &&
                  get_status_output(version, c) == 0,
              "FMI %d: doStep: status %d, state (%g, %g) from (%g, %g), status output %d", version,
              status, get_named(version, c, "crank.angle"), get_named(version, c, "crank.omega"),
              angle, omega, get_status_output(version, c));
        free_either(version, c);
    }
    return fails;
}

/* The drive steps on from where its states are, within rounding, or from a restored
 * FMU state's time; a step from elsewhere is refused with a message and moves
 * nothing. */
static int test_drive_steps_on_from_its_time(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "time") : new_fmi3(&book, "time");
        void* saved = NULL;
        double angle, omega;
        int status, restored;
        CHECK((version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) &&
                  step_either(version, c, 0, 0.01) == 0,
              "FMI %d: initialised, one step (%s)", version, book.last);
        angle = get_named(version, c, "crank.angle");
        omega = get_named(version, c, "crank.omega");
        status = step_either(version, c, 0.5, 0.01);
        CHECK(status == 3 && strstr(book.last, "currentCommunicationPoint") != NULL &&
                  probe_bits(get_named(version, c, "crank.angle")) == probe_bits(angle) &&
                  probe_bits(get_named(version, c, "crank.omega")) == probe_bits(omega),
              "FMI %d: doStep(0.5, 0.01) with the states at 0.01 s: status %d, expected Error "
              "and the state kept (%s)",
              version, status, book.last);
        free_either(version, c);
        c = version == 2 ? new_fmi2(&book, "time") : new_fmi3(&book, "time");
        restored = (version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) &&
                   step_either(version, c, 0, 0.01) == 0 &&
                   (version == 2 ? api2.GetFMUstate(c, &saved) == fmi2OK
                                 : api3.GetFMUState(c, &saved) == fmi3OK) &&
                   step_either(version, c, 0.01 * (1 + 1e-12), 0.01) == 0 &&
                   (version == 2 ? api2.SetFMUstate(c, saved) == fmi2OK
                                 : api3.SetFMUState(c, saved) == fmi3OK) &&
                   step_either(version, c, 0.01, 0.02) == 0;
        CHECK(restored,
              "FMI %d: a step from within rounding of the states' time, and one from "
              "a restored state's time (%s)",
              version, book.last);
        free_either(version, c);
    }
    return fails;
}

/* A state whose checksum is good but whose crank speed no step could have reached
 * (NaN, in the states and in the outputs that show them): refused, naming it. */
static int test_drive_crafted_state(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "craft") : new_fmi3(&book, "craft");
        void *state = NULL, *bad = NULL;
        unsigned char* bytes = NULL;
        size_t size = 0;
        double omega = NAN;
        CHECK((version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) &&
                  step_either(version, c, 0, 0.01) == 0 &&
                  (omega = get_named(version, c, "crank.omega")) != 0 &&
                  get_state(version, c, &state) == 0 &&
                  serialize(version, c, state, &bytes, &size) == 0,
              "FMI %d: a state after one step (%s)", version, book.last);
        CHECK(bytes != NULL && occurrences(bytes, size, omega) >= 1,
              "FMI %d: the state does not hold crank.omega = %.17g", version, omega);
        if (bytes != NULL) {
            replace_and_seal(bytes, size, omega, NAN);
            CHECK(deserialize(version, c, bytes, size, &bad) == 3 && bad == NULL &&
                      strstr(book.last, "crank.omega") != NULL,
                  "FMI %d: a state with crank.omega = NaN accepted: %s", version, book.last);
        }
        free(bytes);
        free_either(version, c);
    }
    return fails;
}

/* The time reached (FMI 3: the variable time; FMI 2: the last successful time). */
static double time_reached(int version, void* c)
{
    const unsigned vr = 0;
    double t = NAN;
    (void)(version == 2 ? (int)api2.GetRealStatus(c, fmi2LastSuccessfulTime, &t)
                        : (int)api3.GetFloat64(c, &vr, 1, &t, 1));
    return t;
}

/* A step the model refuses with Error (inertia + load.inertia not positive), asked from
 * one ulp after the time reached (within the rounding a step from there allows): the
 * time, the last successful time and the terminate flag stay where they were, so that
 * the state taken then is one a restore accepts (the last successful time never after
 * the time). */
static int test_drive_refused_step_keeps_time(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book;
        void* c = version == 2 ? new_fmi2(&book, "refused") : new_fmi3(&book, "refused");
        void *state = NULL, *restored = NULL;
        unsigned char* bytes = NULL;
        size_t size = 0;
        const double t = 0.01;
        CHECK((version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) &&
                  step_either(version, c, 0, t) == 0 && set_named(version, c, "load.inertia", -1),
              "FMI %d: set up (%s)", version, book.last);
        CHECK(step_either(version, c, nextafter(t, 1), 0.01) == 3 &&
                  strstr(book.last, "inertia") != NULL,
              "FMI %d: the step with inertia + load.inertia < 0 not refused: %s", version,
              book.last);
        CHECK(probe_bits(time_reached(version, c)) == probe_bits(t),
              "FMI %d: after a refused step, the time reads %.17g, not %.17g", version,
              time_reached(version, c), t);
        CHECK(get_state(version, c, &state) == 0 &&
                  serialize(version, c, state, &bytes, &size) == 0 &&
                  deserialize(version, c, bytes, size, &restored) == 0 &&
                  set_state(version, c, restored) == 0,
              "FMI %d: the state after a refused step is not restored: %s", version, book.last);
        free(bytes);
        free_either(version, c);
    }
    return fails;
}

static const named_test drive_tests[] = {
    {"drive_refused_step_keeps_time", test_drive_refused_step_keeps_time},
    {"drive_errors_logged_every_time", test_drive_errors_logged_every_time},
    {"drive_step_beyond_cap", test_drive_step_beyond_cap},
    {"drive_outputs_never_infinite", test_drive_outputs_never_infinite},
    {"drive_discard_keeps_state", test_drive_discard_keeps_state},
    {"drive_steps_on_from_its_time", test_drive_steps_on_from_its_time},
    {"drive_crafted_state", test_drive_crafted_state},
};

/* ---- both: a restored FMU state is evaluated again ------------------------------------------ */

/* The instance's state as serialized bytes (the state itself goes with the instance),
 * or NULL. */
static unsigned char* state_bytes(int version, void* c, size_t* size)
{
    void* state = NULL;
    unsigned char* bytes = NULL;
    if (get_state(version, c, &state) != 0 || serialize(version, c, state, &bytes, size) != 0) {
        free(bytes);
        return NULL;
    }
    return bytes;
}

static int read_all(int version, void* c, values_read* r)
{
    return version == 2 ? fmi2_read_all(c, r) : fmi3_read_all(c, r);
}

/* An instance after a step with `v` = `value` (its outputs read, so evaluated); NULL
 * if it cannot get there. */
static void* stepped_with(int version, probe_log_book* book, const probe_variable* v, double value)
{
    void* c = version == 2 ? (void*)new_fmi2(book, "crafted") : (void*)new_fmi3(book, "crafted");
    values_read r;
    if (c != NULL && (version == 2 ? initialise_fmi2(c) : initialise_fmi3(c)) &&
        (v == NULL || set_named(version, c, v->name, value)) &&
        step_either(version, c, 0, 0.01) != 3 && read_all(version, c, &r)) {
        return c;
    }
    free_either(version, c);
    return NULL;
}

/* 1 if the outputs in `a` and `b` (read by read_all) are the same bit for bit. */
static int same_outputs(const probe_model* md, const values_read* a, const values_read* b)
{
    size_t k, at = 0;
    for (k = 0; k < md->variable_count; ++k) {
        const probe_variable* v = &md->variables[k];
        if (v->type == PROBE_REAL && v->causality == PROBE_OUTPUT &&
            probe_bits(a->reals[at]) != probe_bits(b->reals[at])) {
            return 0;
        }
        at += v->type == PROBE_REAL;
    }
    return a->n_integers == b->n_integers &&
           memcmp(a->integers, b->integers, a->n_integers * sizeof a->integers[0]) == 0;
}

/* The instance `ref` (stepped with v = from) with v = to: its values read into
 * `expected`; 1 if its outputs changed (v changes the outputs). */
static int input_changes_outputs(int version, void* ref, const probe_variable* v, double to,
                                 values_read* expected)
{
    values_read before;
    return read_all(version, ref, &before) && set_named(version, ref, v->name, to) &&
           read_all(version, ref, expected) &&
           !same_outputs(version == 2 ? &md2 : &md3, &before, expected);
}

/* A state whose input changed in its bytes, from 0.3 to 1.0 (0.3 one ulp up, so that no
 * other value of the state is it), restores the outputs of 1.0, before and after a step:
 * a restored state keeps no output, it evaluates again. The input is the first (an
 * angle first) whose change changes the outputs. */
static int check_input_changed(int version, const probe_variable* v, int* found)
{
    const double from = nextafter(0.3, 1), to = 1.0;
    probe_log_book book, ref_book;
    void *c, *ref, *state = NULL;
    values_read restored, expected;
    unsigned char* bytes = NULL;
    size_t size = 0;
    int fails = 0;
    if ((v->has_min && v->min > from) || (v->has_max && v->max < to)) {
        return 0;
    }
    c = stepped_with(version, &book, v, from);
    ref = stepped_with(version, &ref_book, v, from);
    if (c != NULL && ref != NULL && input_changes_outputs(version, ref, v, to, &expected)) {
        *found = 1;
        CHECK((bytes = state_bytes(version, c, &size)) != NULL &&
                  occurrences(bytes, size, from) >= 1,
              "FMI %d: no state holding %s = %.17g", version, v->name, from);
    }
    if (bytes != NULL) {
        replace_and_seal(bytes, size, from, to);
        CHECK(deserialize(version, c, bytes, size, &state) == 0 &&
                  set_state(version, c, state) == 0,
              "FMI %d: a state with %s = %g refused: %s", version, v->name, to, book.last);
        CHECK(read_all(version, c, &restored) && same_values(&restored, &expected),
              "FMI %d: a state with %s changed to %g restores the outputs of %.17g", version,
              v->name, to, from);
        CHECK(step_either(version, c, 0.01, 0.01) == step_either(version, ref, 0.01, 0.01) &&
                  read_all(version, c, &restored) == read_all(version, ref, &expected) &&
                  same_values(&restored, &expected),
              "FMI %d: a step from a state with %s changed to %g is not that of %g", version,
              v->name, to, to);
    }
    free(bytes);
    free_either(version, ref);
    free_either(version, c);
    return fails;
}

/* check_input_changed on the first input (an angle first) that changes the outputs. */
static int check_an_input_changed(int version)
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    int fails = 0, found = 0, angles;
    size_t k;
    for (angles = 1; angles >= 0 && !found; --angles) {
        for (k = 0; k < md->variable_count && !found; ++k) {
            const probe_variable* v = &md->variables[k];
            if (v->type == PROBE_REAL && v->causality == PROBE_INPUT &&
                (strstr(v->name, "angle") != NULL) == angles) {
                fails += check_input_changed(version, v, &found);
            }
        }
    }
    CHECK(found, "FMI %d: no input from 0.3 to 1 changes an output", version);
    return fails;
}

/* 1 if `x` is the value of a parameter or input in `r` (read by read_all). */
static int is_a_set_value(const probe_model* md, const values_read* r, double x)
{
    size_t k, at = 0;
    for (k = 0; k < md->variable_count; ++k) {
        const probe_variable* v = &md->variables[k];
        if (v->type != PROBE_REAL) {
            continue;
        }
        if (v->causality != PROBE_OUTPUT && probe_bits(r->reals[at]) == probe_bits(x)) {
            return 1;
        }
        ++at;
    }
    return 0;
}

/* A state whose bytes hold NaN where they hold an output's value (one output at a time,
 * one whose value no parameter or input has): refused, or restored with every output
 * as it was. A state does not keep what the FMU computes; where it did, the NaN was
 * read back with status 0. */
static int check_outputs_not_kept(int version, void* c, probe_log_book* book)
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    values_read before, after;
    unsigned char *bytes, *crafted;
    size_t size = 0, k, at = 0;
    int fails = 0;
    CHECK(read_all(version, c, &before) && (bytes = state_bytes(version, c, &size)) != NULL,
          "FMI %d: a state after a step", version);
    crafted = bytes != NULL ? (unsigned char*)malloc(size) : NULL;
    for (k = 0; k < md->variable_count && crafted != NULL; ++k) {
        const probe_variable* v = &md->variables[k];
        const double x = v->type == PROBE_REAL ? before.reals[at++] : 0;
        void* state = NULL;
        if (v->type != PROBE_REAL || v->causality != PROBE_OUTPUT || x == 0 || !isfinite(x) ||
            is_a_set_value(md, &before, x) || occurrences(bytes, size, x) == 0) {
            continue;
        }
        memcpy(crafted, bytes, size);
        replace_and_seal(crafted, size, x, NAN);
        if (deserialize(version, c, crafted, size, &state) == 3) {
            CHECK(strstr(book->last, "refused: ") != NULL, "FMI %d: %s", version, book->last);
            continue;
        }
        CHECK(set_state(version, c, state) == 0 && read_all(version, c, &after) &&
                  same_values(&before, &after),
              "FMI %d: a state with %s = NaN in its bytes restores other outputs (%s = %g)",
              version, v->name, v->name, after.reals[at - 1]);
    }
    free(crafted);
    free(bytes);
    return fails;
}

/* A state with the int 7 at each 4-byte offset of its payload in turn: where it is
 * accepted, the status output reads what the model says, never 7 (no model has such a
 * status): the status is evaluated again, not restored. */
static int check_status_recomputed(int version, void* c, probe_log_book* book)
{
    const int seven = 7;
    unsigned char *bytes, *crafted;
    size_t size = 0, at;
    int fails = 0, accepted = 0;
    CHECK((bytes = state_bytes(version, c, &size)) != NULL, "FMI %d: a state", version);
    crafted = bytes != NULL ? (unsigned char*)malloc(size) : NULL;
    for (at = 32; crafted != NULL && at + sizeof seven <= size; at += sizeof seven) {
        void* state = NULL;
        memcpy(crafted, bytes, size);
        memcpy(crafted + at, &seven, sizeof seven);
        if (memcmp(crafted, bytes, size) == 0) {
            continue;
        }
        seal(crafted, size);
        if (deserialize(version, c, crafted, size, &state) != 0) {
            continue;
        }
        ++accepted;
        CHECK(set_state(version, c, state) == 0 && get_status_output(version, c) != 7,
              "FMI %d: status reads 7 after a state with 7 at payload byte %zu (%s)", version,
              at - 32, book->last);
    }
    CHECK(bytes == NULL || accepted > 0, "FMI %d: no state with a 7 accepted", version);
    free(crafted);
    free(bytes);
    return fails;
}

static int test_fmu_state_evaluated_again(void)
{
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        probe_log_book book;
        void* c;
        fails += check_an_input_changed(version);
        c = stepped_with(version, &book, NULL, 0);
        CHECK(c != NULL, "FMI %d: a step", version);
        if (c != NULL) {
            fails += check_outputs_not_kept(version, c, &book);
            fails += check_status_recomputed(version, c, &book);
        }
        free_either(version, c);
    }
    return fails;
}

/* Sets on_singular (FMI 2 as Integer, FMI 3 as Int64); 1 if accepted. */
static int set_on_singular(int version, void* c, const probe_variable* v, int value)
{
    const int64_t wide = value;
    return version == 2 ? api2.SetInteger(c, &v->vr, 1, &value) == fmi2OK
                        : api3.SetInt64(c, &v->vr, 1, &wide, 1) == fmi3OK;
}

/* The state of an initialised instance with on_singular = `value`, or NULL. */
static unsigned char* state_with_on_singular(int version, const probe_variable* v, int value,
                                             probe_log_book* book, void** c, size_t* size)
{
    *c = version == 2 ? (void*)new_fmi2(book, "setting") : (void*)new_fmi3(book, "setting");
    if (*c == NULL || !set_on_singular(version, *c, v, value) ||
        !(version == 2 ? initialise_fmi2(*c) : initialise_fmi3(*c))) {
        return NULL;
    }
    return state_bytes(version, *c, size);
}

/* Where the two states (of one size) hold `a` and `b` as an 8-byte double, or as an
 * int, at one offset of their payloads; 0 if nowhere. */
static size_t offset_of(const unsigned char* sa, const unsigned char* sb, size_t size, double a,
                        double b, int as_int)
{
    const int ia = (int)a, ib = (int)b;
    size_t k;
    for (k = 32; sa != NULL && sb != NULL && k + 8 <= size; ++k) {
        if (as_int ? memcmp(sa + k, &ia, sizeof ia) == 0 && memcmp(sb + k, &ib, sizeof ib) == 0
                   : memcmp(sa + k, &a, 8) == 0 && memcmp(sb + k, &b, 8) == 0) {
            return k;
        }
    }
    return 0;
}

/* A state whose on_singular (found as the one 8-byte value that is 1.0 in a state with
 * on_singular = 1 and 2.0 in one with 2) is NaN, infinite, a fraction or no item:
 * refused, naming it, as a set of a value that is not one of its items is. Where it was
 * not, reading it back converted NaN to an int. */
static int test_fmu_state_setting_refused(void)
{
    static const double bad[] = {NAN, INFINITY, 1.5, 1 + DBL_EPSILON, 0, 3, -1, 1e300};
    int fails = 0, version;
    for (version = 2; version <= 3; ++version) {
        const probe_variable* v = probe_variable_named(version == 2 ? &md2 : &md3, "on_singular");
        probe_log_book book_1, book_2;
        void *c1 = NULL, *c2 = NULL, *state = NULL;
        unsigned char *a = NULL, *b = NULL;
        size_t size_1 = 0, size_2 = 0, at, k;
        int64_t read = 0;
        if (v != NULL) {
            a = state_with_on_singular(version, v, 1, &book_1, &c1, &size_1);
            b = state_with_on_singular(version, v, 2, &book_2, &c2, &size_2);
        }
        at = size_1 == size_2 ? offset_of(a, b, size_1, 1, 2, 0) : 0;
        CHECK(v == NULL || at > 0, "FMI %d: on_singular not found in the state", version);
        for (k = 0; at > 0 && k < sizeof bad / sizeof bad[0]; ++k) {
            char expected[100];
            snprintf(expected, sizeof expected,
                     "refused: on_singular = %.17g is not an item of its enumeration", bad[k]);
            memcpy(b + at, &bad[k], 8);
            seal(b, size_2);
            state = NULL;
            CHECK(deserialize(version, c2, b, size_2, &state) == 3 && state == NULL &&
                      strstr(book_2.last, expected) != NULL,
                  "FMI %d: a state with on_singular = %g: %s", version, bad[k], book_2.last);
            if (state != NULL && set_state(version, c2, state) == 0) {
                (void)(version == 2 ? (int)api2.GetInteger(c2, &v->vr, 1, &(int){0})
                                    : (int)api3.GetInt64(c2, &v->vr, 1, &read, 1));
            }
        }
        free(a);
        free(b);
        free_either(version, c1);
        free_either(version, c2);
    }
    return fails;
}

/* A state whose state machine's state (found as the int that is 4, Step, in a state
 * taken in step mode and 8, Terminated, in one taken after terminate) is none of the
 * four: refused, naming it. */
static int check_machine_refused(int version)
{
    static const int bad[] = {0, 3, 5, 6, 16, -1, 4 | 8};
    probe_log_book book;
    void* c = version == 2 ? (void*)new_fmi2(&book, "machine") : (void*)new_fmi3(&book, "machine");
    unsigned char *step = NULL, *terminated = NULL;
    size_t size = 0, other = 0, at, k;
    int fails = 0;
    if (c != NULL && (version == 2 ? initialise_fmi2(c) : initialise_fmi3(c))) {
        step = state_bytes(version, c, &size);
        if ((version == 2 ? (int)api2.Terminate(c) : (int)api3.Terminate(c)) == 0) {
            terminated = state_bytes(version, c, &other);
        }
    }
    at = size == other ? offset_of(step, terminated, size, 4, 8, 1) : 0;
    CHECK(at > 0, "FMI %d: the state machine's state not found in the state", version);
    for (k = 0; at > 0 && k < sizeof bad / sizeof bad[0]; ++k) {
        void* state = NULL;
        memcpy(step + at, &bad[k], sizeof bad[k]);
        seal(step, size);
        CHECK(deserialize(version, c, step, size, &state) == 3 &&
                  strstr(book.last, "refused: the state machine's state") != NULL,
              "FMI %d: a state with the state machine in %d: %s", version, bad[k], book.last);
    }
    free(step);
    free(terminated);
    free_either(version, c);
    return fails;
}

/* A step from `t` that the model cannot complete, with a Real input at an extreme value
 * (a step that completes on the way moves `t` on); 1 if found. */
static int discard_from(int version, void* c, double* t)
{
    const probe_model* md = version == 2 ? &md2 : &md3;
    size_t e, k;
    for (k = 0; k < md->variable_count; ++k) {
        const probe_variable* v = &md->variables[k];
        for (e = 0; is_real_setting(v) && v->causality == PROBE_INPUT && e < 4; ++e) {
            const int status =
                set_named(version, c, v->name, extremes[e]) ? step_either(version, c, *t, 0.01) : 3;
            if (status == 2) {
                return 1;
            }
            *t += status == 0 ? 0.01 : 0;
        }
    }
    return 0;
}

/* One place of the state that holds the time `t` given `value`: a time that is not
 * finite, or a last successful time after the time, is refused, naming it; after a
 * discarded step (the terminate flag set) a later time is one a step can leave (the
 * drive's, when its states moved), and the time then reads `value`. Returns 1 if the
 * state was accepted. */
static int check_time_place(int version, void* c, probe_log_book* book, unsigned char* crafted,
                            size_t size, double t, double value, int* fails_out)
{
    void* state = NULL;
    int fails = 0, accepted;
    seal(crafted, size);
    accepted = deserialize(version, c, crafted, size, &state) == 0;
    if (accepted) {
        CHECK(isfinite(value) && value > t && set_state(version, c, state) == 0 &&
                  probe_bits(time_reached(version, c)) == probe_bits(version == 2 ? t : value),
              "FMI %d: a state with %.17g for the time %.17g accepted (time reached %.17g)",
              version, value, t, time_reached(version, c));
    } else {
        CHECK(strstr(book->last, "refused: ") != NULL && strstr(book->last, "time = ") != NULL,
              "FMI %d: a state with %.17g for the time %.17g: %s", version, value, t, book->last);
    }
    *fails_out += fails;
    return accepted;
}

/* A state after steps from 12.5 s, and one after a discarded step, whose time or last
 * successful time (each place that holds the time, in turn) is NaN, infinite, or one
 * second later: refused, naming it, but for a later time after a discarded step (one
 * place accepted). Where such states were not refused, the time read NaN, or the last
 * successful time was after it. */
static int check_times_refused(int version, int discarded)
{
    static const double bad[] = {NAN, INFINITY, -INFINITY, 1};
    probe_log_book book;
    void* c = version == 2 ? (void*)new_fmi2(&book, "times") : (void*)new_fmi3(&book, "times");
    unsigned char *bytes = NULL, *crafted = NULL;
    size_t size = 0, at, k, places = 0, accepted = 0;
    double t = 12.5;
    int fails = 0, step;
    CHECK(c != NULL && initialise_from(version, c, t, 100), "FMI %d: initialise", version);
    for (step = 0; c != NULL && step < 3; ++step, t += 0.01) {
        CHECK(step_either(version, c, t, 0.01) != 3, "FMI %d: step", version);
    }
    if (c != NULL && discarded && !discard_from(version, c, &t)) {
        printf("    FMI %d: no input makes a step discard\n", version);
        free_either(version, c);
        return fails;
    }
    bytes = c != NULL ? state_bytes(version, c, &size) : NULL;
    crafted = bytes != NULL ? (unsigned char*)malloc(size) : NULL;
    for (at = 32; crafted != NULL && at + 8 <= size; ++at) {
        if (memcmp(bytes + at, &t, 8) != 0) {
            continue;
        }
        ++places;
        for (k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
            const double value = k == 3 ? t + bad[k] : bad[k];
            memcpy(crafted, bytes, size);
            memcpy(crafted + at, &value, 8);
            accepted += check_time_place(version, c, &book, crafted, size, t, value, &fails);
        }
    }
    CHECK(places >= 1 && accepted == (discarded ? 1u : 0u),
          "FMI %d: the state holds its time %.17g in %zu places, %zu of them accepted later",
          version, t, places, accepted);
    free(crafted);
    free(bytes);
    free_either(version, c);
    return fails;
}

static int test_fmu_state_machine_and_times_refused(void)
{
    int fails = check_machine_refused(2) + check_machine_refused(3), discarded;
    for (discarded = 0; discarded <= 1; ++discarded) {
        fails += check_times_refused(2, discarded) + check_times_refused(3, discarded);
    }
    return fails;
}

/* ---- runner --------------------------------------------------------------------------------- */

static const named_test generic_tests[] = {
    {"fmi2_state_machine", test_fmi2_state_machine},
    {"fmi2_null_instance", test_fmi2_null_instance},
    {"fmi2_null_arguments", test_fmi2_null_arguments},
    {"fmi2_wrong_types_and_unknown_vrs", test_fmi2_wrong_types_and_unknown_vrs},
    {"fmi2_invalid_values", test_fmi2_invalid_values},
    {"fmi2_repeated_calls_keep_their_checks", test_fmi2_repeated_calls_keep_their_checks},
    {"fmi2_common_paths_follow_the_instance", test_fmi2_common_paths_follow_the_instance},
    {"fmi2_reset", test_fmi2_reset},
    {"fmi2_instantiate_refusals", test_fmi2_instantiate_refusals},
    {"fmi3_state_machine", test_fmi3_state_machine},
    {"fmi3_null_instance", test_fmi3_null_instance},
    {"fmi3_null_arguments", test_fmi3_null_arguments},
    {"fmi3_wrong_types_and_unknown_vrs", test_fmi3_wrong_types_and_unknown_vrs},
    {"fmi3_size_mismatch", test_fmi3_size_mismatch},
    {"fmi3_invalid_values", test_fmi3_invalid_values},
    {"fmi3_reset", test_fmi3_reset},
    {"fmi3_instantiate_refusals", test_fmi3_instantiate_refusals},
    {"fmi2_on_singular", test_fmi2_on_singular},
    {"fmi3_on_singular", test_fmi3_on_singular},
    {"instances_independent", test_instances_independent},
    {"fmu_state_round_trip", test_fmu_state_round_trip},
    {"fmu_state_evaluated_again", test_fmu_state_evaluated_again},
    {"fmu_state_setting_refused", test_fmu_state_setting_refused},
    {"fmu_state_machine_and_times_refused", test_fmu_state_machine_and_times_refused},
    {"exports_only_fmi", test_exports_only_fmi},
    {"bad_steps", test_bad_steps},
    {"experiment_stop", test_experiment_stop},
    {"huge_seed_discards", test_huge_seed_discards},
};

/* Tests of one model, run when the FMUs are that model. */
static const named_test rrt_tests[] = {
    {"rrt_fmi2_core", test_rrt_fmi2_core},
    {"rrt_rows_match_the_core", test_rrt_rows_match_the_core},
    {"rrt_columns_match_the_rows", test_rrt_columns_match_the_rows},
    {"rrt_bad_input_names_its_variable", test_rrt_bad_input_names_its_variable},
    {"rrt_fmi2_singular", test_rrt_fmi2_singular},
    {"rrt_fmi3_core", test_rrt_fmi3_core},
    {"rrt_fmi3_singular", test_rrt_fmi3_singular},
};

int main(int argc, char** argv)
{
    char error[512];
    int failed, more = 0;
    const int first_name = 3;
    if (argc == 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("usage: fmu_api_tests FMI2_FMU_DIR FMI3_FMU_DIR [test-name ...]\n"
               "The FMI misuse matrix: every FMI 2 and FMI 3 entry point of one model's two "
               "unpacked FMUs in every state, with bad arguments and crafted states; exits "
               "non-zero if a check fails.\n");
        return 0;
    }
    if (argc < 3) {
        printf("usage: fmu_api_tests FMI2_FMU_DIR FMI3_FMU_DIR [test-name ...]\n");
        return 2;
    }
    if (!probe_read_model(argv[1], &md2, error, sizeof error) ||
        !probe_read_model(argv[2], &md3, error, sizeof error) ||
        !probe_load_fmi2(&md2, &api2, error, sizeof error) ||
        !probe_load_fmi3(&md3, &api3, error, sizeof error)) {
        printf("%s\n0 passed, 1 failed\n", error);
        return 1;
    }
    if (md2.fmi_version != 2 || md3.fmi_version != 3 ||
        strcmp(md2.identifier, md3.identifier) != 0) {
        printf("expected the FMI 2 and FMI 3 FMU of one model\n0 passed, 1 failed\n");
        return 1;
    }
    failed = run_named_tests(generic_tests, sizeof generic_tests / sizeof generic_tests[0],
                             md2.identifier, argv + first_name, argc - first_name);
    if (strcmp(md2.identifier, "drive") == 0) {
        more = run_named_tests(drive_tests, sizeof drive_tests / sizeof drive_tests[0],
                               md2.identifier, argv + first_name, argc - first_name);
        failed = failed < 0 ? more : more < 0 ? failed : failed + more;
    }
    if (strcmp(md2.identifier, fmu_this_model.identifier) == 0) {
        more = run_named_tests(rrt_tests, sizeof rrt_tests / sizeof rrt_tests[0], md2.identifier,
                               argv + first_name, argc - first_name);
        failed = failed < 0 ? more : more < 0 ? failed : failed + more;
    }
    printf("misuse %s: %ld checks\n", md2.identifier, checks_run);
    probe_unload(api2.library);
    probe_unload(api3.library);
    probe_free_model(&md2);
    probe_free_model(&md3);
    return failed == 0 ? 0 : 1;
}
