/* dyadfmu: a fuzz of serialized FMU states, on the FMI 2 and FMI 3 FMU of one model.
 *
 * States are taken with inputs away from their start values and the settings changed,
 * one in Initialization and one after steps; then every 8-byte field of a payload is
 * given other values in turn (NaN, the infinities, 7, -1, 1e300, 0, its neighbours,
 * small integers and more), two of its first 16 fields the same value at once (NaN,
 * inf, 7, -1, 1e300, 0), 500 fields seeded random values, and every byte has a few bits
 * flipped, each time with the checksum made good again: bytes an importer could hand
 * over. Each state the FMU accepts is
 * restored into one instance (each restore over the one before) and must agree bit
 * for bit with a fresh instance given what can be read back from the restored one: its
 * parameters, inputs and settings and, for a model with states, those (through their start
 * parameters), in the same state of the state machine at the same time: every Real and
 * Integer output and the status of each getter, then a doStep from it and the outputs
 * after it. A state the FMU refuses must say why in an Error. The counts of accepted
 * and refused states are printed per FMU.
 *
 * Usage: fmu_state_fuzz FMI2_FMU_DIR FMI3_FMU_DIR
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_probe.h"

enum { HEADER = 32, MAX_VALUES = 512, MISMATCHES_SHOWN = 8 };

/* The states of the co-simulation state machine, as the test tells them apart. */
typedef enum machine { M_INSTANTIATED = 0, M_INITIALIZATION, M_STEP, M_TERMINATED } machine;
static const char* const machine_names[] = {"Instantiated", "Initialization", "Step", "Terminated"};

/* The most states a model has (a plant: each driver's position and rate, each motor's
 * current, the integrator's next step). */
enum { MODEL_STATE_COUNT = 32 };

typedef struct fmu {
    int version;
    probe_model md;
    probe_fmi2 f2;
    probe_fmi3 f3;
    /* the variables by role, as indices into md.variables */
    size_t parameters[MAX_VALUES], inputs[MAX_VALUES], settings[MAX_VALUES];
    size_t real_outputs[MAX_VALUES], integer_outputs[MAX_VALUES];
    size_t n_parameters, n_inputs, n_settings, n_real_outputs, n_integer_outputs;
    /* for each model state: its output and the start parameter a fresh instance takes it
     * from (probe_state_start) */
    long state_output[MODEL_STATE_COUNT], state_start[MODEL_STATE_COUNT];
    size_t n_states;
    int has_states;
} fmu;

typedef struct instance {
    const fmu* f;
    void* c;
    probe_log_book book;
} instance;

/* What can be read of an instance: every Real and Integer output with the getters'
 * statuses, and its parameters, inputs and settings. */
typedef struct reading {
    int real_status, integer_status;
    double reals[MAX_VALUES];
    int64_t integers[MAX_VALUES];
} reading;

typedef struct tally {
    long tried, accepted, refused, failures, steps_compared;
    long in_machine[4];
} tally;

/* ---- the calls, either version -------------------------------------------------------------- */

static int new_instance(const fmu* f, instance* in, const char* name)
{
    in->f = f;
    probe_log_book_clear(&in->book);
    if (f->version == 2) {
        fmi2CallbackFunctions callbacks = probe_fmi2_callbacks(&in->book);
        in->c = f->f2.Instantiate(name, fmi2CoSimulation, f->md.token, "", &callbacks, fmi2False,
                                  fmi2False);
    } else {
        in->c =
            f->f3.InstantiateCoSimulation(name, f->md.token, NULL, fmi3False, fmi3False, fmi3False,
                                          fmi3False, NULL, 0, &in->book, probe_fmi3_logger, NULL);
    }
    return in->c != NULL;
}

static void free_instance(instance* in)
{
    if (in->c != NULL) {
        if (in->f->version == 2) {
            in->f->f2.FreeInstance(in->c);
        } else {
            in->f->f3.FreeInstance(in->c);
        }
    }
    in->c = NULL;
}

static const probe_variable* var(const fmu* f, size_t index)
{
    return &f->md.variables[index];
}

static int get_real(instance* in, size_t index, double* value)
{
    const unsigned vr = var(in->f, index)->vr;
    return in->f->version == 2 ? (int)in->f->f2.GetReal(in->c, &vr, 1, value)
                               : (int)in->f->f3.GetFloat64(in->c, &vr, 1, value, 1);
}

static int set_real(instance* in, size_t index, double value)
{
    const unsigned vr = var(in->f, index)->vr;
    return in->f->version == 2 ? (int)in->f->f2.SetReal(in->c, &vr, 1, &value)
                               : (int)in->f->f3.SetFloat64(in->c, &vr, 1, &value, 1);
}

/* An Integer or Enumeration: fmi2Integer, FMI 3's Int32 or Int64. */
static int get_integer(instance* in, size_t index, int64_t* value)
{
    const probe_variable* v = var(in->f, index);
    int status, i32 = 0;
    if (in->f->version == 3 && v->type == PROBE_ENUMERATION) {
        return (int)in->f->f3.GetInt64(in->c, &v->vr, 1, value, 1);
    }
    status = in->f->version == 2 ? (int)in->f->f2.GetInteger(in->c, &v->vr, 1, &i32)
                                 : (int)in->f->f3.GetInt32(in->c, &v->vr, 1, &i32, 1);
    *value = i32;
    return status;
}

static int set_integer(instance* in, size_t index, int64_t value)
{
    const probe_variable* v = var(in->f, index);
    const int i32 = (int)value;
    if (in->f->version == 3 && v->type == PROBE_ENUMERATION) {
        return (int)in->f->f3.SetInt64(in->c, &v->vr, 1, &value, 1);
    }
    return in->f->version == 2 ? (int)in->f->f2.SetInteger(in->c, &v->vr, 1, &i32)
                               : (int)in->f->f3.SetInt32(in->c, &v->vr, 1, &i32, 1);
}

/* Enters initialization at `start` s. FMI 2 without `start` (has_start 0): no
 * setupExperiment, the time as it is. */
static int enter_initialization(instance* in, int has_start, double start)
{
    if (in->f->version == 3) {
        return (int)in->f->f3.EnterInitializationMode(in->c, fmi3False, 0, start, fmi3False, 0);
    }
    if (has_start && in->f->f2.SetupExperiment(in->c, fmi2False, 0, start, fmi2False, 0) != 0) {
        return 3;
    }
    return (int)in->f->f2.EnterInitializationMode(in->c);
}

static int exit_initialization(instance* in)
{
    return in->f->version == 2 ? (int)in->f->f2.ExitInitializationMode(in->c)
                               : (int)in->f->f3.ExitInitializationMode(in->c);
}

static int terminate(instance* in)
{
    return in->f->version == 2 ? (int)in->f->f2.Terminate(in->c) : (int)in->f->f3.Terminate(in->c);
}

/* A doStep, with the last successful time and the terminate flag it reports. */
static int do_step(instance* in, double t, double h, double* last, int* flag)
{
    int status;
    *last = NAN;
    *flag = -1;
    if (in->f->version == 2) {
        fmi2Boolean terminated = fmi2False;
        status = (int)in->f->f2.DoStep(in->c, t, h, fmi2True);
        if ((status == 0 || status == 2) &&
            (in->f->f2.GetRealStatus(in->c, fmi2LastSuccessfulTime, last) != 0 ||
             in->f->f2.GetBooleanStatus(in->c, fmi2Terminated, &terminated) != 0)) {
            return 3;
        }
        *flag = terminated != fmi2False;
    } else {
        fmi3Boolean event = fmi3False, terminated = fmi3False, early = fmi3False;
        status = (int)in->f->f3.DoStep(in->c, t, h, fmi3True, &event, &terminated, &early, last);
        *flag = terminated != fmi3False;
    }
    return status;
}

/* The time an instance after initialization is at (FMI 3: the variable time; FMI 2:
 * its last successful time, which is the time unless its last step was discarded).
 * Returns 1 if *t is the time. */
static int time_of(instance* in, double* t)
{
    fmi2Boolean terminated = fmi2True;
    *t = 0;
    if (in->f->version == 3) {
        const unsigned vr = 0;
        return in->f->f3.GetFloat64(in->c, &vr, 1, t, 1) == fmi3OK;
    }
    if (in->f->f2.GetRealStatus(in->c, fmi2LastSuccessfulTime, t) != fmi2OK) {
        *t = 0; /* exitInitializationMode failed: still in Initialization */
        return 0;
    }
    return in->f->f2.GetBooleanStatus(in->c, fmi2Terminated, &terminated) == fmi2OK &&
           terminated == fmi2False;
}

static int get_state(instance* in, void** state)
{
    return in->f->version == 2 ? (int)in->f->f2.GetFMUstate(in->c, state)
                               : (int)in->f->f3.GetFMUState(in->c, state);
}

static int set_state(instance* in, void* state)
{
    return in->f->version == 2 ? (int)in->f->f2.SetFMUstate(in->c, state)
                               : (int)in->f->f3.SetFMUState(in->c, state);
}

static void free_state(instance* in, void** state)
{
    if (in->f->version == 2) {
        in->f->f2.FreeFMUstate(in->c, state);
    } else {
        in->f->f3.FreeFMUState(in->c, state);
    }
}

static unsigned char* serialize(instance* in, void* state, size_t* size)
{
    unsigned char* bytes;
    int status = in->f->version == 2 ? (int)in->f->f2.SerializedFMUstateSize(in->c, state, size)
                                     : (int)in->f->f3.SerializedFMUStateSize(in->c, state, size);
    bytes = status == 0 ? (unsigned char*)malloc(*size) : NULL;
    if (bytes == NULL) {
        return NULL;
    }
    status = in->f->version == 2
                 ? (int)in->f->f2.SerializeFMUstate(in->c, state, (fmi2Byte*)bytes, *size)
                 : (int)in->f->f3.SerializeFMUState(in->c, state, bytes, *size);
    if (status != 0) {
        free(bytes);
        return NULL;
    }
    return bytes;
}

static int deserialize(instance* in, const unsigned char* bytes, size_t size, void** state)
{
    return in->f->version == 2
               ? (int)in->f->f2.DeSerializeFMUstate(in->c, (const fmi2Byte*)bytes, size, state)
               : (int)in->f->f3.DeserializeFMUState(in->c, bytes, size, state);
}

/* ---- the model ------------------------------------------------------------------------------ */

static int is_setting(const probe_variable* v)
{
    return (v->type == PROBE_INTEGER || v->type == PROBE_ENUMERATION) &&
           (v->causality == PROBE_PARAMETER || v->causality == PROBE_INPUT) &&
           probe_settable_before_initialization(v);
}

/* The variables by role, and the model's states where it has them. */
/* A plant's counts of the integrator's work since the start: a fresh instance has
 * done none, so they are not compared. */
static int is_count(const probe_variable* v)
{
    return strcmp(v->name, "solver.steps") == 0 || strcmp(v->name, "solver.evaluations") == 0;
}

static void sort_variables(fmu* f)
{
    size_t k, s;
    for (k = 0; k < f->md.variable_count && k < MAX_VALUES; ++k) {
        const probe_variable* v = &f->md.variables[k];
        if (v->type == PROBE_REAL && v->causality == PROBE_PARAMETER &&
            probe_settable_before_initialization(v)) {
            f->parameters[f->n_parameters++] = k;
        } else if (v->type == PROBE_REAL && v->causality == PROBE_INPUT) {
            f->inputs[f->n_inputs++] = k;
        } else if (is_setting(v)) {
            f->settings[f->n_settings++] = k;
        } else if (v->type == PROBE_REAL && v->causality == PROBE_OUTPUT && !is_count(v)) {
            f->real_outputs[f->n_real_outputs++] = k;
        } else if (v->type == PROBE_INTEGER && v->causality == PROBE_OUTPUT) {
            f->integer_outputs[f->n_integer_outputs++] = k;
        }
    }
    for (s = 0; s < f->md.variable_count && f->n_states < MODEL_STATE_COUNT; ++s) {
        const probe_variable* start = probe_state_start(&f->md, &f->md.variables[s]);
        if (start != NULL) {
            f->state_output[f->n_states] = (long)s;
            f->state_start[f->n_states++] = (long)(start - f->md.variables);
        }
    }
    f->has_states = f->n_states > 0;
}

/* Every Real and Integer output, and the getters' statuses. */
static void read_outputs(instance* in, reading* r)
{
    const fmu* f = in->f;
    size_t k;
    r->real_status = 0;
    r->integer_status = 0;
    for (k = 0; k < f->n_real_outputs; ++k) {
        const int status = get_real(in, f->real_outputs[k], &r->reals[k]);
        r->real_status = status > r->real_status ? status : r->real_status;
    }
    for (k = 0; k < f->n_integer_outputs; ++k) {
        const int status = get_integer(in, f->integer_outputs[k], &r->integers[k]);
        r->integer_status = status > r->integer_status ? status : r->integer_status;
    }
}

/* The index of the first output that differs bit for bit, -1 if none, -2 for a
 * getter's status. */
static long differs(const fmu* f, const reading* a, const reading* b)
{
    size_t k;
    if (a->real_status != b->real_status || a->integer_status != b->integer_status) {
        return -2;
    }
    for (k = 0; k < f->n_real_outputs; ++k) {
        if (probe_bits(a->reals[k]) != probe_bits(b->reals[k])) {
            return (long)f->real_outputs[k];
        }
    }
    for (k = 0; k < f->n_integer_outputs; ++k) {
        if (a->integers[k] != b->integers[k]) {
            return (long)f->integer_outputs[k];
        }
    }
    return -1;
}

/* ---- the states ----------------------------------------------------------------------------- */

/* The checksum made good again: FNV-1a over the payload, as fmu_state.c computes it. */
static void seal(unsigned char* bytes, size_t size)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    size_t k;
    for (k = HEADER; k < size; ++k) {
        h = (h ^ bytes[k]) * 0x100000001b3ULL;
    }
    memcpy(bytes + 24, &h, sizeof h);
}

/* A value for a Real input other than its start, within its bounds. */
static double input_value(const probe_variable* v, int step)
{
    const double start = v->has_start ? v->start : 0;
    const double value = start + 0.37 + 0.01 * step;
    if ((v->has_min && value < v->min) || (v->has_max && value > v->max)) {
        return start;
    }
    return value;
}

/* A state the fuzz starts from: on_singular = continue (2) where the model has it, the
 * inputs off their start values, in Initialization at 0.25 s (`steps` 0) or after
 * `steps` steps of 0.01 s from there. */
static int set_rates(instance* in, const double rates[]);

/* The state after `steps` steps (a plant of FMI 2 with its inputs ramping at 1 unit/s). */
static unsigned char* base_state(const fmu* f, int steps, size_t* size)
{
    double ones[MAX_VALUES];
    instance in;
    unsigned char* bytes = NULL;
    void* state = NULL;
    int ok, step;
    size_t k;
    double last;
    int flag;
    for (k = 0; k < MAX_VALUES; ++k) {
        ones[k] = 1;
    }
    if (!new_instance(f, &in, "base")) {
        return NULL;
    }
    ok = 1;
    for (k = 0; k < f->n_settings; ++k) {
        if (strcmp(var(f, f->settings[k])->name, "on_singular") == 0) {
            ok &= set_integer(&in, f->settings[k], 2) == 0;
        }
    }
    ok &= enter_initialization(&in, 1, 0.25) == 0;
    ok &= !(f->version == 2 && f->md.interpolates) || set_rates(&in, ones);
    for (k = 0; k < f->n_inputs && steps == 0; ++k) {
        ok &= set_real(&in, f->inputs[k], input_value(var(f, f->inputs[k]), 0)) == 0;
    }
    ok &= steps == 0 || exit_initialization(&in) <= 1;
    for (step = 0; ok && step < steps; ++step) {
        for (k = 0; k < f->n_inputs; ++k) {
            ok &= set_real(&in, f->inputs[k], input_value(var(f, f->inputs[k]), step)) == 0;
        }
        ok &= do_step(&in, 0.25 + 0.01 * step, 0.01, &last, &flag) == 0;
    }
    if (ok && get_state(&in, &state) == 0) {
        bytes = serialize(&in, state, size);
    }
    if (!ok) {
        printf("    the base state cannot be reached: %s\n", in.book.last);
    }
    free_instance(&in);
    return bytes;
}

/* ---- one restored state against a fresh instance ------------------------------------------- */

typedef struct restored {
    machine m;
    int was_instantiated;      /* restored in Instantiated, then entered initialization */
    reading before;            /* the outputs as restored (the first state they can be read in) */
    int exit_status;           /* from Initialization: exitInitializationMode's status */
    reading after_exit;        /* and the outputs after it */
    double values[MAX_VALUES]; /* parameters, inputs, then settings as read back */
    int64_t settings[MAX_VALUES];
    double states[MODEL_STATE_COUNT];
    /* the inputs' first derivatives (FMI 2, a model that interpolates its inputs): the
     * state's last fields, one per Real input in the variable table's order */
    double rates[MAX_VALUES];
    int time_known;
    double time;
} restored;

/* Which state of the machine the restored instance is in, by calls that are legal in
 * some states only and change nothing: a get (not before initialization), a set of a
 * parameter to its own value (only before initialization ends), of an input (not once
 * terminated). */
static machine machine_of(instance* in, const reading* r, const restored* back)
{
    const fmu* f = in->f;
    size_t k;
    int parameter_set = -1;
    if (r->real_status == 3 && strstr(in->book.last, "illegal call sequence") != NULL) {
        return M_INSTANTIATED;
    }
    if (f->n_parameters > 0) {
        parameter_set = set_real(in, f->parameters[0], back->values[0]);
    }
    for (k = 0; k < f->n_settings && parameter_set < 0; ++k) {
        if (var(f, f->settings[k])->causality == PROBE_PARAMETER) {
            parameter_set = set_integer(in, f->settings[k], back->settings[k]);
        }
    }
    if (parameter_set == 0) {
        return M_INITIALIZATION;
    }
    if (f->n_inputs > 0 && set_real(in, f->inputs[0], back->values[f->n_parameters]) == 0) {
        return M_STEP;
    }
    return M_TERMINATED;
}

/* Reads back what a fresh instance is given: parameters, inputs, settings, the model's
 * states; 0 if a get fails. */
static int read_back(instance* in, restored* r)
{
    const fmu* f = in->f;
    size_t k;
    int ok = 1;
    for (k = 0; k < f->n_parameters; ++k) {
        ok &= get_real(in, f->parameters[k], &r->values[k]) == 0;
    }
    for (k = 0; k < f->n_inputs; ++k) {
        ok &= get_real(in, f->inputs[k], &r->values[f->n_parameters + k]) == 0;
    }
    for (k = 0; k < f->n_settings; ++k) {
        ok &= get_integer(in, f->settings[k], &r->settings[k]) == 0;
    }
    for (k = 0; k < f->n_states; ++k) {
        /* read whatever the status: a rejected input leaves the states defined */
        get_real(in, (size_t)f->state_output[k], &r->states[k]);
    }
    return ok;
}

/* The restored instance, read: its outputs where it is, its values, its time; an
 * instance restored before initialization enters it (FMI 3 at 0 s) to be read. */
static int read_restored(instance* in, restored* r)
{
    read_outputs(in, &r->before);
    if (r->before.real_status == 3 && strstr(in->book.last, "illegal call sequence") != NULL) {
        r->was_instantiated = 1;
        if (enter_initialization(in, 0, 0) != 0) {
            return 0;
        }
        read_outputs(in, &r->before);
    }
    if (!read_back(in, r)) {
        return 0;
    }
    r->m = machine_of(in, &r->before, r);
    if (r->m == M_INSTANTIATED) {
        return 0; /* it entered initialization above */
    }
    if (r->m == M_INITIALIZATION) {
        r->exit_status = exit_initialization(in);
        read_outputs(in, &r->after_exit);
    }
    r->time_known = time_of(in, &r->time);
    return 1;
}

/* The first derivatives of every Real input (FMI 2); 1 if the set succeeds. */
static int set_rates(instance* in, const double rates[])
{
    const fmu* f = in->f;
    unsigned int vr[MAX_VALUES];
    fmi2Integer order[MAX_VALUES];
    size_t k;
    for (k = 0; k < f->n_inputs; ++k) {
        vr[k] = var(f, f->inputs[k])->vr;
        order[k] = 1;
    }
    return f->f2.SetRealInputDerivatives(in->c, vr, f->n_inputs, order, rates) == fmi2OK;
}

/* A fresh instance given the restored one's values, in its state of the machine. */
static int fresh_like(const fmu* f, instance* ref, const restored* r, reading* before,
                      reading* after_exit, char* why, size_t why_size)
{
    size_t k, s;
    if (!new_instance(f, ref, "reference")) {
        snprintf(why, why_size, "cannot instantiate");
        return 0;
    }
    for (k = 0; k < f->n_parameters + f->n_inputs; ++k) {
        const size_t index =
            k < f->n_parameters ? f->parameters[k] : f->inputs[k - f->n_parameters];
        double value = r->values[k];
        /* after initialization the states are their own; before, they follow their
         * start values, which the fresh instance is given as they are */
        for (s = 0; r->m != M_INITIALIZATION && s < f->n_states; ++s) {
            value = (long)index == f->state_start[s] ? r->states[s] : value;
        }
        if (set_real(ref, index, value) != 0) {
            snprintf(why, why_size, "it holds %s = %.17g, which a set refuses: %s",
                     var(f, index)->name, value, ref->book.last);
            return 0;
        }
    }
    for (k = 0; k < f->n_settings; ++k) {
        if (set_integer(ref, f->settings[k], r->settings[k]) != 0) {
            snprintf(why, why_size, "it holds %s = %lld, which a set refuses: %s",
                     var(f, f->settings[k])->name, (long long)r->settings[k], ref->book.last);
            return 0;
        }
    }
    if (f->version == 2 && f->md.interpolates && !set_rates(ref, r->rates)) {
        snprintf(why, why_size, "it holds input derivatives which a set refuses: %s",
                 ref->book.last);
        return 0;
    }
    if (enter_initialization(ref, 1, r->time) != 0) {
        snprintf(why, why_size, "enterInitializationMode: %s", ref->book.last);
        return 0;
    }
    if (r->m == M_INITIALIZATION) {
        read_outputs(ref, before);
    }
    if (exit_initialization(ref) != r->exit_status && r->m == M_INITIALIZATION) {
        snprintf(why, why_size, "exitInitializationMode returned %d, a fresh instance's not",
                 r->exit_status);
        return 0;
    }
    if (r->m == M_TERMINATED) {
        terminate(ref);
    }
    read_outputs(ref, r->m == M_INITIALIZATION ? after_exit : before);
    return 1;
}

/* Both steps from the restored instance's time: the same status, reported times and
 *  outputs. Returns 1 if they agree. A plant's step is 0.1 ms: its integrator takes a few
 * internal steps in it, hundreds in the 10 ms of the others'. */
static int same_step(instance* in, instance* ref, const restored* r, char* why, size_t why_size)
{
    const double h = probe_variable_named(&in->f->md, "solver.rtol") != NULL ? 1e-4 : 0.01;
    double last_in, last_ref;
    int flag_in, flag_ref, status_in, status_ref;
    reading a, b;
    long bad;
    status_in = do_step(in, r->time, h, &last_in, &flag_in);
    status_ref = do_step(ref, r->time, h, &last_ref, &flag_ref);
    if (status_in != status_ref) {
        snprintf(why, why_size, "doStep(%.17g, %g) returned %d, a fresh instance %d (%s)", r->time,
                 h, status_in, status_ref, in->book.last);
        return 0;
    }
    if ((status_in == 0 || status_in == 2) &&
        (probe_bits(last_in) != probe_bits(last_ref) || flag_in != flag_ref)) {
        snprintf(why, why_size,
                 "after doStep: last successful time %.17g, terminate %d; a fresh "
                 "instance %.17g, %d",
                 last_in, flag_in, last_ref, flag_ref);
        return 0;
    }
    read_outputs(in, &a);
    read_outputs(ref, &b);
    bad = differs(in->f, &a, &b);
    if (bad != -1) {
        snprintf(why, why_size, "after doStep, %s differs",
                 bad >= 0 ? var(in->f, (size_t)bad)->name : "a getter's status");
        return 0;
    }
    return 1;
}

/* Why the restored instance (of the state `bytes`) disagrees with a fresh one, into `why`;
 * 1 if it agrees. */
static int agrees(instance* in, const unsigned char* bytes, size_t size, tally* t, char* why,
                  size_t why_size)
{
    restored r;
    reading before, after_exit;
    instance ref;
    long bad;
    int ok;
    size_t k;
    memset(&r, 0, sizeof r);
    for (k = 0; in->f->md.interpolates && k < in->f->n_inputs; ++k) {
        memcpy(&r.rates[k], bytes + size - 8 * (in->f->n_inputs - k), sizeof r.rates[k]);
    }
    if (!read_restored(in, &r)) {
        snprintf(why, why_size, "cannot be read back: %s", in->book.last);
        return 0;
    }
    ++t->in_machine[r.was_instantiated ? M_INSTANTIATED : r.m];
    ref.c = NULL;
    ok = fresh_like(in->f, &ref, &r, &before, &after_exit, why, why_size);
    if (ok && (bad = differs(in->f, &r.before, &before)) != -1) {
        snprintf(why, why_size, "in %s, %s differs from a fresh instance's", machine_names[r.m],
                 bad >= 0 ? var(in->f, (size_t)bad)->name : "a getter's status");
        ok = 0;
    }
    if (ok && r.m == M_INITIALIZATION && (bad = differs(in->f, &r.after_exit, &after_exit)) != -1) {
        snprintf(why, why_size, "after exitInitializationMode, %s differs",
                 bad >= 0 ? var(in->f, (size_t)bad)->name : "a getter's status");
        ok = 0;
    }
    /* FMI 2 tells the time of a drive whose last step was discarded by no getter */
    if (ok && r.m != M_TERMINATED && (r.time_known || !in->f->has_states)) {
        ok = same_step(in, &ref, &r, why, why_size);
        t->steps_compared += ok;
    }
    free_instance(&ref);
    return ok;
}

/* ---- the fuzz ------------------------------------------------------------------------------- */

/* One crafted state: refused with a message, or restored and agreeing. */
static void try_state(instance* target, const unsigned char* bytes, size_t size, tally* t,
                      const char* what)
{
    void* state = NULL;
    char why[700];
    long logged = target->book.count;
    const int status = deserialize(target, bytes, size, &state);
    ++t->tried;
    if (status == 3) {
        ++t->refused;
        if (state != NULL || target->book.count == logged ||
            strstr(target->book.last, "refused: ") == NULL ||
            strstr(target->book.last, "checksum") != NULL) {
            if (t->failures++ < MISMATCHES_SHOWN) {
                printf("    FAIL %s: refused without its reason: %s\n", what, target->book.last);
            }
        }
        return;
    }
    ++t->accepted;
    if (status != 0 || set_state(target, state) != 0) {
        snprintf(why, sizeof why, "deserialized (%d) but not set: %s", status, target->book.last);
    } else if (agrees(target, bytes, size, t, why, sizeof why)) {
        free_state(target, &state);
        return;
    }
    free_state(target, &state);
    if (t->failures++ < MISMATCHES_SHOWN) {
        printf("    FAIL %s: accepted, but %s\n", what, why);
    }
}

/* The values an 8-byte field is given: doubles, then integers. */
static size_t field_values(const unsigned char* field, uint64_t out[], size_t capacity)
{
    double was,
        doubles[] = {NAN, INFINITY, -INFINITY, 7,       -1,      1e300,    -1e300, 0, -0.0, 1,
                     2,   3,        0.5,       DBL_MAX, DBL_MIN, 4.9e-324, 0,      0, 0,    0};
    const int64_t integers[] = {0, 1, 2, 3, 4, 5, 7, 8, 16, -1, INT64_MAX, INT64_MIN};
    const size_t n_doubles = sizeof doubles / sizeof doubles[0];
    size_t k, n = 0;
    memcpy(&was, field, sizeof was);
    doubles[n_doubles - 4] = was + 1;
    doubles[n_doubles - 3] = -was;
    doubles[n_doubles - 2] = nextafter(was, INFINITY);
    doubles[n_doubles - 1] = was * 1e10;
    for (k = 0; k < n_doubles && n < capacity; ++k) {
        memcpy(&out[n++], &doubles[k], sizeof out[0]);
    }
    for (k = 0; k < sizeof integers / sizeof integers[0] && n < capacity; ++k) {
        memcpy(&out[n++], &integers[k], sizeof out[0]);
    }
    return n;
}

static void fuzz_fields(instance* target, const unsigned char* base, size_t size, tally* t)
{
    unsigned char* bytes = (unsigned char*)malloc(size);
    uint64_t values[64];
    char what[120];
    size_t at, k, n;
    for (at = HEADER; bytes != NULL && at + 8 <= size; at += 8) {
        n = field_values(base + at, values, sizeof values / sizeof values[0]);
        for (k = 0; k < n; ++k) {
            memcpy(bytes, base, size);
            memcpy(bytes + at, &values[k], 8);
            if (memcmp(bytes + at, base + at, 8) == 0) {
                continue;
            }
            seal(bytes, size);
            snprintf(what, sizeof what, "payload byte %zu = 0x%016llx", at - HEADER,
                     (unsigned long long)values[k]);
            try_state(target, bytes, size, t, what);
        }
    }
    free(bytes);
}

/* Two fields at once given the same value (the time and the last successful time
 * together, say), among the first 16 fields. */
static void fuzz_pairs(instance* target, const unsigned char* base, size_t size, tally* t)
{
    static const double same[] = {NAN, INFINITY, 7, -1, 1e300, 0};
    unsigned char* bytes = (unsigned char*)malloc(size);
    char what[120];
    size_t a, b, k;
    for (a = HEADER; bytes != NULL && a + 8 <= size && a < HEADER + 16 * 8; a += 8) {
        for (b = a + 8; b + 8 <= size && b < HEADER + 16 * 8; b += 8) {
            for (k = 0; k < sizeof same / sizeof same[0]; ++k) {
                memcpy(bytes, base, size);
                memcpy(bytes + a, &same[k], 8);
                memcpy(bytes + b, &same[k], 8);
                seal(bytes, size);
                snprintf(what, sizeof what, "payload bytes %zu and %zu = %g", a - HEADER,
                         b - HEADER, same[k]);
                try_state(target, bytes, size, t, what);
            }
        }
    }
    free(bytes);
}

/* Random values in random fields, from a seed: what the lists above do not think of. */
static void fuzz_random(instance* target, const unsigned char* base, size_t size, tally* t)
{
    unsigned char* bytes = (unsigned char*)malloc(size);
    const size_t fields = (size - HEADER) / 8;
    char what[120];
    probe_rng rng;
    uint64_t value;
    size_t at;
    int k;
    probe_rng_seed(&rng, 20260101);
    for (k = 0; bytes != NULL && fields > 0 && k < 500; ++k) {
        at = HEADER + 8 * (size_t)probe_rng_below(&rng, fields);
        value = probe_rng_next(&rng);
        if (k % 2 == 1) { /* a double of any magnitude and sign */
            const double x =
                ldexp(probe_rng_uniform(&rng) - 0.5, (int)probe_rng_below(&rng, 80) - 40);
            memcpy(&value, &x, 8);
        }
        memcpy(bytes, base, size);
        memcpy(bytes + at, &value, 8);
        seal(bytes, size);
        snprintf(what, sizeof what, "payload byte %zu = 0x%016llx (random)", at - HEADER,
                 (unsigned long long)value);
        try_state(target, bytes, size, t, what);
    }
    free(bytes);
}

static void fuzz_bits(instance* target, const unsigned char* base, size_t size, tally* t)
{
    static const unsigned char flips[] = {0x01, 0x10, 0x80};
    unsigned char* bytes = (unsigned char*)malloc(size);
    char what[120];
    size_t at, k;
    for (at = HEADER; bytes != NULL && at < size; ++at) {
        for (k = 0; k < sizeof flips; ++k) {
            memcpy(bytes, base, size);
            bytes[at] ^= flips[k];
            seal(bytes, size);
            snprintf(what, sizeof what, "payload byte %zu ^ 0x%02x", at - HEADER, flips[k]);
            try_state(target, bytes, size, t, what);
        }
    }
    free(bytes);
}

/* The fuzz of one FMU from a state in Initialization and one after five steps; returns
 * the number of failures. */
static long fuzz_fmu(const fmu* f)
{
    tally t;
    instance target;
    size_t size = 0;
    int steps;
    memset(&t, 0, sizeof t);
    if (!new_instance(f, &target, "target")) {
        printf("    FAIL FMI %d: cannot instantiate\n", f->version);
        return 1;
    }
    for (steps = 0; steps <= 5; steps += 5) {
        unsigned char* base = base_state(f, steps, &size);
        if (base == NULL) {
            printf("    FAIL FMI %d: no state to start from\n", f->version);
            ++t.failures;
            continue;
        }
        try_state(&target, base, size, &t, "the state as taken");
        fuzz_fields(&target, base, size, &t);
        fuzz_pairs(&target, base, size, &t);
        fuzz_random(&target, base, size, &t);
        fuzz_bits(&target, base, size, &t);
        free(base);
    }
    printf("state fuzz %s FMI %d: %zu payload bytes, %ld states: %ld accepted (%ld in "
           "Instantiated, %ld Initialization, %ld Step, %ld Terminated; %ld steps compared), "
           "%ld refused, %ld failures\n",
           f->md.identifier, f->version, size - HEADER, t.tried, t.accepted, t.in_machine[0],
           t.in_machine[1], t.in_machine[2], t.in_machine[3], t.steps_compared, t.refused,
           t.failures);
    free_instance(&target);
    return t.failures;
}

static int load(const char* directory, int version, fmu* f)
{
    char error[512];
    memset(f, 0, sizeof *f);
    f->version = version;
    if (!probe_read_model(directory, &f->md, error, sizeof error) || f->md.fmi_version != version ||
        !(version == 2 ? probe_load_fmi2(&f->md, &f->f2, error, sizeof error)
                       : probe_load_fmi3(&f->md, &f->f3, error, sizeof error))) {
        printf("%s: %s\n", directory,
               f->md.fmi_version != version ? "not this FMI version" : error);
        return 0;
    }
    sort_variables(f);
    return 1;
}

int main(int argc, char** argv)
{
    static fmu f;
    long failures = 0;
    int version;
    if (argc == 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("usage: fmu_state_fuzz FMI2_FMU_DIR FMI3_FMU_DIR\n"
               "Serialized FMU states of one model's two unpacked FMUs changed one value at a "
               "time, the checksum recomputed: every state accepted must give a fresh "
               "instance's outputs bit for bit; exits non-zero if one does not.\n");
        return 0;
    }
    if (argc != 3) {
        printf("usage: fmu_state_fuzz FMI2_FMU_DIR FMI3_FMU_DIR\n");
        return 2;
    }
    for (version = 2; version <= 3; ++version) {
        if (!load(argv[version - 1], version, &f)) {
            return 1;
        }
        failures += fuzz_fmu(&f);
        probe_unload(version == 2 ? f.f2.library : f.f3.library);
        probe_free_model(&f.md);
    }
    printf("%s\n", failures == 0 ? "state fuzz passed" : "state fuzz FAILED");
    return failures == 0 ? 0 : 1;
}
