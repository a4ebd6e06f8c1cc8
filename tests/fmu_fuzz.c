/* dyadfmu: a fuzz driver for the FMU binaries, FMI 2 and FMI 3.
 *
 * It loads an extracted FMU (its modelDescription.xml and binary, as an
 * importer does) and runs episodes: a fresh instance, a random sequence of
 * set, get and doStep calls through the state machine with nasty values
 * (NaN, infinities, +-DBL_MAX, +-DBL_MIN, denormals, -0, huge and tiny, at and
 * around the declared bounds, random bit patterns) for every input and
 * parameter, and nasty step sizes and times. After every call it checks:
 *
 *   - an accepted setter got finite values within the declared bounds, for
 *     variables settable in that state, and the getters return them exactly;
 *   - a rejected setter (or any call that returns Error) logged a message, and
 *     changed nothing: every variable, output and status reads as before;
 *   - the status output is 0 exactly when the getter says OK, and then every
 *     output is finite; otherwise every output is NaN, except those the model
 *     descriptions keep defined (a dyad's conditioning and amplification; the
 *     drive's motor.torque and the motor's motor.current, NaN only where they
 *     overflow themselves), and doStep is
 *     not OK unless on_singular (set too, FMI 2 as Integer, FMI 3 as Int64) is 2,
 *     continue; a model's states (the drive's crank.angle and crank.omega, a
 *     plant's outputs X with a parameter X_start) and a plant's solver counts
 *     are finite whatever the status;
 *   - an OK doStep had finite t, h > 0 and t + h, reports t + h as the last
 *     successful time, and moved a model's state if the step should have;
 *     an algebraic model's outputs do not depend on the step;
 *   - a discarded doStep reports t as the last successful time and changed
 *     nothing, or, for a model with states, a last successful time in [t, t + h)
 *     where its states stopped, the next step starting there;
 *   - the episode replayed on a fresh instance gives the same trace, bit for
 *     bit (every status, value, and logged message).
 *
 * Each episode has its own seed, printed on a failure; --replay SEED --verbose
 * reruns that episode alone and prints every call.
 *
 * Usage: fmu_fuzz [--steps N] [--seed S] [--replay SEED] [--verbose] FMU_DIR
 */
#define _POSIX_C_SOURCE 200809L

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmu_probe.h"

/* ---- the FMU, either version ---------------------------------------------------------------- */

/* What an output may be when the status output is not 0, as the model
 * descriptions say; every output is finite when it is 0. */
typedef enum fuzz_rule {
    FUZZ_NAN_WHEN_FAILED = 0, /* NaN unless status 0 (the reactions, crank.epsilon) */
    FUZZ_ANY_WHEN_FAILED,     /* explains the failure: a dyad's conditioning, amplification */
    FUZZ_FINITE_OR_NAN,       /* NaN only where it overflows itself: the drive's motor.torque,
                                 the motor's motor.current (a state, but without inductance it
                                 follows the inputs), a plant's CRANK.motor.current without
                                 inductance (it follows the state and the supply) */
    FUZZ_ALWAYS_FINITE        /* a state, kept whatever the status, and a solver's counts */
} fuzz_rule;

typedef struct fuzz_named_rule {
    const char* name;
    fuzz_rule rule;
} fuzz_named_rule;

static const fuzz_named_rule fuzz_rules[] = {
    {"conditioning", FUZZ_ANY_WHEN_FAILED}, {"amplification", FUZZ_ANY_WHEN_FAILED},
    {"motor.torque", FUZZ_FINITE_OR_NAN},   {"motor.current", FUZZ_FINITE_OR_NAN},
    {"solver.steps", FUZZ_ALWAYS_FINITE},   {"solver.evaluations", FUZZ_ALWAYS_FINITE},
};

/* Whether `name` ends with `suffix`. */
static int ends_with(const char* name, const char* suffix)
{
    const size_t n = strlen(name), m = strlen(suffix);
    return n >= m && strcmp(name + n - m, suffix) == 0;
}

typedef struct fuzz_fmu {
    probe_model model;
    probe_fmi2 f2;
    probe_fmi3 f3;
    /* Indices into model.variables, and value references in the same order. */
    size_t* reals; /* every Real variable but FMI 3's time */
    unsigned* real_vrs;
    size_t real_count;
    size_t* integers;
    unsigned* integer_vrs;
    size_t integer_count;
    size_t* settable; /* inputs and parameters */
    size_t settable_count;
    int status_index;          /* the Integer output `status`, -1 if none */
    int on_singular;           /* the Enumeration parameter on_singular, -1 if none */
    int angle, omega, epsilon; /* the drive's crank.angle, .omega, .epsilon; -1 if none */
    int has_states;            /* a step carries states from where the last one ended */
    int first_state;           /* the first state output, -1 if none */
    int* rate_of;              /* per state output: the state that is its rate, -1 if none */
    fuzz_rule* rule;           /* per variable: what an output may be when status is not 0 */
} fuzz_fmu;

/* The length of a state's name up to its last '.': the driver it belongs to. */
static size_t owner_length(const char* name)
{
    const char* dot = strrchr(name, '.');
    return dot != NULL ? (size_t)(dot - name) : 0;
}

/* Pairs each state output with the next one of the same driver (a position with its
 * rate: crank.angle, crank.omega; ram.position, ram.velocity). */
static void pair_states(fuzz_fmu* f)
{
    size_t k, j, n = f->model.variable_count;
    for (k = 0; k < n; ++k) {
        const probe_variable* v = &f->model.variables[k];
        f->rate_of[k] = -1;
        if (probe_state_start(&f->model, v) == NULL) {
            continue;
        }
        for (j = k + 1; j < n; ++j) {
            const probe_variable* w = &f->model.variables[j];
            if (probe_state_start(&f->model, w) != NULL) {
                if (owner_length(w->name) == owner_length(v->name) &&
                    strncmp(w->name, v->name, owner_length(v->name)) == 0) {
                    f->rate_of[k] = (int)j;
                }
                break;
            }
        }
    }
}

static int fuzz_prepare(fuzz_fmu* f, const char* directory)
{
    char error[512];
    size_t k, n;
    memset(f, 0, sizeof *f);
    if (!probe_read_model(directory, &f->model, error, sizeof error)) {
        printf("%s\n", error);
        return 0;
    }
    if (!(f->model.fmi_version == 2 ? probe_load_fmi2(&f->model, &f->f2, error, sizeof error)
                                    : probe_load_fmi3(&f->model, &f->f3, error, sizeof error))) {
        printf("%s\n", error);
        return 0;
    }
    n = f->model.variable_count;
    f->reals = (size_t*)calloc(n + 1, sizeof *f->reals);
    f->real_vrs = (unsigned*)calloc(n + 1, sizeof *f->real_vrs);
    f->integers = (size_t*)calloc(n + 1, sizeof *f->integers);
    f->integer_vrs = (unsigned*)calloc(n + 1, sizeof *f->integer_vrs);
    f->settable = (size_t*)calloc(n + 1, sizeof *f->settable);
    f->rule = (fuzz_rule*)calloc(n + 1, sizeof *f->rule);
    f->rate_of = (int*)calloc(n + 1, sizeof *f->rate_of);
    if (f->reals == NULL || f->real_vrs == NULL || f->integers == NULL || f->integer_vrs == NULL ||
        f->settable == NULL || f->rule == NULL || f->rate_of == NULL) {
        printf("out of memory\n");
        return 0;
    }
    f->status_index = f->angle = f->omega = f->epsilon = f->on_singular = -1;
    for (k = 0; k < n; ++k) {
        const probe_variable* v = &f->model.variables[k];
        size_t j;
        if (v->causality == PROBE_INDEPENDENT || v->is_array) {
            continue;
        }
        if (v->type == PROBE_REAL) {
            f->real_vrs[f->real_count] = v->vr;
            f->reals[f->real_count++] = k;
        } else if (v->type == PROBE_INTEGER) {
            f->integer_vrs[f->integer_count] = v->vr;
            f->integers[f->integer_count++] = k;
        }
        if (v->causality == PROBE_INPUT || v->causality == PROBE_PARAMETER) {
            f->settable[f->settable_count++] = k;
        }
        if (v->type == PROBE_ENUMERATION && strcmp(v->name, "on_singular") == 0) {
            f->on_singular = (int)k;
        }
        if (v->causality == PROBE_OUTPUT) {
            if (v->type == PROBE_INTEGER && strcmp(v->name, "status") == 0) {
                f->status_index = (int)k;
            }
            if (strcmp(v->name, "crank.angle") == 0) {
                f->angle = (int)k;
            } else if (strcmp(v->name, "crank.omega") == 0) {
                f->omega = (int)k;
            } else if (strcmp(v->name, "crank.epsilon") == 0) {
                f->epsilon = (int)k;
            }
            if (probe_state_start(&f->model, v) != NULL) {
                f->rule[k] = FUZZ_ALWAYS_FINITE;
                f->first_state = f->has_states ? f->first_state : (int)k;
                f->has_states = 1;
            }
            /* a rule by name comes before a state's: the motor's current */
            for (j = 0; j < sizeof fuzz_rules / sizeof fuzz_rules[0]; ++j) {
                if (strcmp(v->name, fuzz_rules[j].name) == 0) {
                    f->rule[k] = fuzz_rules[j].rule;
                }
            }
            /* a plant's motor without inductance: its current no state, but (V - k ratio
             * omega) / R of the state and the supply, whatever the status */
            if (f->rule[k] != FUZZ_ALWAYS_FINITE && ends_with(v->name, ".motor.current")) {
                f->rule[k] = FUZZ_FINITE_OR_NAN;
            }
        }
    }
    if (f->angle < 0 || f->omega < 0 || f->epsilon < 0) {
        f->angle = f->omega = f->epsilon = -1;
    }
    pair_states(f);
    return 1;
}

static void fuzz_release(fuzz_fmu* f)
{
    probe_unload(f->model.fmi_version == 2 ? f->f2.library : f->f3.library);
    free(f->reals);
    free(f->real_vrs);
    free(f->integers);
    free(f->integer_vrs);
    free(f->settable);
    free(f->rule);
    free(f->rate_of);
    probe_free_model(&f->model);
}

static int has_state(const fuzz_fmu* f)
{
    return f->has_states;
}

/* ---- an episode ----------------------------------------------------------------------------- */

typedef enum fuzz_state { S_INSTANTIATED, S_INITIALIZATION, S_STEP, S_TERMINATED } fuzz_state;
static const char* const fuzz_state_names[] = {"Instantiated", "Initialization", "Step",
                                               "Terminated"};

/* What every call reads back: all Real and Integer variables, and the status
 * of the getter. */
typedef struct fuzz_snapshot {
    int valid;
    int get_status;
    double* reals;
    int* integers;
} fuzz_snapshot;

typedef struct fuzz_counts {
    long episodes, instances, steps, steps_ok, steps_continued, steps_discard, steps_error;
    long sets, sets_rejected, gets, illegal_calls, replays;
} fuzz_counts;

typedef struct fuzz_episode {
    const fuzz_fmu* fmu;
    probe_rng rng;
    void* instance;
    probe_log_book book;
    fuzz_state state;
    double* shadow; /* per variable: the value the last accepted set stored */
    double* rates;  /* per variable: the first derivative the last accepted set gave it */
    double time;    /* the communication point an importer would use next */
    uint64_t trace;
    fuzz_snapshot before, after;
    long call; /* index of the current call, for the report */
    long step_quota;
    int verbose;
    int failed; /* an invariant broke */
    fuzz_counts* counts;
    unsigned last_vrs[6]; /* of the last setReal of op_set_real, */
    size_t last_n;        /* which a third of them call again */
    char failure[1200];
} fuzz_episode;

static void note(fuzz_episode* e, const char* format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void note(fuzz_episode* e, const char* format, ...)
{
    va_list args;
    if (!e->verbose) {
        return;
    }
    va_start(args, format);
    printf("    #%ld ", e->call);
    vprintf(format, args);
    printf("\n");
    va_end(args);
}

/* Records the first broken invariant of the episode, which ends it. */
static void violation(fuzz_episode* e, const char* format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void violation(fuzz_episode* e, const char* format, ...)
{
    va_list args;
    if (e->failed) {
        return;
    }
    va_start(args, format);
    vsnprintf(e->failure, sizeof e->failure, format, args);
    va_end(args);
    e->failed = 1;
    note(e, "VIOLATION: %s", e->failure);
}

static int stopped(const fuzz_episode* e)
{
    return e->failed;
}

static const char* name_of(const fuzz_episode* e, size_t index)
{
    return e->fmu->model.variables[index].name;
}

static int fmi2(const fuzz_episode* e)
{
    return e->fmu->model.fmi_version == 2;
}

static void trace(fuzz_episode* e, uint64_t v)
{
    e->trace = probe_hash_u64(e->trace, v);
}

static void trace_double(fuzz_episode* e, double x)
{
    e->trace = probe_hash_double(e->trace, x);
}

/* Every call that returns Error must say why through the logger. */
static void expect_message(fuzz_episode* e, int status, long count_before, const char* call)
{
    if (status >= 3 && (e->book.count == count_before || e->book.last_status < 3)) {
        violation(e, "%s returned %d without logging an error", call, status);
    }
}

/* ---- the calls, either version -------------------------------------------------------------- */

static int call_set_real(fuzz_episode* e, const unsigned* vrs, size_t n, const double* values)
{
    if (fmi2(e)) {
        return (int)e->fmu->f2.SetReal(e->instance, vrs, n, values);
    }
    return (int)e->fmu->f3.SetFloat64(e->instance, vrs, n, values, n);
}

static int call_set_integer(fuzz_episode* e, const unsigned* vrs, size_t n, const int* values)
{
    if (fmi2(e)) {
        return (int)e->fmu->f2.SetInteger(e->instance, vrs, n, values);
    }
    return (int)e->fmu->f3.SetInt32(e->instance, vrs, n, values, n);
}

static int call_set_int64(fuzz_episode* e, const unsigned* vrs, size_t n, const int64_t* values)
{
    return (int)e->fmu->f3.SetInt64(e->instance, vrs, n, values, n);
}

static int call_get_real(fuzz_episode* e, const unsigned* vrs, size_t n, double* values)
{
    if (fmi2(e)) {
        return (int)e->fmu->f2.GetReal(e->instance, vrs, n, values);
    }
    return (int)e->fmu->f3.GetFloat64(e->instance, vrs, n, values, n);
}

static int call_get_integer(fuzz_episode* e, const unsigned* vrs, size_t n, int* values)
{
    if (fmi2(e)) {
        return (int)e->fmu->f2.GetInteger(e->instance, vrs, n, values);
    }
    return (int)e->fmu->f3.GetInt32(e->instance, vrs, n, values, n);
}

/* ---- snapshots ------------------------------------------------------------------------------ */

static int can_get(const fuzz_episode* e)
{
    return e->state != S_INSTANTIATED;
}

static int is_finite(double x)
{
    return x - x == 0;
}

/* Reads every variable into s and checks what must hold at any time. */
static void snapshot(fuzz_episode* e, fuzz_snapshot* s)
{
    const fuzz_fmu* f = e->fmu;
    int status = 0, integer_status = 0;
    size_t k;
    s->valid = 0;
    if (!can_get(e)) {
        return;
    }
    ++e->counts->gets;
    /* sentinels: a getter that returns OK must have written every value */
    for (k = 0; k < f->real_count; ++k) {
        s->reals[k] = -12345.678;
    }
    s->get_status = call_get_real(e, f->real_vrs, f->real_count, s->reals);
    if (f->integer_count > 0) {
        integer_status = call_get_integer(e, f->integer_vrs, f->integer_count, s->integers);
    }
    trace(e, (uint64_t)s->get_status);
    trace(e, (uint64_t)integer_status);
    for (k = 0; k < f->real_count; ++k) {
        trace_double(e, s->reals[k]);
    }
    for (k = 0; k < f->integer_count; ++k) {
        trace(e, (uint64_t)(unsigned)s->integers[k]);
    }
    if (integer_status != 0) {
        violation(e, "getting the Integer variables in %s returned %d", fuzz_state_names[e->state],
                  integer_status);
        return;
    }
    if (s->get_status > 3) {
        violation(e, "getting the Real variables returned %d", s->get_status);
        return;
    }
    s->valid = 1;
    /* inputs and parameters read back as last set */
    for (k = 0; k < f->real_count; ++k) {
        const size_t index = f->reals[k];
        if (f->model.variables[index].causality != PROBE_OUTPUT &&
            probe_bits(s->reals[k]) != probe_bits(e->shadow[index])) {
            violation(e, "%s reads %.17g, but the last accepted value was %.17g", name_of(e, index),
                      s->reals[k], e->shadow[index]);
            return;
        }
    }
    if (f->status_index >= 0) {
        for (k = 0; k < f->integer_count; ++k) {
            if ((int)f->integers[k] == f->status_index) {
                status = s->integers[k];
            }
        }
    } else {
        status = s->get_status == 0 ? 0 : -1;
    }
    if ((status == 0) != (s->get_status == 0)) {
        violation(e, "status output %d but the getter returned %d", status, s->get_status);
        return;
    }
    for (k = 0; k < f->real_count; ++k) {
        const size_t index = f->reals[k];
        const double x = s->reals[k];
        if (f->model.variables[index].causality != PROBE_OUTPUT) {
            continue;
        }
        const fuzz_rule rule = f->rule[index];
        if ((status == 0 || rule == FUZZ_ALWAYS_FINITE) && !is_finite(x)) {
            violation(e, "status %d but %s = %g", status, name_of(e, index), x);
            return;
        }
        if (status != 0 && rule == FUZZ_NAN_WHEN_FAILED && !isnan(x)) {
            violation(e, "status %d but %s = %.17g, not NaN", status, name_of(e, index), x);
            return;
        }
        if (status != 0 && rule == FUZZ_FINITE_OR_NAN && isinf(x)) {
            violation(e, "status %d but %s = %g, neither finite nor NaN", status, name_of(e, index),
                      x);
            return;
        }
    }
}

static double snapshot_real(const fuzz_episode* e, const fuzz_snapshot* s, int index)
{
    size_t k;
    for (k = 0; k < e->fmu->real_count; ++k) {
        if ((int)e->fmu->reals[k] == index) {
            return s->reals[k];
        }
    }
    return NAN;
}

/* The snapshot before a call that must change nothing, if the state allows one. */
static void take_before(fuzz_episode* e)
{
    if (!e->before.valid) {
        snapshot(e, &e->before);
    }
}

/* Compares the snapshot after a call with the one before it, bit for bit. */
static void compare_with_before(fuzz_episode* e, const char* call)
{
    const fuzz_fmu* f = e->fmu;
    size_t k;
    if (e->after.get_status != e->before.get_status) {
        violation(e, "%s changed the getter's status from %d to %d", call, e->before.get_status,
                  e->after.get_status);
        return;
    }
    for (k = 0; k < f->real_count; ++k) {
        if (probe_bits(e->after.reals[k]) != probe_bits(e->before.reals[k])) {
            violation(e, "%s changed %s from %.17g to %.17g", call, name_of(e, f->reals[k]),
                      e->before.reals[k], e->after.reals[k]);
            return;
        }
    }
    for (k = 0; k < f->integer_count; ++k) {
        if (e->after.integers[k] != e->before.integers[k]) {
            violation(e, "%s changed %s from %d to %d", call, name_of(e, f->integers[k]),
                      e->before.integers[k], e->after.integers[k]);
            return;
        }
    }
}

/* After a call that must have changed nothing: everything reads as before. */
static void expect_unchanged(fuzz_episode* e, const char* call)
{
    if (!e->before.valid || stopped(e)) {
        return;
    }
    snapshot(e, &e->after);
    if (e->after.valid && !stopped(e)) {
        compare_with_before(e, call);
    }
}

/* The snapshot after a call becomes the one before the next. */
static void swap_snapshots(fuzz_episode* e)
{
    const fuzz_snapshot keep = e->before;
    e->before = e->after;
    e->after = keep;
    e->after.valid = 0;
}

/* ---- nasty values --------------------------------------------------------------------------- */

static double from_bits(uint64_t bits)
{
    double x;
    memcpy(&x, &bits, sizeof x);
    return x;
}

static double special_value(probe_rng* rng)
{
    const double specials[] = {NAN,
                               -(double)NAN,
                               INFINITY,
                               -INFINITY,
                               DBL_MAX,
                               -DBL_MAX,
                               DBL_MIN,
                               -DBL_MIN,
                               4.9406564584124654e-324,
                               -4.9406564584124654e-324, /* smallest denormals */
                               2.2250738585072009e-308,
                               -2.2250738585072009e-308, /* largest denormals */
                               0.0,
                               -0.0,
                               1e308,
                               -1e308,
                               1e300,
                               -1e300,
                               1e154,
                               -1e154, /* squares overflow */
                               1e-154,
                               -1e-160,
                               1e-300,
                               9007199254740992.0,
                               9.2233720368547758e18,
                               -9.3e18,
                               1e16,
                               -1e16,
                               1.5707963267948966,
                               -1.5707963267948966,
                               3.141592653589793,
                               1.0,
                               -1.0,
                               from_bits(0x7FF0000000000001ULL) /* a signalling NaN */};
    return specials[probe_rng_below(rng, sizeof specials / sizeof specials[0])];
}

static double log_uniform(probe_rng* rng)
{
    const double magnitude = pow(10.0, -324.0 + 632.2 * probe_rng_uniform(rng));
    return probe_rng_below(rng, 2) ? magnitude : -magnitude;
}

/* A value an importer might well set: near the start value, inside the bounds. */
static double plausible_value(probe_rng* rng, const probe_variable* v)
{
    static const double scales[] = {0.01, 0.1, 1.0, 10.0};
    const double start = v->has_start ? v->start : 0.0;
    const double scale = (fabs(start) > 1 ? fabs(start) : 1.0) * scales[probe_rng_below(rng, 4)];
    double x = start + (2 * probe_rng_uniform(rng) - 1) * scale;
    if (v->has_min && x < v->min) {
        x = v->min + (v->min - x);
    }
    if (v->has_max && x > v->max) {
        x = v->max - (x - v->max);
    }
    if ((v->has_min && x < v->min) || (v->has_max && x > v->max)) {
        x = v->has_min && v->has_max ? 0.5 * (v->min + v->max) : start;
    }
    return x;
}

/* Values at and next to the declared bounds and the start value. */
static double edge_value(probe_rng* rng, const probe_variable* v)
{
    double candidates[9];
    size_t n = 0;
    if (v->has_min) {
        candidates[n++] = v->min;
        candidates[n++] = nextafter(v->min, -INFINITY);
        candidates[n++] = nextafter(v->min, INFINITY);
    }
    if (v->has_max) {
        candidates[n++] = v->max;
        candidates[n++] = nextafter(v->max, -INFINITY);
        candidates[n++] = nextafter(v->max, INFINITY);
    }
    if (v->has_start) {
        candidates[n++] = v->start;
        candidates[n++] = nextafter(v->start, INFINITY);
        candidates[n++] = -v->start;
    }
    if (n == 0) {
        return probe_rng_below(rng, 2) ? 0.0 : -0.0;
    }
    return candidates[probe_rng_below(rng, n)];
}

static double nasty_value(probe_rng* rng, const probe_variable* v)
{
    const uint64_t pick = probe_rng_below(rng, 100);
    if (pick < 45) {
        return plausible_value(rng, v);
    }
    if (pick < 62) {
        return special_value(rng);
    }
    if (pick < 76) {
        return edge_value(rng, v);
    }
    if (pick < 88) {
        return log_uniform(rng);
    }
    if (pick < 94) {
        return from_bits(probe_rng_next(rng));
    }
    return (v->has_start ? v->start : 1.0) * pow(10.0, -30.0 + 60.0 * probe_rng_uniform(rng));
}

static double nasty_step(probe_rng* rng)
{
    static const double steps[] = {
        0.0,    -0.0,    -1e-3, NAN,  INFINITY, -INFINITY, DBL_MIN, 4.9406564584124654e-324,
        1e-300, DBL_MAX, 1e300, 1e16, 1e6,      1.0,       -DBL_MAX};
    const uint64_t pick = probe_rng_below(rng, 100);
    if (pick < 70) {
        return pow(10.0, -4.0 + 3.0 * probe_rng_uniform(rng));
    }
    if (pick < 90) {
        return steps[probe_rng_below(rng, sizeof steps / sizeof steps[0])];
    }
    return log_uniform(rng);
}

static double nasty_time(probe_rng* rng, double tracked)
{
    static const double times[] = {DBL_MAX, -DBL_MAX, NAN, INFINITY, 1e300, -1e300, -0.0, 1e20};
    const uint64_t pick = probe_rng_below(rng, 100);
    if (pick < 90) {
        return tracked;
    }
    if (pick < 97) {
        return times[probe_rng_below(rng, sizeof times / sizeof times[0])];
    }
    return log_uniform(rng);
}

/* ---- operations ----------------------------------------------------------------------------- */

/* Whether a setter of `type` (the type it is named for) sets a variable of type
 * `variable`: FMI 2's fmi2SetInteger sets Enumerations too, FMI 3 has fmi3SetInt64. */
static int sets_type(const fuzz_episode* e, probe_type type, probe_type variable)
{
    return variable == type || (fmi2(e) && type == PROBE_INTEGER && variable == PROBE_ENUMERATION);
}

/* Whether doStep goes on where the model has no answer: on_singular is 2, continue. */
static int continues(const fuzz_episode* e)
{
    return e->fmu->on_singular >= 0 && e->shadow[e->fmu->on_singular] == 2;
}

/* Why a set of this variable and value must be refused now, or NULL. */
static const char* must_refuse(const fuzz_episode* e, const probe_variable* v, double value,
                               probe_type type)
{
    if (v == NULL) {
        return "unknown value reference";
    }
    if (!sets_type(e, type, v->type)) {
        return "wrong type";
    }
    if (v->type == PROBE_ENUMERATION && !(value == 1 || value == 2)) {
        return "not an item of on_singular (1 discard, 2 continue)";
    }
    if (e->state == S_TERMINATED) {
        return "set in Terminated";
    }
    if (e->state == S_STEP ? !probe_settable_in_step_mode(v)
                           : !probe_settable_before_initialization(v)) {
        return "not settable in this state";
    }
    if (!is_finite(value)) {
        return "not finite";
    }
    if ((v->has_min && value < v->min) || (v->has_max && value > v->max)) {
        return "outside the declared bounds";
    }
    return NULL;
}

static unsigned random_vr(fuzz_episode* e, probe_type type)
{
    const fuzz_fmu* f = e->fmu;
    const uint64_t pick = probe_rng_below(&e->rng, 100);
    if (pick < 80 && f->settable_count > 0) {
        return f->model.variables[f->settable[probe_rng_below(&e->rng, f->settable_count)]].vr;
    }
    if (pick < 88 && f->real_count > 0) {
        return f->real_vrs[probe_rng_below(&e->rng, f->real_count)];
    }
    if (pick < 93 && f->integer_count > 0) {
        return f->integer_vrs[probe_rng_below(&e->rng, f->integer_count)];
    }
    if (pick < 96) {
        return 0; /* FMI 3's time, unknown in FMI 2 */
    }
    (void)type;
    return probe_rng_below(&e->rng, 2) ? probe_unused_vr(&f->model) : UINT_MAX;
}

/* Checks a setter's outcome against must_refuse, and applies an accepted one
 * to the shadow. */
static void judge_set(fuzz_episode* e, const unsigned* vrs, size_t n, const double* values,
                      probe_type type, int status, long log_count, const char* call)
{
    const char* reason = NULL;
    size_t k, bad = 0;
    for (k = 0; k < n && reason == NULL; ++k) {
        reason = must_refuse(e, probe_variable_of_vr(&e->fmu->model, vrs[k]), values[k], type);
        bad = k;
    }
    trace(e, (uint64_t)status);
    ++e->counts->sets;
    if (status == 0) {
        if (reason != NULL) {
            violation(e, "%s accepted value reference %u = %.17g (%s) in %s", call, vrs[bad],
                      values[bad], reason, fuzz_state_names[e->state]);
            return;
        }
        for (k = 0; k < n; ++k) {
            const probe_variable* v = probe_variable_of_vr(&e->fmu->model, vrs[k]);
            e->shadow[v - e->fmu->model.variables] = values[k];
        }
        if (n > 0) {
            e->before.valid = 0;
        }
        return;
    }
    ++e->counts->sets_rejected;
    if (status != 3) {
        violation(e, "%s returned %d: a setter accepts (0) or refuses (3)", call, status);
        return;
    }
    expect_message(e, status, log_count, call);
    if (n == 1 && e->state != S_TERMINATED && !stopped(e)) {
        /* the message names the variable, or the value reference it does not know */
        const probe_variable* v = probe_variable_of_vr(&e->fmu->model, vrs[0]);
        char number[16];
        sprintf(number, "%u", vrs[0]);
        if (!(v != NULL && strstr(e->book.last, v->name) != NULL) &&
            strstr(e->book.last, number) == NULL) {
            violation(e, "%s refused %s without naming it: %s", call, v != NULL ? v->name : number,
                      e->book.last);
        }
    }
    expect_unchanged(e, call);
}

static void op_set_real(fuzz_episode* e)
{
    unsigned vrs[6];
    double values[6];
    const uint64_t pick = probe_rng_below(&e->rng, 100);
    /* a third of them the same value references as the last: an importer's every
     * step, which the FMU serves by its plan of that call */
    const int again = e->last_n > 0 && probe_rng_below(&e->rng, 3) == 0;
    const size_t n = again       ? e->last_n
                     : pick < 4  ? 0
                     : pick < 65 ? 1
                                 : 2 + (size_t)probe_rng_below(&e->rng, 5);
    long log_count;
    size_t k;
    int status;
    for (k = 0; k < n; ++k) {
        const probe_variable* v;
        /* now and then the same variable twice: the last value counts */
        vrs[k] = again                                        ? e->last_vrs[k]
                 : k > 0 && probe_rng_below(&e->rng, 10) == 0 ? vrs[k - 1]
                                                              : random_vr(e, PROBE_REAL);
        e->last_vrs[k] = vrs[k];
        v = probe_variable_of_vr(&e->fmu->model, vrs[k]);
        values[k] = v != NULL ? nasty_value(&e->rng, v) : special_value(&e->rng);
        trace(e, vrs[k]);
        trace_double(e, values[k]);
    }
    e->last_n = n;
    take_before(e);
    log_count = e->book.count;
    status = call_set_real(e, vrs, n, values);
    note(e, "setReal n=%zu first %s = %.17g -> %d", n,
         n > 0 && probe_variable_of_vr(&e->fmu->model, vrs[0]) != NULL
             ? probe_variable_of_vr(&e->fmu->model, vrs[0])->name
             : "-",
         n > 0 ? values[0] : 0.0, status);
    judge_set(e, vrs, n, values, PROBE_REAL, status, log_count, "setReal");
}

static void op_set_integer(fuzz_episode* e)
{
    static const int specials[] = {0, 1, -1, 2, 3, INT_MAX, INT_MIN};
    unsigned vr = random_vr(e, PROBE_INTEGER);
    const int value = specials[probe_rng_below(&e->rng, sizeof specials / sizeof specials[0])];
    const double as_double = value;
    /* FMI 3 sets an Enumeration as Int64 (and now and then, wrongly, as Int32) */
    const probe_variable* v = probe_variable_of_vr(&e->fmu->model, vr);
    const int as_int64 =
        !fmi2(e) && v != NULL && v->type == PROBE_ENUMERATION && probe_rng_below(&e->rng, 4) != 0;
    const int64_t wide = value;
    long log_count;
    int status;
    trace(e, vr);
    trace(e, (uint64_t)(unsigned)value);
    take_before(e);
    log_count = e->book.count;
    status = as_int64 ? call_set_int64(e, &vr, 1, &wide) : call_set_integer(e, &vr, 1, &value);
    note(e, "set%s vr %u = %d -> %d", as_int64 ? "Int64" : "Integer", vr, value, status);
    judge_set(e, &vr, 1, &as_double, as_int64 ? PROBE_ENUMERATION : PROBE_INTEGER, status,
              log_count, as_int64 ? "setInt64" : "setInteger");
}

/* Sets in one call every Real settable now (inputs_only: every Real input, which in
 * ascending value references is the call an importer makes every step and the FMU
 * serves by its model's straight copy), to plausible values; with `maybe_nasty`, a
 * quarter of the time one of them nasty, which must refuse the whole call. */
static void set_all(fuzz_episode* e, int inputs_only, int maybe_nasty, const char* call)
{
    const fuzz_fmu* f = e->fmu;
    unsigned* vrs = (unsigned*)malloc((f->settable_count + 1) * sizeof *vrs);
    double* values = (double*)malloc((f->settable_count + 1) * sizeof *values);
    size_t k, n = 0;
    long log_count;
    int status;
    if (vrs == NULL || values == NULL) {
        free(vrs);
        free(values);
        return;
    }
    for (k = 0; k < f->settable_count; ++k) {
        const probe_variable* v = &f->model.variables[f->settable[k]];
        if (v->type == PROBE_REAL && (inputs_only ? v->causality == PROBE_INPUT
                                                  : must_refuse(e, v, 0.0, PROBE_REAL) == NULL)) {
            vrs[n] = v->vr;
            values[n] = plausible_value(&e->rng, v);
            ++n;
        }
    }
    if (maybe_nasty && n > 0 && probe_rng_below(&e->rng, 4) == 0) {
        const size_t at = (size_t)probe_rng_below(&e->rng, n);
        values[at] = nasty_value(&e->rng, probe_variable_of_vr(&f->model, vrs[at]));
    }
    for (k = 0; k < n; ++k) {
        trace_double(e, values[k]);
    }
    take_before(e);
    log_count = e->book.count;
    status = call_set_real(e, vrs, n, values);
    note(e, "%s: %zu values -> %d", call, n, status);
    judge_set(e, vrs, n, values, PROBE_REAL, status, log_count, call);
    free(vrs);
    free(values);
}

/* Every variable settable now, to plausible values, in one call: brings an instance
 * that nasty values put out of its domain back to solvable inputs. */
static void op_set_plausible(fuzz_episode* e)
{
    set_all(e, 0, 0, "setReal (plausible)");
}

static void op_set_inputs(fuzz_episode* e)
{
    set_all(e, 1, 1, "setReal (every input)");
}

/* Every Real output in one call, in ascending value references (the FMU's straight
 * copy), against the snapshot's get of every Real: the same values, bit for bit,
 * and the same status. */
static void op_get_outputs(fuzz_episode* e)
{
    const fuzz_fmu* f = e->fmu;
    unsigned* vrs = (unsigned*)malloc((f->real_count + 1) * sizeof *vrs);
    double* values = (double*)malloc((f->real_count + 1) * sizeof *values);
    size_t* at = (size_t*)malloc((f->real_count + 1) * sizeof *at);
    size_t k, n = 0;
    int status;
    take_before(e);
    if (vrs == NULL || values == NULL || at == NULL || !e->before.valid) {
        free(vrs);
        free(values);
        free(at);
        return;
    }
    for (k = 0; k < f->real_count; ++k) {
        if (f->model.variables[f->reals[k]].causality == PROBE_OUTPUT) {
            vrs[n] = f->real_vrs[k];
            at[n++] = k;
        }
    }
    status = call_get_real(e, vrs, n, values);
    note(e, "getReal every output (%zu) -> %d", n, status);
    if (status != e->before.get_status) {
        violation(e, "getReal of every output: status %d, of every Real %d", status,
                  e->before.get_status);
    }
    for (k = 0; k < n && status == 0; ++k) {
        if (memcmp(&values[k], &e->before.reals[at[k]], sizeof values[k]) != 0) {
            violation(e, "getReal of every output: vr %u = %.17g, of every Real %.17g", vrs[k],
                      values[k], e->before.reals[at[k]]);
            break;
        }
    }
    free(vrs);
    free(values);
    free(at);
}

/* Input derivatives (FMI 2) and output derivatives, either version. A model that does not
 * interpolate refuses both with a message. One that does takes a finite first derivative
 * of an input and refuses anything else with a message; the outputs' derivatives are
 * finite with OK, or Discard with a message where the point has none. */
static void op_rates(fuzz_episode* e)
{
    const fuzz_fmu* f = e->fmu;
    const int interpolates = f->model.interpolates;
    const unsigned vr = random_vr(e, PROBE_REAL);
    const probe_variable* v = probe_variable_of_vr(&f->model, vr);
    const double rate =
        probe_rng_below(&e->rng, 4) == 0 ? special_value(&e->rng) : log_uniform(&e->rng);
    int order = probe_rng_below(&e->rng, 8) == 0 ? 2 : 1, status;
    long before = e->book.count;
    size_t k, n = 0;
    unsigned vrs[64];
    int orders[64];
    double values[64];
    if (fmi2(e)) {
        const int takes = interpolates && order == 1 && v != NULL && v->causality == PROBE_INPUT &&
                          v->type == PROBE_REAL && is_finite(rate);
        status = (int)f->f2.SetRealInputDerivatives(e->instance, &vr, 1, &order, &rate);
        note(e, "setRealInputDerivatives vr %u order %d = %.17g -> %d", vr, order, rate, status);
        expect_message(e, status, before, "setRealInputDerivatives");
        if (status == 0 && takes) {
            e->rates[v - f->model.variables] = rate;
        }
        if ((status == 0) != takes) {
            violation(e, "setRealInputDerivatives vr %u order %d = %.17g: status %d", vr, order,
                      rate, status);
        }
    }
    for (k = 0; k < f->real_count && n < 64; ++k) {
        if (f->model.variables[f->reals[k]].causality == PROBE_OUTPUT) {
            vrs[n] = f->real_vrs[k];
            orders[n++] = 1;
        }
    }
    before = e->book.count;
    status = fmi2(e) ? (int)f->f2.GetRealOutputDerivatives(e->instance, vrs, n, orders, values)
                     : (int)f->f3.GetOutputDerivatives(e->instance, vrs, n, orders, values, n);
    note(e, "getOutputDerivatives (%zu) -> %d", n, status);
    expect_message(e, status, before, "getOutputDerivatives");
    if (!interpolates && status != 3) {
        violation(e, "getOutputDerivatives of a model without them: status %d", status);
    }
    if (interpolates && status == 2 && e->book.count == before) {
        violation(e, "getOutputDerivatives discarded without a message");
    }
    for (k = 0; k < n && interpolates && status == 0; ++k) {
        if (!is_finite(values[k])) {
            violation(e, "getOutputDerivatives: vr %u = %.17g with status 0", vrs[k], values[k]);
            break;
        }
    }
}

/* FMI 2: the last successful time and the terminate flag, from the status getters. */
static void fmi2_step_status(fuzz_episode* e, double* last, int* terminate)
{
    fmi2Real time = NAN;
    fmi2Boolean flag = fmi2False;
    const int a = (int)e->fmu->f2.GetRealStatus(e->instance, fmi2LastSuccessfulTime, &time);
    const int b = (int)e->fmu->f2.GetBooleanStatus(e->instance, fmi2Terminated, &flag);
    if (a != 0 || b != 0) {
        violation(e, "fmi2GetRealStatus / fmi2GetBooleanStatus in Step: %d, %d", a, b);
    }
    *last = time;
    *terminate = flag != fmi2False;
}

/* The value of the drive's variable `name` in `before` (NaN if it has none). */
static double before_named(const fuzz_episode* e, const char* name)
{
    const probe_variable* v = probe_variable_named(&e->fmu->model, name);
    return v != NULL ? snapshot_real(e, &e->before, (int)(v - e->fmu->model.variables)) : NAN;
}

/* Whether a step of h s must move some position from `before` by more than a
 * billionth of its size (and beyond underflow): its rate times h does. */
static int position_must_move(const fuzz_episode* e, double h)
{
    size_t k;
    for (k = 0; k < e->fmu->model.variable_count; ++k) {
        if (e->fmu->rate_of[k] >= 0) {
            const double position = snapshot_real(e, &e->before, (int)k);
            const double turn = fabs(h * snapshot_real(e, &e->before, e->fmu->rate_of[k]));
            if (turn > 1e-250 && turn > 1e-9 * fabs(position)) {
                return 1;
            }
        }
    }
    return 0;
}

/* Whether a step of h s from the state in `before` must move it, by more than
 * a billionth of its size (and beyond underflow): in position, if it moves; the
 * drive's speed too, if its acceleration is more than the round-off of the
 * torque balance it comes from (1e-9 of the torques summed: at a standstill
 * held by gravity the acceleration is that round-off, and the state rightly
 * stays). A subnormal step is too short to resolve either. */
static int state_must_move(const fuzz_episode* e, double h)
{
    const double omega = snapshot_real(e, &e->before, e->fmu->omega);
    const double epsilon = snapshot_real(e, &e->before, e->fmu->epsilon);
    const double inertia = before_named(e, "inertia") + before_named(e, "load.inertia");
    const double gravity = fabs(before_named(e, "crank.mass")) *
                           hypot(before_named(e, "crank.com.x"), before_named(e, "crank.com.y")) *
                           hypot(before_named(e, "gravity.x"), before_named(e, "gravity.y"));
    const double torques = fabs(before_named(e, "motor.torque")) +
                           fabs(before_named(e, "load.torque")) + gravity; /* N.m */
    const double spin = fabs(h * epsilon);
    if (!(h >= DBL_MIN)) {
        return 0;
    }
    return position_must_move(e, h) ||
           (e->fmu->angle >= 0 && spin > 1e-250 && spin > 1e-9 * fabs(omega) &&
            fabs(epsilon) * inertia > 1e-9 * torques);
}

/* Whether some state output differs between `before` and `after`. */
static int states_moved(const fuzz_episode* e)
{
    size_t k;
    for (k = 0; k < e->fmu->real_count; ++k) {
        if (e->fmu->rule[e->fmu->reals[k]] == FUZZ_ALWAYS_FINITE &&
            probe_state_start(&e->fmu->model, &e->fmu->model.variables[e->fmu->reals[k]]) != NULL &&
            probe_bits(e->after.reals[k]) != probe_bits(e->before.reals[k])) {
            return 1;
        }
    }
    return 0;
}

static void check_step_ok(fuzz_episode* e, double t, double h, double last, int terminate)
{
    const double end = t + h;
    if (!is_finite(t) || !is_finite(h) || !(h > 0)) {
        violation(e, "doStep(%g, %g) returned OK", t, h);
        return;
    }
    if (!is_finite(end) || !(end > t)) {
        /* an end time that overflows, or that rounds back to t */
        violation(e, "doStep(%.17g, %.17g) returned OK: t + h = %.17g is not a later finite time",
                  t, h, end);
        return;
    }
    if (probe_bits(last) != probe_bits(end) || terminate) {
        violation(e, "doStep(%.17g, %.17g) OK but last successful time %.17g, terminate %d", t, h,
                  last, terminate);
        return;
    }
    snapshot(e, &e->after);
    if (stopped(e)) {
        return;
    }
    /* on_singular = continue: an OK step without an answer, which the getter warns of */
    if (!e->after.valid ||
        (e->after.get_status != 0 && !(continues(e) && e->after.get_status == 1))) {
        violation(e, "doStep returned OK, the getter then %d", e->after.get_status);
        return;
    }
    e->counts->steps_continued += e->after.get_status == 1;
    if (!fmi2(e)) {
        const unsigned time_vr = 0;
        double time = NAN;
        const int status = (int)e->fmu->f3.GetFloat64(e->instance, &time_vr, 1, &time, 1);
        trace_double(e, time);
        if (status != 0 || probe_bits(time) != probe_bits(end)) {
            violation(e, "after doStep(%.17g, %.17g) OK, time reads %.17g (%d)", t, h, time,
                      status);
            return;
        }
    }
    if (!e->before.valid) {
        return;
    }
    if (!has_state(e->fmu)) {
        /* an algebraic model: the step size does not change the answer */
        compare_with_before(e, "an OK doStep of an algebraic model");
    } else if (state_must_move(e, h) && !states_moved(e)) {
        violation(e, "doStep(%.17g, %.17g) OK but no state moved (the first, %s, is %.17g)", t, h,
                  name_of(e, (size_t)e->fmu->first_state),
                  snapshot_real(e, &e->before, e->fmu->first_state));
    }
}

/* A discarded step of a model with states stopped at `last`, where the motion last
 * had an answer: its outputs are there (the states finite, as snapshot checks), FMI 3's
 * time reads `last`, and the next step starts there. */
static void check_step_stopped(fuzz_episode* e, double last)
{
    snapshot(e, &e->after);
    if (!fmi2(e) && !stopped(e)) {
        const unsigned time_vr = 0;
        double time = NAN;
        const int status = (int)e->fmu->f3.GetFloat64(e->instance, &time_vr, 1, &time, 1);
        trace_double(e, time);
        if (status != 0 || probe_bits(time) != probe_bits(last)) {
            violation(e, "after a discarded doStep stopped at %.17g s, time reads %.17g (%d)", last,
                      time, status);
        }
    }
    swap_snapshots(e);
    e->time = last;
}

/* A step of h seconds carried each input with a first derivative along it, as the FMU
 * computes it: value + h rate. */
static void move_inputs(fuzz_episode* e, double h)
{
    size_t k;
    for (k = 0; k < e->fmu->model.variable_count; ++k) {
        if (e->rates[k] != 0) {
            e->shadow[k] += h * e->rates[k];
        }
    }
}

/* A step that stopped within h seconds left each input with a first derivative between
 * its value at the start and h seconds on: read, checked and kept. */
static void inputs_moved_within(fuzz_episode* e, double h)
{
    size_t k;
    for (k = 0; k < e->fmu->model.variable_count; ++k) {
        const unsigned vr = e->fmu->model.variables[k].vr;
        const double from = e->shadow[k], to = from + h * e->rates[k];
        double now = NAN;
        if (e->rates[k] == 0) {
            continue;
        }
        if (call_get_real(e, &vr, 1, &now) != 0 || !(now >= fmin(from, to)) ||
            !(now <= fmax(from, to))) {
            violation(e, "%s reads %.17g after a step that stopped, not within [%.17g, %.17g]",
                      name_of(e, k), now, from, to);
            return;
        }
        e->shadow[k] = now;
    }
}

static void op_do_step(fuzz_episode* e)
{
    const double t = nasty_time(&e->rng, e->time);
    const double h = nasty_step(&e->rng);
    double last = NAN;
    int terminate = 0, status;
    long log_count;
    trace_double(e, t);
    trace_double(e, h);
    take_before(e);
    log_count = e->book.count;
    ++e->counts->steps;
    if (fmi2(e)) {
        status = (int)e->fmu->f2.DoStep(e->instance, t, h, fmi2True);
        if (status == 0 || status == 2) {
            fmi2_step_status(e, &last, &terminate);
        }
    } else {
        fmi3Boolean event = fmi3False, flag = fmi3False, early = fmi3False;
        status = (int)e->fmu->f3.DoStep(e->instance, t, h, fmi3True, &event, &flag, &early, &last);
        terminate = flag != fmi3False;
        if (event != fmi3False || early != fmi3False) {
            violation(e, "doStep asks for event handling or returned early");
        }
    }
    note(e, "doStep(%.17g, %.17g) -> %d (last %.17g, terminate %d)", t, h, status, last, terminate);
    trace(e, (uint64_t)status);
    trace_double(e, last);
    trace(e, (uint64_t)terminate);
    expect_message(e, status, log_count, "doStep");
    if (status == 0) {
        ++e->counts->steps_ok;
        move_inputs(e, h);
        check_step_ok(e, t, h, last, terminate);
        swap_snapshots(e);
        e->time = t + h;
        return;
    }
    if (status == 2) {
        ++e->counts->steps_discard;
        if (has_state(e->fmu) && last >= t && last < t + h && terminate) {
            inputs_moved_within(e, h);
            check_step_stopped(e, last);
            return;
        }
        if ((probe_bits(last) != probe_bits(t) || !terminate) && !stopped(e)) {
            violation(e, "doStep(%.17g, %.17g) discarded: last successful time %.17g, terminate %d",
                      t, h, last, terminate);
        }
    } else if (status == 3) {
        ++e->counts->steps_error;
    } else {
        violation(e, "doStep returned %d", status);
    }
    /* a step that is not OK takes the state nowhere and leaves every output */
    expect_unchanged(e, "a doStep that is not OK");
}

static void op_snapshot(fuzz_episode* e)
{
    snapshot(e, &e->before);
    note(e, "get all -> %d", e->before.get_status);
}

/* A call the state machine forbids now: Error with a message, nothing changed. */
static void op_illegal(fuzz_episode* e)
{
    const fuzz_fmu* f = e->fmu;
    const uint64_t pick = probe_rng_below(&e->rng, 6);
    long log_count;
    int status = 0;
    const char* call = "";
    take_before(e);
    log_count = e->book.count;
    if (pick == 0 && e->state != S_STEP) {
        call = "doStep";
        status = fmi2(e)
                     ? (int)f->f2.DoStep(e->instance, e->time, 1e-3, fmi2True)
                     : (int)f->f3.DoStep(e->instance, e->time, 1e-3, fmi3True, &(fmi3Boolean){0},
                                         &(fmi3Boolean){0}, &(fmi3Boolean){0}, &(fmi3Float64){0});
    } else if (pick == 1 && e->state != S_INITIALIZATION) {
        call = "exitInitializationMode";
        status = fmi2(e) ? (int)f->f2.ExitInitializationMode(e->instance)
                         : (int)f->f3.ExitInitializationMode(e->instance);
    } else if (pick == 2 && e->state != S_INSTANTIATED) {
        call = "enterInitializationMode";
        status = fmi2(e) ? (int)f->f2.EnterInitializationMode(e->instance)
                         : (int)f->f3.EnterInitializationMode(e->instance, fmi3False, 0, 0,
                                                              fmi3False, 0);
    } else if (pick == 3 && e->state != S_STEP) {
        call = "terminate";
        status = fmi2(e) ? (int)f->f2.Terminate(e->instance) : (int)f->f3.Terminate(e->instance);
    } else if (pick == 4 && e->state == S_INSTANTIATED && f->real_count > 0) {
        double value;
        call = "getReal in Instantiated";
        status = call_get_real(e, f->real_vrs, 1, &value);
    } else if (pick == 5 && fmi2(e) && e->state != S_INSTANTIATED) {
        call = "fmi2SetupExperiment";
        status = (int)f->f2.SetupExperiment(e->instance, fmi2False, 0, 0, fmi2False, 0);
    } else {
        return;
    }
    ++e->counts->illegal_calls;
    note(e, "illegal %s in %s -> %d", call, fuzz_state_names[e->state], status);
    trace(e, (uint64_t)status);
    if (status != 3) {
        violation(e, "%s in %s returned %d, not Error", call, fuzz_state_names[e->state], status);
        return;
    }
    expect_message(e, status, log_count, call);
    expect_unchanged(e, call);
}

static void op_enter_initialization(fuzz_episode* e)
{
    static const double starts[] = {0.0, 0.0, 0.0, -0.0, 1.5, -3.0, 1e9, 1e300};
    const double start = starts[probe_rng_below(&e->rng, sizeof starts / sizeof starts[0])];
    int a = 0, b;
    if (fmi2(e)) {
        a = (int)e->fmu->f2.SetupExperiment(e->instance, fmi2False, 0, start, fmi2False, 0);
        b = (int)e->fmu->f2.EnterInitializationMode(e->instance);
    } else {
        b = (int)e->fmu->f3.EnterInitializationMode(e->instance, fmi3False, 0, start, fmi3False, 0);
    }
    note(e, "enter initialization at %g -> %d %d", start, a, b);
    trace(e, (uint64_t)a);
    trace(e, (uint64_t)b);
    if (a != 0 || b != 0) {
        violation(e, "entering initialization from Instantiated: %d, %d", a, b);
        return;
    }
    e->state = S_INITIALIZATION;
    e->time = start;
    snapshot(e, &e->before);
}

static void op_exit_initialization(fuzz_episode* e)
{
    long log_count = e->book.count;
    const int status = fmi2(e) ? (int)e->fmu->f2.ExitInitializationMode(e->instance)
                               : (int)e->fmu->f3.ExitInitializationMode(e->instance);
    note(e, "exitInitializationMode -> %d", status);
    trace(e, (uint64_t)status);
    expect_message(e, status, log_count, "exitInitializationMode");
    if (status == 0 || status == 1) {
        e->state = S_STEP;
        snapshot(e, &e->before);
        if (e->before.valid && (e->before.get_status == 0) != (status == 0)) {
            violation(e, "exitInitializationMode returned %d, the getter then %d", status,
                      e->before.get_status);
        }
    } else if (status != 3) {
        violation(e, "exitInitializationMode returned %d", status);
    } else {
        /* refused inputs: still in Initialization Mode */
        e->before.valid = 0;
    }
}

static void load_start_values(fuzz_episode* e)
{
    size_t k;
    for (k = 0; k < e->fmu->model.variable_count; ++k) {
        const probe_variable* v = &e->fmu->model.variables[k];
        e->shadow[k] = v->has_start ? v->start : 0.0;
        e->rates[k] = 0.0;
    }
    e->state = S_INSTANTIATED;
    e->before.valid = 0;
}

static void op_terminate(fuzz_episode* e)
{
    const int status =
        fmi2(e) ? (int)e->fmu->f2.Terminate(e->instance) : (int)e->fmu->f3.Terminate(e->instance);
    note(e, "terminate -> %d", status);
    trace(e, (uint64_t)status);
    if (status != 0) {
        violation(e, "terminate in Step returned %d", status);
        return;
    }
    e->state = S_TERMINATED;
    take_before(e);
}

static void op_reset(fuzz_episode* e)
{
    const int status =
        fmi2(e) ? (int)e->fmu->f2.Reset(e->instance) : (int)e->fmu->f3.Reset(e->instance);
    note(e, "reset -> %d", status);
    trace(e, (uint64_t)status);
    if (status != 0) {
        violation(e, "reset in %s returned %d", fuzz_state_names[e->state], status);
        return;
    }
    load_start_values(e);
}

static void op_debug_logging(fuzz_episode* e)
{
    static const char* const categories[] = {"logStatusError", "logStatusWarning",
                                             "logStatusDiscard", "logCalls", "noSuchCategory"};
    const size_t pick = (size_t)probe_rng_below(&e->rng, 6);
    const int on = (int)probe_rng_below(&e->rng, 2);
    const char* one = pick < 5 ? categories[pick] : NULL;
    long log_count = e->book.count;
    int status;
    if (fmi2(e)) {
        status = (int)e->fmu->f2.SetDebugLogging(e->instance, on, one != NULL,
                                                 one != NULL ? &one : NULL);
    } else {
        status = (int)e->fmu->f3.SetDebugLogging(e->instance, on, one != NULL,
                                                 one != NULL ? &one : NULL);
    }
    note(e, "setDebugLogging(%d, %s) -> %d", on, one != NULL ? one : "all", status);
    trace(e, (uint64_t)status);
    if (status != (pick == 4 ? 3 : 0)) {
        violation(e, "setDebugLogging(%s) returned %d", one != NULL ? one : "all", status);
    }
    expect_message(e, status, log_count, "setDebugLogging");
}

static void* instantiate(fuzz_episode* e)
{
    static const char* const names[] = {"fuzz", "100% %s %n %p",
                                        "\xc3\xbcnic\xc3\xb8"
                                        "de",
                                        "a-name-of-sixty-four-characters-so-that-messages-must-"
                                        "be-clipped-at-the-end-of-their-buffer-........"};
    const char* name = names[probe_rng_below(&e->rng, sizeof names / sizeof names[0])];
    const int logging = (int)probe_rng_below(&e->rng, 2);
    ++e->counts->instances;
    if (fmi2(e)) {
        fmi2CallbackFunctions callbacks = probe_fmi2_callbacks(&e->book);
        return e->fmu->f2.Instantiate(name, fmi2CoSimulation, e->fmu->model.token, "", &callbacks,
                                      fmi2False, logging);
    }
    return e->fmu->f3.InstantiateCoSimulation(name, e->fmu->model.token, NULL, fmi3False, logging,
                                              fmi3False, fmi3False, NULL, 0, &e->book,
                                              probe_fmi3_logger, NULL);
}

static void free_instance(fuzz_episode* e)
{
    if (fmi2(e)) {
        e->fmu->f2.FreeInstance(e->instance);
    } else {
        e->fmu->f3.FreeInstance(e->instance);
    }
    e->instance = NULL;
}

/* One call chosen at random among those that make sense in the current state,
 * with now and then one that does not. */
static void one_call(fuzz_episode* e)
{
    const uint64_t pick = probe_rng_below(&e->rng, 100);
    switch (e->state) {
    case S_INSTANTIATED:
        if (pick < 45) {
            op_set_real(e);
        } else if (pick < 50) {
            op_set_integer(e);
        } else if (pick < 55) {
            op_illegal(e);
        } else if (pick < 60) {
            op_debug_logging(e);
        } else if (pick < 65) {
            op_set_plausible(e);
        } else {
            op_enter_initialization(e);
        }
        break;
    case S_INITIALIZATION:
        if (pick < 40) {
            op_set_real(e);
        } else if (pick < 45) {
            op_set_plausible(e);
        } else if (pick < 55) {
            op_snapshot(e);
        } else if (pick < 60) {
            op_illegal(e);
        } else {
            op_exit_initialization(e);
        }
        break;
    case S_STEP:
        if (pick < 30) {
            op_set_real(e);
        } else if (pick < 33) {
            op_set_integer(e);
        } else if (pick < 39) {
            op_set_plausible(e);
        } else if (pick < 46) {
            op_set_inputs(e);
        } else if (pick < 48) {
            op_get_outputs(e);
        } else if (pick < 50) {
            op_rates(e);
        } else if (pick < 84) {
            op_do_step(e);
        } else if (pick < 90) {
            op_snapshot(e);
        } else if (pick < 94) {
            op_illegal(e);
        } else if (pick < 96) {
            op_debug_logging(e);
        } else if (pick < 98) {
            op_reset(e);
        } else {
            op_terminate(e);
        }
        break;
    case S_TERMINATED:
        if (pick < 30) {
            op_snapshot(e);
        } else if (pick < 50) {
            op_illegal(e);
        } else if (pick < 60) {
            op_set_real(e);
        } else if (pick < 80) {
            op_reset(e);
        } else {
            e->step_quota = 0; /* end of the episode */
        }
        break;
    }
}

/* Runs one episode on a fresh instance; returns its trace hash. */
static uint64_t run_episode(fuzz_episode* e, uint64_t seed)
{
    const fuzz_fmu* f = e->fmu;
    const long steps_at_start = e->counts->steps;
    probe_rng_seed(&e->rng, seed);
    probe_log_book_clear(&e->book);
    e->trace = PROBE_HASH_START;
    e->failed = 0;
    e->last_n = 0;
    e->call = 0;
    e->step_quota = 1 + (long)probe_rng_below(&e->rng, 200);
    e->time = 0;
    e->instance = instantiate(e);
    if (e->instance == NULL) {
        violation(e, "instantiation failed: %s", e->book.last);
        return e->trace;
    }
    load_start_values(e);
    while (!stopped(e) && e->counts->steps - steps_at_start < e->step_quota) {
        ++e->call;
        one_call(e);
        (void)f;
    }
    free_instance(e);
    return probe_hash_u64(e->trace, e->book.hash);
}

/* ---- the run -------------------------------------------------------------------------------- */

typedef struct fuzz_options {
    long steps;
    uint64_t seed;
    int verbose, replay;
    uint64_t replay_seed;
    const char* directory;
} fuzz_options;

static int alloc_snapshot(fuzz_snapshot* s, const fuzz_fmu* f)
{
    s->valid = 0;
    s->reals = (double*)calloc(f->real_count + 1, sizeof *s->reals);
    s->integers = (int*)calloc(f->integer_count + 1, sizeof *s->integers);
    return s->reals != NULL && s->integers != NULL;
}

static uint64_t episode_seed(uint64_t master, const fuzz_fmu* f, long episode)
{
    uint64_t state = probe_hash_string(probe_hash_u64(master, (uint64_t)f->model.fmi_version),
                                       f->model.identifier) ^
                     (uint64_t)episode * 0x9E3779B97F4A7C15ULL;
    return probe_splitmix64(&state);
}

/* Runs an episode and its replay; 0 if both ran through and agree. */
static int episode_and_replay(fuzz_episode* e, uint64_t seed, const char* directory)
{
    const fuzz_fmu* f = e->fmu;
    uint64_t first, second;
    ++e->counts->episodes;
    first = run_episode(e, seed);
    if (e->failed) {
        printf("FAIL %s fmi%d: episode seed 0x%016" PRIx64 ", call %ld: %s\n"
               "     replay: fmu_fuzz --replay 0x%016" PRIx64 " --verbose %s\n",
               f->model.identifier, f->model.fmi_version, seed, e->call, e->failure, seed,
               directory);
        return 1;
    }
    if (e->verbose) {
        printf("  -- replay on a fresh instance\n");
    }
    e->verbose = 0; /* the replay prints nothing new */
    second = run_episode(e, seed);
    ++e->counts->replays;
    if (first != second || e->failed) {
        printf("FAIL %s fmi%d: episode seed 0x%016" PRIx64 " replayed on a fresh instance "
               "differs (trace %016" PRIx64 " then %016" PRIx64 ")%s%s\n"
               "     replay: fmu_fuzz --replay 0x%016" PRIx64 " --verbose %s\n",
               f->model.identifier, f->model.fmi_version, seed, first, second,
               e->failed ? ": " : "", e->failed ? e->failure : "", seed, directory);
        return 1;
    }
    return 0;
}

/* A whole number of option `name` from `text`: decimal digits (with `hex`, also 0x and
 * hex digits) and nothing else, from `low` to `high`; else 0 after a message naming the
 * option and the text. */
static int parse_count(const char* name, const char* text, int hex, unsigned long long low,
                       unsigned long long high, unsigned long long* value)
{
    char* end = NULL;
    int digits = hex && (text[0] == '0') && (text[1] == 'x' || text[1] == 'X');
    errno = 0;
    if (isdigit((unsigned char)text[0])) {
        *value = strtoull(text, &end, digits ? 16 : 10);
    }
    if (end == NULL || *end != '\0' || errno == ERANGE || *value < low || *value > high) {
        fprintf(stderr, "fmu_fuzz: %s must be a whole number from %llu to %llu%s, not '%s'\n", name,
                low, high, hex ? " (decimal or 0x hex)" : "", text);
        return 0;
    }
    return 1;
}

/* The options; 0 after a message if one is bad or the FMU directory is missing. */
static int parse_options(int argc, char** argv, fuzz_options* o)
{
    int a, ok = 1;
    unsigned long long steps = 20000, seed = 1, replay_seed = 0;
    memset(o, 0, sizeof *o);
    for (a = 1; a < argc && ok; ++a) {
        const char* value = a + 1 < argc ? argv[a + 1] : NULL;
        int takes = strcmp(argv[a], "--steps") == 0 || strcmp(argv[a], "--seed") == 0 ||
                    strcmp(argv[a], "--replay") == 0;
        if (takes && value == NULL) {
            fprintf(stderr, "fmu_fuzz: %s needs a value\n", argv[a]);
            ok = 0;
        } else if (strcmp(argv[a], "--steps") == 0) {
            ok = parse_count("--steps", argv[++a], 0, 1, LONG_MAX, &steps);
        } else if (strcmp(argv[a], "--seed") == 0) {
            ok = parse_count("--seed", argv[++a], 1, 0, UINT64_MAX, &seed);
        } else if (strcmp(argv[a], "--replay") == 0) {
            o->replay = 1;
            ok = parse_count("--replay", argv[++a], 1, 0, UINT64_MAX, &replay_seed);
        } else if (strcmp(argv[a], "--verbose") == 0) {
            o->verbose = 1;
        } else if (argv[a][0] != '-' && o->directory == NULL) {
            o->directory = argv[a];
        } else {
            fprintf(stderr, "fmu_fuzz: unknown argument '%s'\n", argv[a]);
            ok = 0;
        }
    }
    o->steps = (long)steps;
    o->seed = (uint64_t)seed;
    o->replay_seed = (uint64_t)replay_seed;
    return ok && o->directory != NULL;
}

int main(int argc, char** argv)
{
    fuzz_options options;
    fuzz_fmu fmu;
    fuzz_episode e;
    fuzz_counts counts;
    long episode;
    int failed = 0;
    struct timespec started, ended;
    if (argc == 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("usage: fmu_fuzz [--steps N] [--seed S] [--replay SEED] [--verbose] FMU_DIR\n"
               "Drives the FMU unpacked in FMU_DIR with random FMI calls, values and states "
               "for N steps (seeded; --replay runs one episode again) and checks every answer; "
               "exits non-zero on the first failure. scripts/run-fuzz runs it on every FMU.\n");
        return 0;
    }
    if (!parse_options(argc, argv, &options)) {
        printf("usage: fmu_fuzz [--steps N] [--seed S] [--replay SEED] [--verbose] FMU_DIR\n");
        return 2;
    }
    if (!fuzz_prepare(&fmu, options.directory)) {
        return 1;
    }
    memset(&e, 0, sizeof e);
    memset(&counts, 0, sizeof counts);
    e.fmu = &fmu;
    e.counts = &counts;
    e.shadow = (double*)calloc(fmu.model.variable_count + 1, sizeof *e.shadow);
    e.rates = (double*)calloc(fmu.model.variable_count + 1, sizeof *e.rates);
    if (e.shadow == NULL || !alloc_snapshot(&e.before, &fmu) || !alloc_snapshot(&e.after, &fmu)) {
        printf("out of memory\n");
        return 1;
    }
    clock_gettime(CLOCK_MONOTONIC, &started);
    if (options.replay) {
        e.verbose = 1;
        printf("replaying episode 0x%016" PRIx64 " of %s fmi%d\n", options.replay_seed,
               fmu.model.identifier, fmu.model.fmi_version);
        failed = episode_and_replay(&e, options.replay_seed, options.directory);
    } else {
        for (episode = 0; counts.steps < options.steps && !failed; ++episode) {
            e.verbose = 0;
            failed = episode_and_replay(&e, episode_seed(options.seed, &fmu, episode),
                                        options.directory);
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &ended);
    printf("fuzz %s fmi%d: %ld steps (%ld ok, of them %ld continued without an answer, %ld "
           "discarded, %ld refused), %ld sets (%ld refused), %ld reads, %ld illegal calls, %ld "
           "episodes on %ld instances, %ld replays identical; %.1f s\n",
           fmu.model.identifier, fmu.model.fmi_version, counts.steps, counts.steps_ok,
           counts.steps_continued, counts.steps_discard, counts.steps_error, counts.sets,
           counts.sets_rejected, counts.gets, counts.illegal_calls, counts.episodes,
           counts.instances, counts.replays,
           (double)(ended.tv_sec - started.tv_sec) +
               1e-9 * (double)(ended.tv_nsec - started.tv_nsec));
    free(e.shadow);
    free(e.rates);
    free(e.before.reals);
    free(e.before.integers);
    free(e.after.reals);
    free(e.after.integers);
    fuzz_release(&fmu);
    return failed ? 1 : 0;
}
