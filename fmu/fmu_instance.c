/* dyadfmu FMU layer: the version-neutral instance (see fmu_instance.h). */
#include "fmu_instance.h"

#include "dyadfmu/angle.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

enum {
    ALL_STATES = FMU_STATE_INSTANTIATED | FMU_STATE_INITIALIZATION | FMU_STATE_STEP |
    FMU_STATE_TERMINATED
};

/* Where each operation may be called. One table instead of a test per entry point. */
static const unsigned legal_states[FMU_OP_COUNT] = {
    [FMU_OP_SETUP_EXPERIMENT] = FMU_STATE_INSTANTIATED,
    [FMU_OP_ENTER_INITIALIZATION] = FMU_STATE_INSTANTIATED,
    [FMU_OP_EXIT_INITIALIZATION] = FMU_STATE_INITIALIZATION,
    [FMU_OP_DO_STEP] = FMU_STATE_STEP,
    [FMU_OP_TERMINATE] = FMU_STATE_STEP,
    [FMU_OP_RESET] = ALL_STATES,
    [FMU_OP_GET] = FMU_STATE_INITIALIZATION | FMU_STATE_STEP | FMU_STATE_TERMINATED,
    [FMU_OP_SET] = FMU_STATE_INSTANTIATED | FMU_STATE_INITIALIZATION | FMU_STATE_STEP,
    [FMU_OP_STEP_STATUS] = FMU_STATE_STEP | FMU_STATE_TERMINATED,
    [FMU_OP_DEBUG_LOGGING] = ALL_STATES,
    [FMU_OP_UNSUPPORTED] = ALL_STATES,
    [FMU_OP_STATE] = ALL_STATES,
};

/* Parameters (fixed) may change only while these hold. */
enum { PARAMETER_STATES = FMU_STATE_INSTANTIATED | FMU_STATE_INITIALIZATION };

const char* const fmu_log_category_names[] = {"logStatusError", "logStatusWarning",
                                              "logStatusDiscard", "logCalls"};
const size_t fmu_log_category_count =
    sizeof fmu_log_category_names / sizeof fmu_log_category_names[0];
enum { LOG_ERROR = 0, LOG_WARNING, LOG_DISCARD, LOG_CALLS };

/* Which operations may take their common path, worked out whenever the state or the
 * logged categories change so that each call tests one bit: legal now, and not a call
 * to log; a set only once the parameters are closed (before, it restarts the states);
 * a step only of a model without states. */
static void find_common_paths(fmu_instance* instance)
{
    const unsigned state = (unsigned)instance->state;
    unsigned paths = 0;
    if (!(instance->log_categories & (1u << LOG_CALLS))) {
        if (legal_states[FMU_OP_GET] & state) {
            paths |= 1u << FMU_OP_GET;
        }
        if ((legal_states[FMU_OP_SET] & state) && !(state & PARAMETER_STATES)) {
            paths |= 1u << FMU_OP_SET;
        }
        if ((legal_states[FMU_OP_DO_STEP] & state) && instance->model->behaviour->advance == NULL) {
            paths |= 1u << FMU_OP_DO_STEP;
        }
    }
    instance->common_paths = paths;
}

/* Moves the state machine to `state`. */
static void enter_state(fmu_instance* instance, fmu_state state)
{
    instance->state = state;
    find_common_paths(instance);
}

static const char* state_name(fmu_state state)
{
    switch (state) {
    case FMU_STATE_INSTANTIATED: return "Instantiated";
    case FMU_STATE_INITIALIZATION: return "Initialization Mode";
    case FMU_STATE_STEP: return "Step Mode";
    case FMU_STATE_TERMINATED: return "Terminated";
    }
    return "?";
}

static void emit(const fmu_logger* logger, unsigned categories, fmu_status status,
                 const char* format, va_list args)
{
    char message[512];
    int category;
    if (logger->sink == NULL) {
        return;
    }
    switch (status) {
    case FMU_OK: category = LOG_CALLS; break;
    case FMU_WARNING: category = LOG_WARNING; break;
    case FMU_DISCARD: category = LOG_DISCARD; break;
    default: category = LOG_ERROR; break;
    }
    if (status == FMU_OK && !(categories & (1u << LOG_CALLS))) {
        return;
    }
    vsnprintf(message, sizeof message, format, args);
    logger->sink(logger, status, fmu_log_category_names[category], message);
}

void fmu_log(const fmu_instance* instance, fmu_status status, const char* format, ...)
{
    va_list args;
    /* the common case, a call logged in no category: nothing to format */
    if (status == FMU_OK && !(instance->log_categories & (1u << LOG_CALLS))) {
        return;
    }
    va_start(args, format);
    emit(&instance->logger, instance->log_categories, status, format, args);
    va_end(args);
}

/* Logging before an instance exists. */
static void log_to(const fmu_logger* logger, fmu_status status, const char* format, ...)
    FMU_PRINTF_FORMAT(3, 4);
static void log_to(const fmu_logger* logger, fmu_status status, const char* format, ...)
{
    va_list args;
    va_start(args, format);
    emit(logger, 0, status, format, args);
    va_end(args);
}

/* Where the value of a parameter or input is kept: in the input block if the
 * model reads it as it is, else as set (an angle, whose unit vector the model
 * reads). */
static double* kept_value(fmu_instance* instance, size_t index)
{
    const fmu_variable* v = &instance->model->variables[index];
    if (v->target == FMU_TARGET_INPUT_REAL) {
        return (double*)(void*)((char*)instance->input + v->offset);
    }
    return &instance->values[index];
}

/* Stores a value as set and where the model reads it, so that a solve needs no
 * pass over the variables. An angle's unit vector is brought up to date by
 * sync_angles, once per change and only before the model reads it. */
static void store(fmu_instance* instance, size_t index, double value)
{
    *kept_value(instance, index) = value;
}

double* fmu_kept_value(fmu_instance* instance, size_t index)
{
    return kept_value(instance, index);
}

/* The (cos, sin) of every angle that changed since the model last read them, two at
 * a time (both again where one of the two changed: as cheap as one alone). It runs
 * only before an evaluation, so comparing each angle costs less than a flag kept up
 * to date by every set. */
FMU_INLINE void sync_angles(fmu_instance* instance)
{
    fmu_angle* a = instance->angles;
    fmu_angle* const end = a + instance->angle_count;
    for (; end - a >= 2; a += 2) {
        if (*a[0].angle != a[0].converted || *a[1].angle != a[1].converted) {
            a[0].converted = *a[0].angle;
            a[1].converted = *a[1].angle;
            dyad_cos_sin_pair(a[0].converted, a[1].converted, a[0].unit, a[1].unit);
        }
    }
    if (a < end && *a->angle != a->converted) {
        a->converted = *a->angle;
        dyad_cos_sin(a->converted, &a->unit[0], &a->unit[1]);
    }
}

/* Sizes rounded up so that every block is aligned for any scalar. */
static size_t round_up(size_t size)
{
    const size_t unit = 16;
    return (size + unit - 1) / unit * unit;
}

static void build_slots(fmu_instance* instance);
static void choose_evaluation(fmu_instance* instance);

static void load_start_values(fmu_instance* instance)
{
    size_t k;
    instance->model->behaviour->initialise(instance->model, instance->input);
    for (k = 0; k < instance->angle_count; ++k) {
        instance->angles[k].converted = NAN; /* initialise overwrote every unit vector */
    }
    for (k = 0; k < instance->model->variable_count; ++k) {
        store(instance, k, instance->model->variables[k].start);
    }
    sync_angles(instance);
    if (instance->model->behaviour->start != NULL) {
        instance->model->behaviour->start(instance->model, instance->input);
    }
    enter_state(instance, FMU_STATE_INSTANTIATED);
    build_slots(instance);
    instance->time = 0;
    instance->last_successful_time = 0;
    instance->stop_limit = (double)INFINITY;
    instance->terminate_requested = 0;
    instance->dirty = 1;
}

/* The interval a set value must lie in: its bounds, within the finite doubles. */
static void accepted_range(const fmu_variable* v, fmu_slot* slot)
{
    slot->low = -DBL_MAX;
    slot->high = DBL_MAX;
    if (v->bounds & FMU_HAS_MIN) {
        const double min = (v->bounds & FMU_MIN_EXCLUSIVE) ? nextafter(v->min, INFINITY) : v->min;
        slot->low = min > slot->low ? min : slot->low;
    }
    if (v->bounds & FMU_HAS_MAX) {
        const double max = (v->bounds & FMU_MAX_EXCLUSIVE) ? nextafter(v->max, -INFINITY) : v->max;
        slot->high = max < slot->high ? max : slot->high;
    }
}

/* Whether `vr` is an output of the model's fmu_later. */
static int is_later(const fmu_model* model, unsigned int vr)
{
    const fmu_later* later = model->behaviour->later;
    size_t k;
    for (k = 0; later != NULL && k < later->count; ++k) {
        if (later->vrs[k] == vr) {
            return 1;
        }
    }
    return 0;
}

static void build_slot(fmu_instance* instance, unsigned int vr, fmu_slot* slot)
{
    const fmu_model* model = instance->model;
    const int index = model->index_of_vr[vr];
    const fmu_variable* v = index >= 0 ? &model->variables[index] : NULL;
    slot->low = 1; /* empty: no set is accepted at once */
    slot->high = 0;
    slot->write = NULL;
    slot->read = NULL;
    slot->is_output = 0;
    slot->later = 0;
    if (v == NULL) {
        slot->read = vr == 0 && instance->time_at_vr_0 ? &instance->time : NULL;
    } else if (v->causality == FMU_OUTPUT) {
        slot->is_output = 1;
        slot->later = is_later(model, vr);
        if (v->target == FMU_TARGET_RESULT_REAL) {
            slot->read = (const double*)(const void*)((const char*)instance->output + v->offset);
        }
    } else if (v->type == FMU_REAL) {
        slot->write = kept_value(instance, (size_t)index);
        slot->read = slot->write;
        if (v->causality == FMU_INPUT || ((unsigned)instance->state & PARAMETER_STATES)) {
            accepted_range(v, slot);
        }
    }
}

/* The slots for the current state: a parameter is settable only before
 * initialization ends. */
static void build_slots(fmu_instance* instance)
{
    const fmu_model* model = instance->model;
    unsigned int vr;
    for (vr = 0; vr < model->vr_limit; ++vr) {
        build_slot(instance, vr, &instance->slots[vr]);
    }
    instance->set_plan.count = FMU_NO_PLAN; /* the accepted intervals changed */
    instance->get_plan.count = FMU_NO_PLAN;
    instance->get_plan.later = 0;
    choose_evaluation(instance);
}

void fmu_restored(fmu_instance* instance, fmu_state state)
{
    size_t k;
    for (k = 0; k < instance->angle_count; ++k) {
        instance->angles[k].converted = NAN;
    }
    instance->evaluation.status = FMU_OK;
    instance->evaluation.bad_variable = -1;
    instance->evaluation.reason[0] = '\0';
    instance->dirty = 1;
    enter_state(instance, state);
    build_slots(instance);
}

/* The angle variables, and the settings the layer reads (kept as set). */
static void find_places(fmu_instance* instance)
{
    const fmu_model* model = instance->model;
    size_t k;
    instance->angle_count = 0;
    instance->on_singular = NULL;
    for (k = 0; k < model->variable_count; ++k) {
        const fmu_variable* v = &model->variables[k];
        if (v->target == FMU_TARGET_INPUT_ANGLE) {
            fmu_angle* a = &instance->angles[instance->angle_count++];
            a->angle = &instance->values[k];
            a->unit = (double*)(void*)((char*)instance->input + v->offset);
            a->converted = NAN;
        } else if (v->target == FMU_TARGET_SETTING && v->offset == FMU_SETTING_ON_SINGULAR) {
            instance->on_singular = &instance->values[k];
        }
    }
}

/* A plan's arrays for up to `capacity` values, aligned. */
static size_t plan_size(size_t capacity)
{
    return 2 * round_up(capacity * sizeof(unsigned int)) + 2 * round_up(capacity * sizeof(double)) +
           2 * round_up(capacity * sizeof(double*));
}

static void place_plan(fmu_plan* plan, char* at, size_t capacity)
{
    plan->count = FMU_NO_PLAN;
    plan->bounded_count = 0;
    plan->store = NULL;
    plan->load = NULL;
    plan->vr = (unsigned int*)(void*)at;
    at += round_up(capacity * sizeof(unsigned int));
    plan->position = (unsigned int*)(void*)at;
    at += round_up(capacity * sizeof(unsigned int));
    plan->low = (double*)(void*)at;
    at += round_up(capacity * sizeof(double));
    plan->high = (double*)(void*)at;
    at += round_up(capacity * sizeof(double));
    plan->write = (double**)(void*)at;
    at += round_up(capacity * sizeof(double*));
    plan->read = (const double**)(void*)at;
}

/* The instance and everything it owns in one block: its parts, aligned. */
typedef struct instance_layout {
    size_t values, slots, plans, angles, input, output, name, total;
} instance_layout;

static instance_layout layout_of(const fmu_model* model, const char* instance_name)
{
    instance_layout at;
    const size_t variables = model->variable_count;
    at.values = round_up(sizeof(fmu_instance));
    at.slots = at.values + round_up(variables * sizeof(double));
    at.plans = at.slots + round_up(model->vr_limit * sizeof(fmu_slot));
    at.angles = at.plans + 2 * plan_size(model->vr_limit);
    at.input = at.angles + round_up(variables * sizeof(fmu_angle));
    at.output = at.input + 2 * round_up(model->behaviour->input_size);
    at.name = at.output + 3 * round_up(model->behaviour->output_size);
    at.total = at.name + strlen(instance_name) + 1;
    return at;
}

static void place_parts(fmu_instance* instance, const instance_layout* at, const char* name)
{
    char* base = (char*)instance;
    const size_t input_size = round_up(instance->model->behaviour->input_size);
    const size_t output_size = round_up(instance->model->behaviour->output_size);
    instance->values = (double*)(void*)(base + at->values);
    instance->slots = (fmu_slot*)(void*)(base + at->slots);
    place_plan(&instance->set_plan, base + at->plans, instance->model->vr_limit);
    place_plan(&instance->get_plan, base + at->plans + plan_size(instance->model->vr_limit),
               instance->model->vr_limit);
    instance->angles = (fmu_angle*)(void*)(base + at->angles);
    instance->input = base + at->input;
    instance->seed = base + at->input + input_size;
    instance->output = base + at->output;
    instance->value = base + at->output + output_size;
    instance->rate = base + at->output + 2 * output_size;
    memcpy(base + at->name, name, at->total - at->name);
    instance->logger.instance_name = base + at->name;
}

fmu_instance* fmu_instantiate(const fmu_model* model, const char* instance_name, const char* token,
                              fmu_logger logger, int logging_on, fmu_allocate allocate,
                              fmu_release release, int time_at_vr_0)
{
    fmu_instance* instance;
    instance_layout at;

    logger.instance_name = instance_name != NULL ? instance_name : "";
    if (instance_name == NULL || instance_name[0] == '\0') {
        log_to(&logger, FMU_ERROR, "instantiate: the instance name must not be empty");
        return NULL;
    }
    if (token == NULL || strcmp(token, model->token) != 0) {
        log_to(&logger, FMU_ERROR,
               "instantiate: instantiation token '%s' does not match this FMU's '%s' (%s); "
               "was the model description taken from another FMU?",
               token != NULL ? token : "(null)", model->token, model->identifier);
        return NULL;
    }
    if (allocate == NULL || release == NULL) {
        allocate = calloc;
        release = free;
    }
    at = layout_of(model, instance_name);
    instance = (fmu_instance*)allocate(1, at.total);
    if (instance == NULL) {
        log_to(&logger, FMU_ERROR, "instantiate: out of memory");
        return NULL;
    }
    instance->model = model;
    instance->logger = logger;
    place_parts(instance, &at, instance_name);
    instance->allocate = allocate;
    instance->release = release;
    instance->saved = NULL;
    instance->log_categories = logging_on ? ~0u : 0u;
    instance->time_at_vr_0 = time_at_vr_0;
    find_places(instance);
    load_start_values(instance);
    fmu_log(instance, FMU_OK, "instantiated %s", model->identifier);
    return instance;
}

void fmu_free(fmu_instance* instance)
{
    if (instance != NULL) {
        fmu_free_states(instance);
        instance->release(instance);
    }
}

/* Whether a call may take its common path (find_common_paths). */
static int quiet_call(const fmu_instance* instance, fmu_operation operation)
{
    return (instance->common_paths >> operation) & 1u;
}

fmu_status fmu_check_call(fmu_instance* instance, fmu_operation operation, const char* function)
{
    if (instance == NULL) {
        return FMU_ERROR;
    }
    if (!(legal_states[operation] & (unsigned)instance->state)) {
        fmu_log(instance, FMU_ERROR, "%s: illegal call sequence: not allowed in %s", function,
                state_name(instance->state));
        return FMU_ERROR;
    }
    if (instance->log_categories & (1u << LOG_CALLS)) {
        fmu_log(instance, FMU_OK, "%s", function);
    }
    return FMU_OK;
}

fmu_status fmu_set_debug_logging(fmu_instance* instance, int logging_on, size_t count,
                                 const char* const categories[])
{
    unsigned bits = 0;
    size_t k, c;
    fmu_status status = fmu_check_call(instance, FMU_OP_DEBUG_LOGGING, "setDebugLogging");
    if (status != FMU_OK) {
        return status;
    }
    if (count > 0 && categories == NULL) {
        fmu_log(instance, FMU_ERROR, "setDebugLogging: %zu categories but a NULL array", count);
        return FMU_ERROR;
    }
    for (k = 0; k < count; ++k) {
        for (c = 0; c < fmu_log_category_count; ++c) {
            if (categories[k] != NULL && strcmp(categories[k], fmu_log_category_names[c]) == 0) {
                break;
            }
        }
        if (c == fmu_log_category_count) {
            fmu_log(instance, FMU_ERROR, "setDebugLogging: unknown log category '%s'",
                    categories[k] != NULL ? categories[k] : "(null)");
            return FMU_ERROR;
        }
        bits |= 1u << c;
    }
    if (count == 0) {
        bits = ~0u;
    }
    instance->log_categories =
        logging_on ? (instance->log_categories | bits) : (instance->log_categories & ~bits);
    find_common_paths(instance);
    return FMU_OK;
}

/* Refuses, naming it, a start or stop time that no step could follow: not finite,
 * or a stop before the start. */
static fmu_status check_experiment(fmu_instance* instance, const fmu_experiment* x,
                                   const char* function)
{
    if (!isfinite(x->start_time) || (x->stop_defined && !isfinite(x->stop_time))) {
        fmu_log(instance, FMU_ERROR, "%s: startTime = %g s, stopTime = %g s: both must be finite",
                function, x->start_time, x->stop_defined ? x->stop_time : (double)INFINITY);
        return FMU_ERROR;
    }
    if (x->stop_defined && x->stop_time < x->start_time) {
        fmu_log(instance, FMU_ERROR, "%s: stopTime = %.17g s is before startTime = %.17g s",
                function, x->stop_time, x->start_time);
        return FMU_ERROR;
    }
    return FMU_OK;
}

/* The experiment's start as the time reached, and its stop as the limit of a step's
 * end: the stop time, with room for the rounding of a sum of steps that reaches it
 * (an importer's last step ends within 1e-9 of it, relatively, as fmpy's does). */
static void start_experiment(fmu_instance* instance, const fmu_experiment* x)
{
    instance->time = x->start_time;
    instance->last_successful_time = x->start_time;
    instance->stop_limit = x->stop_defined
                               ? x->stop_time + 1e-9 * fmax(fabs(x->start_time), fabs(x->stop_time))
                               : (double)INFINITY;
}

fmu_status fmu_setup_experiment(fmu_instance* instance, const fmu_experiment* experiment)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_SETUP_EXPERIMENT, "setupExperiment");
    if (status == FMU_OK) {
        status = check_experiment(instance, experiment, "setupExperiment");
    }
    if (status == FMU_OK) {
        start_experiment(instance, experiment);
    }
    return status;
}

/* ---- the solve ------------------------------------------------------------------------------ */

/* Logs why the last evaluation failed. */
FMU_COLD static void log_failure(fmu_instance* instance, fmu_status not_solvable,
                                 const char* function)
{
    const fmu_evaluation* e = &instance->evaluation;
    if (e->status == FMU_ERROR && e->bad_variable >= 0) {
        fmu_log(instance, FMU_ERROR, "%s: %s = %g: %s", function,
                instance->model->variables[e->bad_variable].name,
                *kept_value(instance, (size_t)e->bad_variable), e->reason);
    } else if (e->status != FMU_OK) {
        fmu_log(instance, e->status == FMU_ERROR ? FMU_ERROR : not_solvable, "%s: at t = %g s: %s",
                function, instance->time, e->reason);
    }
}

/* The evaluation a step makes for what the importer reads: every output; but where the
 * model can leave some to their first read (fmu_later) and the importer's get did not
 * read any of them (an importer repeats its gets), the others alone. Chosen anew with
 * each new get plan. */
static void choose_evaluation(fmu_instance* instance)
{
    const fmu_behaviour* behaviour = instance->model->behaviour;
    instance->leaves_later = behaviour->later != NULL && !instance->get_plan.later;
    instance->evaluate_now = instance->leaves_later ? behaviour->later->first : behaviour->evaluate;
}

FMU_INLINE void evaluate_for_reads(fmu_instance* instance)
{
    instance->evaluate_now(instance->model, instance->input, instance->output,
                           &instance->evaluation);
    instance->later_pending = instance->leaves_later;
}

/* Evaluates if an input changed since the last evaluation. Returns FMU_OK,
 * FMU_ERROR for inputs the model rejects, or `not_solvable` where the model has
 * no answer (a singular dyad). A failure is logged when it is found; an Error
 * is logged again by every call that returns it (`each_error`), since a call
 * that returns Error must say why, while a getter that reports a failure in
 * its status alone (fmi*GetInteger of `status`) passes 0. */
static fmu_status solve(fmu_instance* instance, fmu_status not_solvable, const char* function,
                        int each_error)
{
    fmu_evaluation* e = &instance->evaluation;
    if (instance->dirty) {
        sync_angles(instance);
        evaluate_for_reads(instance);
        instance->dirty = 0;
        if (e->status != FMU_OK) {
            log_failure(instance, not_solvable, function);
        }
    } else if (e->status == FMU_ERROR && each_error) {
        log_failure(instance, not_solvable, function);
    }
    if (e->status == FMU_OK || e->status == FMU_ERROR) {
        return e->status;
    }
    return not_solvable;
}

/* ---- the state machine ---------------------------------------------------------------------- */

fmu_status fmu_enter_initialization(fmu_instance* instance, const fmu_experiment* experiment)
{
    fmu_status status =
        fmu_check_call(instance, FMU_OP_ENTER_INITIALIZATION, "enterInitializationMode");
    if (status == FMU_OK && experiment != NULL) {
        status = check_experiment(instance, experiment, "enterInitializationMode");
    }
    if (status == FMU_OK) {
        enter_state(instance, FMU_STATE_INITIALIZATION);
        if (experiment != NULL) {
            start_experiment(instance, experiment);
        }
    }
    return status;
}

fmu_status fmu_exit_initialization(fmu_instance* instance)
{
    fmu_status status =
        fmu_check_call(instance, FMU_OP_EXIT_INITIALIZATION, "exitInitializationMode");
    if (status != FMU_OK) {
        return status;
    }
    status = solve(instance, FMU_WARNING, "exitInitializationMode", 1);
    if (status != FMU_ERROR) {
        enter_state(instance, FMU_STATE_STEP);
        build_slots(instance); /* the parameters close */
    }
    return status;
}

/* Whether a step may be taken: a positive size and a later finite end, not past the
 * stop. A sum that overflows would leave the instance at an infinite time, one below
 * the resolution of double at current_time would advance the states but not the
 * time. */
static int step_is_valid(const fmu_instance* instance, double current_time, double step_size)
{
    /* x - x is 0 for a finite x: both ends finite, and the end later (so the size is
     * positive, finite, and above the resolution of double at current_time) */
    const double end = current_time + step_size;
    return (end - end) + (current_time - current_time) == 0 && end > current_time &&
           end <= instance->stop_limit;
}

/* Refuses, with the reason, a step that step_is_valid does not take. */
FMU_COLD static fmu_status check_step(fmu_instance* instance, double current_time, double step_size,
                                      const char* function)
{
    if (!isfinite(current_time) || !isfinite(step_size) || !(step_size > 0)) {
        fmu_log(instance, FMU_ERROR,
                "%s: currentCommunicationPoint = %g s and communicationStepSize = %g s: the "
                "step size must be positive and both finite",
                function, current_time, step_size);
        return FMU_ERROR;
    }
    if (!(current_time + step_size > current_time) || !isfinite(current_time + step_size)) {
        fmu_log(instance, FMU_ERROR,
                "%s: currentCommunicationPoint = %.17g s + communicationStepSize = %.17g s "
                "= %.17g s is not a finite time after the current one",
                function, current_time, step_size, current_time + step_size);
        return FMU_ERROR;
    }
    if (!step_is_valid(instance, current_time, step_size)) {
        fmu_log(instance, FMU_ERROR,
                "%s: currentCommunicationPoint = %.17g s + communicationStepSize = %.17g s "
                "= %.17g s ends past the experiment's stopTime (%.17g s at the latest)",
                function, current_time, step_size, current_time + step_size, instance->stop_limit);
        return FMU_ERROR;
    }
    return FMU_OK;
}

/* Refuses a step of a model with states that starts elsewhere than where its states
 * are (within the rounding of a sum of steps): they would be carried to another
 * time. An algebraic model's outputs do not depend on the time; it steps from any
 * communication point. */
static fmu_status check_continues(fmu_instance* instance, double current_time, const char* function)
{
    if (fabs(current_time - instance->time) >
        1e-9 * fmax(fabs(current_time), fabs(instance->time))) {
        fmu_log(instance, FMU_ERROR,
                "%s: currentCommunicationPoint = %.17g s, but the states are at t = %.17g s: a "
                "step starts where the last one ended (or at a restored FMU state's time)",
                function, current_time, instance->time);
        return FMU_ERROR;
    }
    return FMU_OK;
}

/* A step that reached `end`: the time there, and nothing to end the simulation for. */
static void step_completed(fmu_instance* instance, double end)
{
    instance->time = end;
    instance->last_successful_time = end;
    instance->terminate_requested = 0;
}

/* The time where a failed step stopped, `reached` seconds into it: before the step's end
 * even where the time's resolution (at t = 1e9 s, 1.2e-7 s) rounds the stop to it, so that
 * a master never reads a discarded step's last successful time as its end. */
static double stop_time(double current_time, double step_size, double reached)
{
    const double end = current_time + step_size;
    const double stopped = reached > 0 ? current_time + reached : current_time;
    return stopped < end ? stopped : nextafter(end, current_time);
}

/* The outputs of the model's fmu_later now, after an evaluation that went well: 1 if
 * they did too, else 0 (logged). */
FMU_COLD static int later_now(fmu_instance* instance, const char* function)
{
    fmu_evaluation* e = &instance->evaluation;
    instance->later_pending = 0;
    instance->model->behaviour->later->later(instance->model, instance->input, instance->output, e);
    if (e->status == FMU_OK) {
        return 1;
    }
    log_failure(instance, FMU_WARNING, function);
    return 0;
}

/* solve(), then the outputs of the model's fmu_later where they are not computed since
 * the evaluation; a failure of theirs is logged when it is found (FMU_WARNING, as a
 * get's failed solve). */
static fmu_status solve_later(fmu_instance* instance, const char* function, int each_error)
{
    const fmu_status status = solve(instance, FMU_WARNING, function, each_error);
    if (status != FMU_OK || !instance->later_pending) {
        return status;
    }
    return later_now(instance, function) ? FMU_OK : FMU_WARNING;
}

/* solve() for a step, which says why whenever it returns Discard: a failure found before
 * the step (at initialisation, say) was logged by the call that found it, and is logged
 * again by the step it stops. */
static fmu_status solve_step(fmu_instance* instance, fmu_status not_solvable, const char* function)
{
    const int found_now = instance->dirty;
    const fmu_status status = solve(instance, not_solvable, function, 1);
    if (status == FMU_DISCARD && !found_now) {
        log_failure(instance, FMU_DISCARD, function);
    }
    return status;
}

/* A step of a model with states: the outputs at its start, the states
 * advanced, the outputs at its end. */
static fmu_status advance_states(fmu_instance* instance, double current_time, double step_size,
                                 const char* function)
{
    fmu_status status = solve_step(instance, FMU_DISCARD, function);
    if (status == FMU_OK) {
        fmu_evaluation* e = &instance->evaluation;
        const double reached =
            instance->model->behaviour->advance(instance->model, instance->input, step_size, e);
        instance->dirty = 1;
        if (e->status == FMU_ERROR) {
            /* A step the model refuses (it left its states as they were). */
            fmu_log(instance, FMU_ERROR, "%s: at t = %g s: %s", function, current_time, e->reason);
            return FMU_ERROR;
        }
        if (e->status != FMU_OK) {
            /* A step that failed: the states where it stopped, the outputs there */
            fmu_log(instance, FMU_DISCARD, "%s: at t = %g s: %s", function, current_time,
                    e->reason);
            instance->time = stop_time(current_time, step_size, reached);
            instance->last_successful_time = instance->time;
            instance->terminate_requested = 1;
            return FMU_DISCARD;
        }
        instance->time = current_time + step_size;
        status = solve(instance, FMU_DISCARD, function, 1);
        if (status == FMU_OK) {
            step_completed(instance, instance->time);
            return FMU_OK;
        }
    }
    if (status == FMU_DISCARD) {
        instance->last_successful_time = current_time;
        instance->terminate_requested = 1;
    }
    return status;
}

/* Whether a step the model has no answer for goes on (on_singular = continue). The
 * step's failure is then logged as a warning, once, when it is found. */
static int continues(const fmu_instance* instance)
{
    return instance->on_singular != NULL && *instance->on_singular == FMU_ON_SINGULAR_CONTINUE;
}

/* A step of an algebraic model: its outputs for the inputs, or none. */
static fmu_status step_algebraic(fmu_instance* instance, double current_time, double step_size,
                                 const char* function)
{
    fmu_status status =
        solve_step(instance, continues(instance) ? FMU_WARNING : FMU_DISCARD, function);
    if (status == FMU_WARNING) {
        status = FMU_OK; /* on_singular = continue: the outputs NaN, the status set */
    }
    if (status == FMU_OK) {
        step_completed(instance, current_time + step_size);
    } else if (status == FMU_DISCARD) {
        instance->last_successful_time = current_time;
        instance->terminate_requested = 1;
    }
    return status;
}

/* A step the common path did not take: a checked call, a model with states, or a
 * step without an answer. */
FMU_COLD static fmu_status do_step_checked(fmu_instance* instance, double current_time,
                                           double step_size, const char* function)
{
    double time;
    fmu_status status = fmu_check_call(instance, FMU_OP_DO_STEP, function);
    if (status != FMU_OK) {
        return status;
    }
    if (check_step(instance, current_time, step_size, function) != FMU_OK) {
        return FMU_ERROR;
    }
    if (instance->model->behaviour->advance != NULL &&
        check_continues(instance, current_time, function) != FMU_OK) {
        return FMU_ERROR;
    }
    time = instance->time;
    instance->time = current_time; /* where a failure found now is logged */
    status = instance->model->behaviour->advance != NULL
                 ? advance_states(instance, current_time, step_size, function)
                 : step_algebraic(instance, current_time, step_size, function);
    if (status == FMU_ERROR) {
        /* a step refused reached no time: the time, the last successful time and the
         * terminate flag stay, so that the last successful time is never after the time */
        instance->time = time;
    }
    return status;
}

fmu_status fmu_do_step(fmu_instance* instance, double current_time, double step_size,
                       const char* function)
{
    /* the common case: an algebraic model whose new inputs have an answer */
    if (instance != NULL && quiet_call(instance, FMU_OP_DO_STEP) &&
        step_is_valid(instance, current_time, step_size)) {
        fmu_evaluation* e = &instance->evaluation;
        if (instance->dirty) {
            sync_angles(instance);
            evaluate_for_reads(instance);
            if (e->status != FMU_OK) {
                /* found now: do_step_checked logs it, once, and decides */
                instance->dirty = 1;
                return do_step_checked(instance, current_time, step_size, function);
            }
            instance->dirty = 0;
        }
        if (e->status == FMU_OK) {
            step_completed(instance, current_time + step_size);
            return FMU_OK;
        }
    }
    return do_step_checked(instance, current_time, step_size, function);
}

fmu_status fmu_terminate(fmu_instance* instance)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_TERMINATE, "terminate");
    if (status == FMU_OK) {
        enter_state(instance, FMU_STATE_TERMINATED);
    }
    return status;
}

fmu_status fmu_reset(fmu_instance* instance)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_RESET, "reset");
    if (status == FMU_OK) {
        load_start_values(instance);
    }
    return status;
}

/* ---- get and set ---------------------------------------------------------------------------- */

static const char* type_name(fmu_value_type type)
{
    switch (type) {
    case FMU_REAL: return "Real";
    case FMU_INTEGER: return "Integer";
    case FMU_ENUMERATION: return "Enumeration";
    }
    return "?";
}

/* The types a call addresses, for a message. */
static const char* types_name(unsigned types)
{
    if (types == (FMU_TYPE_BIT(FMU_INTEGER) | FMU_TYPE_BIT(FMU_ENUMERATION))) {
        return "Integer or Enumeration";
    }
    if (types == FMU_TYPE_BIT(FMU_INTEGER)) {
        return "Integer";
    }
    return types == FMU_TYPE_BIT(FMU_ENUMERATION) ? "Enumeration" : "Real";
}

/* How a get or set passes its values: the C type of the importer's array, and the
 * variable types the call addresses (FMU_TYPE_BIT). */
typedef enum array_type { ARRAY_DOUBLE = 0, ARRAY_INT, ARRAY_INT64 } array_type;
typedef struct value_access {
    array_type array;
    unsigned types;
} value_access;

static const value_access reals = {ARRAY_DOUBLE, FMU_TYPE_BIT(FMU_REAL)};

/* The variable of a value reference of one of the given types, or NULL with a
 * logged error. */
static const fmu_variable* lookup(const fmu_instance* instance, unsigned int vr, unsigned types,
                                  const char* function)
{
    const fmu_model* model = instance->model;
    const fmu_variable* v;
    if (vr >= model->vr_limit || model->index_of_vr[vr] < 0) {
        fmu_log(instance, FMU_ERROR, "%s: unknown value reference %u", function, vr);
        return NULL;
    }
    v = &model->variables[model->index_of_vr[vr]];
    if (!(FMU_TYPE_BIT(v->type) & types)) {
        fmu_log(instance, FMU_ERROR, "%s: value reference %u (%s) is of type %s, not %s", function,
                vr, v->name, type_name(v->type), types_name(types));
        return NULL;
    }
    return v;
}

static fmu_status check_arrays(const fmu_instance* instance, const void* vr, size_t count,
                               const void* values, const char* function)
{
    if (count > 0 && (vr == NULL || values == NULL)) {
        fmu_log(instance, FMU_ERROR, "%s: %zu values requested but an array is NULL", function,
                count);
        return FMU_ERROR;
    }
    return FMU_OK;
}

/* The items of an enumeration, for a message. */
static const char* items_of(const fmu_variable* v)
{
    if (v->target == FMU_TARGET_SETTING && v->offset == FMU_SETTING_ON_SINGULAR) {
        return "1 (discard) or 2 (continue)";
    }
    return "see its declared type";
}

/* Why a value of an Enumeration is not one of its items (NaN, a fraction, another
 * number); 0 if it is. */
static int item_refused(const fmu_variable* v, double value, char* why, size_t size)
{
    if (value >= v->min && value <= v->max && value == floor(value)) {
        return 0;
    }
    snprintf(why, size, "%s = %.17g is not an item of its enumeration: %s", v->name, value,
             items_of(v));
    return 1;
}

/* Why a value outside v's bounds is; 0 if it is within them. */
static int bound_refused(const fmu_variable* v, double value, char* why, size_t size)
{
    if ((v->bounds & FMU_HAS_MIN) &&
        ((v->bounds & FMU_MIN_EXCLUSIVE) ? !(value > v->min) : !(value >= v->min))) {
        snprintf(why, size, "%s = %g%s%s: it must be %s %g", v->name, value,
                 v->unit[0] != '\0' ? " " : "", v->unit,
                 (v->bounds & FMU_MIN_EXCLUSIVE) ? ">" : ">=", v->min);
        return 1;
    }
    if ((v->bounds & FMU_HAS_MAX) &&
        ((v->bounds & FMU_MAX_EXCLUSIVE) ? !(value < v->max) : !(value <= v->max))) {
        snprintf(why, size, "%s = %g%s%s: it must be %s %g", v->name, value,
                 v->unit[0] != '\0' ? " " : "", v->unit,
                 (v->bounds & FMU_MAX_EXCLUSIVE) ? "<" : "<=", v->max);
        return 1;
    }
    return 0;
}

int fmu_value_refused(const fmu_variable* v, double value, char* why, size_t size)
{
    if (v->type == FMU_ENUMERATION) {
        return item_refused(v, value, why, size);
    }
    if (!isfinite(value)) {
        snprintf(why, size, "%s = %g is not a finite number", v->name, value);
        return 1;
    }
    if (v->type == FMU_INTEGER &&
        !(value == floor(value) && value >= (double)INT_MIN && value <= (double)INT_MAX)) {
        snprintf(why, size, "%s = %.17g is not an Integer", v->name, value);
        return 1;
    }
    return bound_refused(v, value, why, size);
}

/* Whether a value may be stored in v now; logs the reason if not. */
static fmu_status check_settable(const fmu_instance* instance, const fmu_variable* v, double value,
                                 const char* function)
{
    char why[300];
    if (v->causality == FMU_OUTPUT) {
        fmu_log(instance, FMU_ERROR, "%s: %s is an output and cannot be set", function, v->name);
        return FMU_ERROR;
    }
    if (v->causality == FMU_PARAMETER && !((unsigned)instance->state & PARAMETER_STATES)) {
        fmu_log(instance, FMU_ERROR,
                "%s: %s is a fixed parameter; it can be set only before initialization ends "
                "(now in %s)",
                function, v->name, state_name(instance->state));
        return FMU_ERROR;
    }
    if (fmu_value_refused(v, value, why, sizeof why)) {
        fmu_log(instance, FMU_ERROR, "%s: %s", function, why);
        return FMU_ERROR;
    }
    return FMU_OK;
}

/* The importer's arrays are double, int or int64_t; the store is double (which
 * holds every value an Integer or Enumeration may take exactly). */
static double value_at(const void* values, array_type array, size_t k)
{
    switch (array) {
    case ARRAY_INT: return (double)((const int*)values)[k];
    case ARRAY_INT64: return (double)((const int64_t*)values)[k];
    case ARRAY_DOUBLE: break;
    }
    return ((const double*)values)[k];
}

/* A kept value as the importer's integer type. Every value kept is one the type holds
 * (the setters and a restored FMU state check it); were one not, it saturates, and a
 * NaN reads as the type's minimum, rather than convert with undefined behaviour. */
static int to_int(double value)
{
    if (value >= (double)INT_MAX) {
        return INT_MAX;
    }
    return value > (double)INT_MIN ? (int)value : INT_MIN;
}

static int64_t to_int64(double value)
{
    const double limit = 9223372036854775808.0; /* 2^63: INT64_MAX + 1 */
    if (value >= limit) {
        return INT64_MAX;
    }
    return value >= -limit ? (int64_t)value : INT64_MIN;
}

static void store_at(void* values, array_type array, size_t k, double value)
{
    switch (array) {
    case ARRAY_INT: ((int*)values)[k] = to_int(value); break;
    case ARRAY_INT64: ((int64_t*)values)[k] = to_int64(value); break;
    case ARRAY_DOUBLE: ((double*)values)[k] = value; break;
    }
}

/* The slot of a value reference, NULL beyond the table. */
static const fmu_slot* slot_of(const fmu_instance* instance, unsigned int vr)
{
    return vr < instance->model->vr_limit ? &instance->slots[vr] : NULL;
}

/* Finds and logs why a set is refused, by the checks that name the variable;
 * FMU_OK if none refuses it. */
static fmu_status explain_refusal(const fmu_instance* instance, const unsigned int vr[],
                                  size_t count, const void* values, value_access access,
                                  const char* function)
{
    size_t k;
    for (k = 0; k < count; ++k) {
        const fmu_variable* v;
        if (vr[k] == 0 && instance->time_at_vr_0) {
            fmu_log(instance, FMU_ERROR,
                    "%s: time (value reference 0) is the independent variable and cannot be set",
                    function);
            return FMU_ERROR;
        }
        v = lookup(instance, vr[k], access.types, function);
        if (v == NULL ||
            check_settable(instance, v, value_at(values, access.array, k), function) != FMU_OK) {
            return FMU_ERROR;
        }
    }
    return FMU_OK;
}

/* The states from their start parameters, after a set before initialization ends. */
static void restart_states(fmu_instance* instance)
{
    if (instance->model->behaviour->start != NULL) {
        sync_angles(instance);
        instance->model->behaviour->start(instance->model, instance->input);
    }
}

/* Until initialization ends, the states follow their start parameters. */
FMU_INLINE void after_set(fmu_instance* instance)
{
    instance->dirty = 1;
    if ((unsigned)instance->state & PARAMETER_STATES) {
        restart_states(instance);
    }
}

/* Every value is checked before any is stored: a rejected call changes nothing.
 * The caller checked that a set is legal now. */
static fmu_status set_values(fmu_instance* instance, const unsigned int vr[], size_t count,
                             const void* values, value_access access, const char* function)
{
    size_t k;
    if (check_arrays(instance, vr, count, values, function) != FMU_OK ||
        explain_refusal(instance, vr, count, values, access, function) != FMU_OK) {
        return FMU_ERROR;
    }
    for (k = 0; k < count; ++k) {
        store(instance, (size_t)instance->model->index_of_vr[vr[k]],
              value_at(values, access.array, k));
    }
    if (count > 0) {
        after_set(instance);
    }
    return FMU_OK;
}

/* The common case of set_values, by the slots alone: every value valid. A call
 * the plan does not cover yet (its first, say) checks every value, then stores. */
static int set_reals_at_once(fmu_instance* instance, const unsigned int vr[], size_t count,
                             const double values[])
{
    const unsigned int limit = instance->model->vr_limit;
    const fmu_slot* slots = instance->slots;
    size_t k;
    for (k = 0; k < count; ++k) {
        const double value = values[k];
        if (vr[k] >= limit || !(value >= slots[vr[k]].low && value <= slots[vr[k]].high)) {
            return 0;
        }
    }
    for (k = 0; k < count; ++k) {
        *slots[vr[k]].write = values[k];
    }
    return 1;
}

/* The value of a variable as a double; an output as of the last evaluation. */
static double read_variable(fmu_instance* instance, const fmu_variable* v)
{
    const char* member = (const char*)instance->output + v->offset;
    if (v->causality != FMU_OUTPUT) {
        return *kept_value(instance, (size_t)(v - instance->model->variables));
    }
    if (v->target == FMU_TARGET_RESULT_STATUS) {
        return (double)*(const int*)(const void*)member;
    }
    return *(const double*)(const void*)member;
}

/* Reads the values, solving once before the first output (the caller checked
 * that a get is legal now). Returns FMU_ERROR
 * for a value reference that is not of `type`; otherwise, if `solve_counts`,
 * the status of that solve (a failed one as FMU_WARNING), else FMU_OK. */
static fmu_status get_values(fmu_instance* instance, const unsigned int vr[], size_t count,
                             void* values, value_access access, int solve_counts,
                             const char* function)
{
    fmu_status worst = FMU_OK;
    int solved = 0;
    size_t k;
    if (check_arrays(instance, vr, count, values, function) != FMU_OK) {
        return FMU_ERROR;
    }
    for (k = 0; k < count; ++k) {
        const fmu_slot* slot = slot_of(instance, vr[k]);
        const fmu_variable* v;
        if (access.array == ARRAY_DOUBLE && slot != NULL && slot->read == &instance->time) {
            store_at(values, access.array, k, instance->time);
            continue;
        }
        v = lookup(instance, vr[k], access.types, function);
        if (v == NULL) {
            return FMU_ERROR;
        }
        if (v->causality == FMU_OUTPUT && !solved) {
            const fmu_status solved_status = solve(instance, FMU_WARNING, function, solve_counts);
            worst = solve_counts ? solved_status : FMU_OK;
            solved = 1;
        }
        if (slot != NULL && slot->later && instance->later_pending && worst == FMU_OK) {
            worst = solve_later(instance, function, solve_counts);
        }
        store_at(values, access.array, k, read_variable(instance, v));
    }
    return worst;
}

/* The common case of get_values for Reals, by the slots alone: every value
 * reference a Real; -1 where one is not (get_values says why). */
static int get_reals_at_once(fmu_instance* instance, const unsigned int vr[], size_t count,
                             double values[], fmu_status* solved, const char* function)
{
    const unsigned int limit = instance->model->vr_limit;
    const fmu_slot* slots = instance->slots;
    int have_solved = 0;
    size_t k;
    for (k = 0; k < count; ++k) {
        if (vr[k] >= limit || slots[vr[k]].read == NULL) {
            return 0;
        }
        if (slots[vr[k]].is_output && !have_solved) {
            *solved = solve(instance, FMU_WARNING, function, 1);
            have_solved = 1;
        }
        if (slots[vr[k]].later && instance->later_pending && *solved == FMU_OK) {
            *solved = solve_later(instance, function, 1);
        }
        values[k] = *slots[vr[k]].read;
    }
    return 1;
}

/* 1 if vr[k] == planned[k] for every k < count (count > 0): four at a time, the
 * last four overlapping those before where count is not a multiple of four, so
 * that no loop handles a tail. */
FMU_INLINE int same_references(const unsigned int planned[], const unsigned int vr[], size_t count)
{
    unsigned int differ;
#if defined(__SSE2__)
    if (count >= 4) {
        const __m128i* const mine = (const __m128i*)(const void*)planned;
        const __m128i* const theirs = (const __m128i*)(const void*)vr;
        const __m128i* const mine_last = (const __m128i*)(const void*)(planned + count - 4);
        const __m128i* const theirs_last = (const __m128i*)(const void*)(vr + count - 4);
        __m128i d = _mm_xor_si128(_mm_loadu_si128(mine_last), _mm_loadu_si128(theirs_last));
        size_t k = 0;
        for (; 4 * k + 8 < count; k += 2) {
            d = _mm_or_si128(d,
                             _mm_xor_si128(_mm_loadu_si128(mine + k), _mm_loadu_si128(theirs + k)));
            d = _mm_or_si128(
                d, _mm_xor_si128(_mm_loadu_si128(mine + k + 1), _mm_loadu_si128(theirs + k + 1)));
        }
        if (4 * k + 4 < count) {
            d = _mm_or_si128(d,
                             _mm_xor_si128(_mm_loadu_si128(mine + k), _mm_loadu_si128(theirs + k)));
        }
        return _mm_movemask_epi8(_mm_cmpeq_epi32(d, _mm_setzero_si128())) == 0xFFFF;
    }
#endif
    differ = vr[0] ^ planned[0];
    if (count >= 2) {
        size_t k;
        for (k = 1; k < count; ++k) {
            differ |= vr[k] ^ planned[k];
        }
    }
    return differ == 0;
}

/* 1 if every value is finite (count > 0): their products with 0 add up to 0,
 * where an infinity or a NaN makes the sum NaN. What same_and_finite does four at
 * a time, for fewer than four values or without SSE2. */
static int all_finite(const double values[], size_t count)
{
    double sum = 0;
    size_t k;
    for (k = 0; k < count; ++k) {
        sum += values[k] * 0.0;
    }
    return sum == 0;
}

/* same_references and all_finite in one pass: a set's common case. */
FMU_INLINE int same_and_finite(const unsigned int planned[], const unsigned int vr[],
                               const double values[], size_t count)
{
#if defined(__SSE2__)
    if (count >= 4) {
        const __m128i* const mine = (const __m128i*)(const void*)planned;
        const __m128i* const theirs = (const __m128i*)(const void*)vr;
        const size_t last = count - 4;
        const __m128d zero = _mm_setzero_pd();
        __m128i d = _mm_xor_si128(_mm_loadu_si128((const __m128i*)(const void*)(planned + last)),
                                  _mm_loadu_si128((const __m128i*)(const void*)(vr + last)));
        __m128d low = _mm_mul_pd(_mm_loadu_pd(values + last), zero);
        __m128d high = _mm_mul_pd(_mm_loadu_pd(values + last + 2), zero);
        size_t k;
        for (k = 0; 4 * k < last; ++k) {
            d = _mm_or_si128(d,
                             _mm_xor_si128(_mm_loadu_si128(mine + k), _mm_loadu_si128(theirs + k)));
            low = _mm_add_pd(low, _mm_mul_pd(_mm_loadu_pd(values + 4 * k), zero));
            high = _mm_add_pd(high, _mm_mul_pd(_mm_loadu_pd(values + 4 * k + 2), zero));
        }
        low = _mm_add_pd(low, high);
        return _mm_movemask_epi8(_mm_cmpeq_epi32(d, _mm_setzero_si128())) == 0xFFFF &&
               _mm_cvtsd_f64(_mm_add_sd(low, _mm_unpackhi_pd(low, low))) == 0;
    }
#endif
    return same_references(planned, vr, count) && all_finite(values, count);
}

/* 1 if each value with bounds tighter than finite is within them (never a NaN). */
static int bounded_within(const fmu_plan* plan, const double values[])
{
    int within = 1;
    size_t j;
    for (j = 0; j < plan->bounded_count; ++j) {
        const double value = values[plan->position[j]];
        within &= value >= plan->low[j] && value <= plan->high[j];
    }
    return within;
}

/* A set by the plan (count > 0) of finite values: every bound checked, then every
 * value stored, in order (a repeated reference keeps its last value; the
 * overlapping last four store again what they stored, in the same order, so that
 * still holds). */
static int set_by_plan(fmu_instance* instance, size_t count, const double values[])
{
    const fmu_plan* plan = &instance->set_plan;
    double* const* write = plan->write;
    size_t k;
    if (!bounded_within(plan, values)) {
        return 0;
    }
    if (plan->store != NULL) {
        plan->store(instance->input, instance->values, values);
    } else if (count >= 4) {
        for (k = 0; k + 4 < count; k += 4) {
            *write[k] = values[k];
            *write[k + 1] = values[k + 1];
            *write[k + 2] = values[k + 2];
            *write[k + 3] = values[k + 3];
        }
        k = count - 4;
        *write[k] = values[k];
        *write[k + 1] = values[k + 1];
        *write[k + 2] = values[k + 2];
        *write[k + 3] = values[k + 3];
    } else {
        for (k = 0; k < count; ++k) {
            *write[k] = values[k];
        }
    }
    return 1;
}

/* A get by the plan (count > 0): each value from where it is kept, two at a time,
 * the last two overlapping where count is odd. */
static void get_by_plan(const fmu_plan* plan, const void* output, size_t count, double values[])
{
    const double* const* read = plan->read;
    size_t k;
    if (plan->load != NULL) {
        plan->load(output, values);
        return;
    }
#if defined(__SSE2__)
    if (count >= 2) {
        for (k = 0; k + 2 < count; k += 2) {
            _mm_storeu_pd(values + k, _mm_loadh_pd(_mm_load_sd(read[k]), read[k + 1]));
        }
        k = count - 2;
        _mm_storeu_pd(values + k, _mm_loadh_pd(_mm_load_sd(read[k]), read[k + 1]));
        return;
    }
#endif
    for (k = 0; k < count; ++k) {
        values[k] = *read[k];
    }
}

/* A plan of a call the slots accepted (every vr below vr_limit), none for an empty
 * call or one longer than the table (a repeated reference: rare, and not planned). */
static void make_plan(const fmu_instance* instance, fmu_plan* plan, const unsigned int vr[],
                      size_t count)
{
    const fmu_copies* copies = instance->model->copies;
    size_t k, bounded = 0;
    plan->count = FMU_NO_PLAN;
    if (count == 0 || count > instance->model->vr_limit) {
        return;
    }
    for (k = 0; k < count; ++k) {
        const fmu_slot* slot = &instance->slots[vr[k]];
        plan->vr[k] = vr[k];
        plan->write[k] = slot->write;
        plan->read[k] = slot->read;
        if (slot->low != -DBL_MAX || slot->high != DBL_MAX) {
            plan->position[bounded] = (unsigned int)k;
            plan->low[bounded] = slot->low;
            plan->high[bounded] = slot->high;
            ++bounded;
        }
    }
    plan->bounded_count = bounded;
    plan->store = NULL;
    plan->load = NULL;
    plan->later = 0;
    for (k = 0; k < count; ++k) {
        plan->later |= instance->slots[vr[k]].later;
    }
    if (copies != NULL && count == copies->input_count && count > 0 &&
        same_references(copies->input_vrs, vr, count)) {
        plan->store = copies->store_inputs;
    }
    if (copies != NULL && count == copies->output_count && count > 0 &&
        same_references(copies->output_vrs, vr, count)) {
        plan->load = copies->load_outputs;
    }
    plan->count = count;
}

/* A set of Reals the common path did not take: checked call, and a new plan or a
 * refusal that names the value. */
FMU_COLD static fmu_status set_reals_checked(fmu_instance* instance, const unsigned int vr[],
                                             size_t count, const double values[],
                                             const char* function)
{
    if (fmu_check_call(instance, FMU_OP_SET, function) != FMU_OK) {
        return FMU_ERROR;
    }
    if (count > 0 && vr != NULL && values != NULL &&
        set_reals_at_once(instance, vr, count, values)) {
        make_plan(instance, &instance->set_plan, vr, count);
        after_set(instance);
        return FMU_OK;
    }
    return set_values(instance, vr, count, values, reals, function);
}

fmu_status fmu_set_real(fmu_instance* instance, const unsigned int vr[], size_t count,
                        const double values[], const char* function)
{
    /* the common case: the same references as the last set, every value valid */
    if (instance != NULL && count == instance->set_plan.count && vr != NULL && values != NULL &&
        quiet_call(instance, FMU_OP_SET) &&
        same_and_finite(instance->set_plan.vr, vr, values, count) &&
        set_by_plan(instance, count, values)) {
        instance->dirty = 1; /* the parameters are closed: no states to restart */
        return FMU_OK;
    }
    return set_reals_checked(instance, vr, count, values, function);
}

fmu_status fmu_set_integer(fmu_instance* instance, const unsigned int vr[], size_t count,
                           const int values[], unsigned types, const char* function)
{
    const value_access access = {ARRAY_INT, types};
    if (fmu_check_call(instance, FMU_OP_SET, function) != FMU_OK) {
        return FMU_ERROR;
    }
    return set_values(instance, vr, count, values, access, function);
}

fmu_status fmu_set_int64(fmu_instance* instance, const unsigned int vr[], size_t count,
                         const int64_t values[], const char* function)
{
    const value_access access = {ARRAY_INT64, FMU_TYPE_BIT(FMU_ENUMERATION)};
    if (fmu_check_call(instance, FMU_OP_SET, function) != FMU_OK) {
        return FMU_ERROR;
    }
    return set_values(instance, vr, count, values, access, function);
}

/* A get of Reals the common path did not take: checked call, a solve where an output
 * needs one, and a new plan or the reason a value reference is refused. */
FMU_COLD static fmu_status get_reals_checked(fmu_instance* instance, const unsigned int vr[],
                                             size_t count, double values[], const char* function)
{
    fmu_status solved = FMU_OK;
    if (fmu_check_call(instance, FMU_OP_GET, function) != FMU_OK) {
        return FMU_ERROR;
    }
    if (vr != NULL && values != NULL &&
        get_reals_at_once(instance, vr, count, values, &solved, function)) {
        make_plan(instance, &instance->get_plan, vr, count);
        choose_evaluation(instance);
        return solved;
    }
    return get_values(instance, vr, count, values, reals, 1, function);
}

fmu_status fmu_get_real(fmu_instance* instance, const unsigned int vr[], size_t count,
                        double values[], const char* function)
{
    /* the common case: after a step, the same references as the last get */
    if (instance != NULL && count == instance->get_plan.count && vr != NULL && values != NULL &&
        quiet_call(instance, FMU_OP_GET) && !instance->dirty &&
        instance->evaluation.status == FMU_OK &&
        same_references(instance->get_plan.vr, vr, count)) {
        /* A plan that reads outputs of the model's fmu_later was made by a get that
         * computed them, and a step after it evaluates every output (choose_evaluation):
         * here they are never pending. */
        get_by_plan(&instance->get_plan, instance->output, count, values);
        return FMU_OK;
    }
    return get_reals_checked(instance, vr, count, values, function);
}

fmu_status fmu_get_integer(fmu_instance* instance, const unsigned int vr[], size_t count,
                           int values[], unsigned types, const char* function)
{
    const value_access access = {ARRAY_INT, types};
    if (fmu_check_call(instance, FMU_OP_GET, function) != FMU_OK) {
        return FMU_ERROR;
    }
    /* The status output is how the model reports a singular configuration or
     * a rejected input (logged when it was evaluated): reading it succeeds
     * whatever it says. */
    return get_values(instance, vr, count, values, access, 0, function);
}

fmu_status fmu_get_int64(fmu_instance* instance, const unsigned int vr[], size_t count,
                         int64_t values[], const char* function)
{
    const value_access access = {ARRAY_INT64, FMU_TYPE_BIT(FMU_ENUMERATION)};
    if (fmu_check_call(instance, FMU_OP_GET, function) != FMU_OK) {
        return FMU_ERROR;
    }
    return get_values(instance, vr, count, values, access, 0, function);
}

/* The seed block from the knowns' rates: an angle's rate as the derivative of
 * its (cos, sin). FMU_ERROR where a known is not an input or its seed is not
 * finite; nothing is evaluated then. */
static fmu_status seed_knowns(fmu_instance* instance, const unsigned int knowns[], size_t n_knowns,
                              const double seed[], const char* function)
{
    size_t k;
    memset(instance->seed, 0, instance->model->behaviour->input_size);
    for (k = 0; k < n_knowns; ++k) {
        const fmu_variable* v = lookup(instance, knowns[k], reals.types, function);
        double* rate;
        if (v == NULL) {
            return FMU_ERROR;
        }
        if (v->causality != FMU_INPUT) {
            fmu_log(instance, FMU_ERROR, "%s: known %s is not an input", function, v->name);
            return FMU_ERROR;
        }
        if (!isfinite(seed[k])) {
            fmu_log(instance, FMU_ERROR, "%s: the seed of known %s is not finite", function,
                    v->name);
            return FMU_ERROR;
        }
        rate = (double*)(void*)((char*)instance->seed + v->offset);
        if (v->target == FMU_TARGET_INPUT_ANGLE) {
            /* d(cos, sin)/d angle = (-sin, cos) */
            const double* dir =
                (const double*)(const void*)((const char*)instance->input + v->offset);
            rate[0] -= seed[k] * dir[1];
            rate[1] += seed[k] * dir[0];
        } else {
            rate[0] += seed[k];
        }
    }
    return FMU_OK;
}

/* FMU_ERROR unless every unknown is an output. */
static fmu_status check_unknowns(fmu_instance* instance, const unsigned int unknowns[],
                                 size_t n_unknowns, const char* function)
{
    size_t k;
    for (k = 0; k < n_unknowns; ++k) {
        const fmu_variable* v = lookup(instance, unknowns[k], reals.types, function);
        if (v == NULL) {
            return FMU_ERROR;
        }
        if (v->causality != FMU_OUTPUT) {
            fmu_log(instance, FMU_ERROR, "%s: %s is not an output", function, v->name);
            return FMU_ERROR;
        }
    }
    return FMU_OK;
}

fmu_status fmu_directional_derivative(fmu_instance* instance, const unsigned int unknowns[],
                                      size_t n_unknowns, const unsigned int knowns[],
                                      size_t n_knowns, const double seed[], double derivative[],
                                      const char* function)
{
    const fmu_behaviour* behaviour;
    fmu_evaluation evaluation;
    size_t k;
    fmu_status status = fmu_check_call(instance, FMU_OP_GET, function);
    if (status != FMU_OK || check_arrays(instance, knowns, n_knowns, seed, function) != FMU_OK ||
        check_arrays(instance, unknowns, n_unknowns, derivative, function) != FMU_OK) {
        return FMU_ERROR;
    }
    behaviour = instance->model->behaviour;
    if (behaviour->derivative == NULL) {
        return fmu_unsupported(instance, function, "this model has no directional derivatives");
    }
    sync_angles(instance);
    if (seed_knowns(instance, knowns, n_knowns, seed, function) != FMU_OK ||
        check_unknowns(instance, unknowns, n_unknowns, function) != FMU_OK) {
        return FMU_ERROR;
    }
    behaviour->derivative(instance->model, instance->input, instance->seed, instance->value,
                          instance->rate, &evaluation);
    if (evaluation.status != FMU_OK) {
        fmu_log(instance, FMU_DISCARD, "%s: no derivative at these inputs: %s", function,
                evaluation.reason);
        for (k = 0; k < n_unknowns; ++k) {
            derivative[k] = NAN;
        }
        return FMU_DISCARD;
    }
    for (k = 0; k < n_unknowns; ++k) {
        const short index = instance->model->index_of_vr[unknowns[k]];
        const fmu_variable* v = &instance->model->variables[index];
        derivative[k] = *(const double*)(const void*)((const char*)instance->rate + v->offset);
    }
    return FMU_OK;
}

/* ---- inputs interpolated and outputs differentiated (canInterpolateInputs) ------------------- */

/* The model's interpolation, or NULL with "not supported" logged. */
static const fmu_interpolation* interpolation_of(fmu_instance* instance, const char* function,
                                                 const char* why)
{
    const fmu_interpolation* i = instance->model->behaviour->interpolation;
    if (i == NULL) {
        fmu_unsupported(instance, function, why);
    }
    return i;
}

/* Where the model keeps the first derivative of the input v, or NULL: it does not
 * interpolate v. */
static double* input_rate_of(fmu_instance* instance, const fmu_interpolation* interpolation,
                             const fmu_variable* v)
{
    size_t k;
    for (k = 0; k < interpolation->input_count; ++k) {
        if (v->target == FMU_TARGET_INPUT_REAL &&
            interpolation->inputs[k].value_offset == v->offset) {
            return (double*)(void*)((char*)instance->input + interpolation->inputs[k].rate_offset);
        }
    }
    return NULL;
}

/* FMU_ERROR, logged, unless every order is 1: the model's derivatives are first ones. */
static fmu_status check_orders(fmu_instance* instance, const unsigned int vr[], const int order[],
                               size_t count, const char* function)
{
    size_t k;
    for (k = 0; k < count; ++k) {
        if (order[k] != 1) {
            fmu_log(instance, FMU_ERROR,
                    "%s: order %d asked of value reference %u: this FMU's derivatives are "
                    "first derivatives only (order 1)",
                    function, order[k], vr[k]);
            return FMU_ERROR;
        }
    }
    return FMU_OK;
}

/* The rate of each input before any is stored, so that a refused call changes nothing. */
static fmu_status check_input_rates(fmu_instance* instance, const fmu_interpolation* interpolation,
                                    const unsigned int vr[], const double values[], size_t count,
                                    const char* function)
{
    size_t k;
    for (k = 0; k < count; ++k) {
        const fmu_variable* v = lookup(instance, vr[k], reals.types, function);
        if (v == NULL) {
            return FMU_ERROR;
        }
        if (v->causality != FMU_INPUT || input_rate_of(instance, interpolation, v) == NULL) {
            fmu_log(instance, FMU_ERROR,
                    "%s: %s is not an input this FMU interpolates; its inputs are its "
                    "continuous Real inputs",
                    function, v->name);
            return FMU_ERROR;
        }
        if (!isfinite(values[k])) {
            fmu_log(instance, FMU_ERROR, "%s: the derivative of %s = %g (%s/s) is not finite",
                    function, v->name, values[k], v->unit);
            return FMU_ERROR;
        }
    }
    return FMU_OK;
}

fmu_status fmu_set_input_rates(fmu_instance* instance, const unsigned int vr[], size_t count,
                               const int order[], const double values[], const char* function)
{
    const fmu_interpolation* interpolation;
    size_t k;
    if (fmu_check_call(instance, FMU_OP_SET, function) != FMU_OK ||
        check_arrays(instance, vr, count, values, function) != FMU_OK ||
        check_arrays(instance, order, count, values, function) != FMU_OK) {
        return FMU_ERROR;
    }
    interpolation = interpolation_of(instance, function, "canInterpolateInputs is false");
    if (interpolation == NULL || check_orders(instance, vr, order, count, function) != FMU_OK ||
        check_input_rates(instance, interpolation, vr, values, count, function) != FMU_OK) {
        return FMU_ERROR;
    }
    for (k = 0; k < count; ++k) {
        const fmu_variable* v = &instance->model->variables[instance->model->index_of_vr[vr[k]]];
        *input_rate_of(instance, interpolation, v) = values[k];
    }
    return FMU_OK;
}

fmu_status fmu_get_output_rates(fmu_instance* instance, const unsigned int vr[], size_t count,
                                const int order[], double values[], const char* function)
{
    const fmu_interpolation* interpolation;
    fmu_evaluation evaluation;
    size_t k;
    if (fmu_check_call(instance, FMU_OP_GET, function) != FMU_OK ||
        check_arrays(instance, vr, count, values, function) != FMU_OK ||
        check_arrays(instance, order, count, values, function) != FMU_OK) {
        return FMU_ERROR;
    }
    interpolation = interpolation_of(instance, function, "maxOutputDerivativeOrder is 0");
    if (interpolation == NULL || check_orders(instance, vr, order, count, function) != FMU_OK ||
        check_unknowns(instance, vr, count, function) != FMU_OK) {
        return FMU_ERROR;
    }
    sync_angles(instance);
    interpolation->output_rates(instance->model, instance->input, instance->rate, &evaluation);
    for (k = 0; k < count; ++k) {
        const fmu_variable* v = &instance->model->variables[instance->model->index_of_vr[vr[k]]];
        values[k] = *(const double*)(const void*)((const char*)instance->rate + v->offset);
    }
    if (evaluation.status != FMU_OK) {
        fmu_log(instance, FMU_DISCARD, "%s: at t = %g s the outputs have no derivatives: %s",
                function, instance->time, evaluation.reason);
        return FMU_DISCARD;
    }
    return FMU_OK;
}

fmu_status fmu_no_variables_of_type(fmu_instance* instance, fmu_operation operation,
                                    const unsigned int vr[], size_t count, const char* function)
{
    fmu_status status = fmu_check_call(instance, operation, function);
    if (status != FMU_OK) {
        return status;
    }
    if (count > 0) {
        fmu_log(instance, FMU_ERROR,
                "%s: unknown value reference %u (this FMU has no variables "
                "of this type)",
                function, vr != NULL ? vr[0] : 0u);
        return FMU_ERROR;
    }
    return FMU_OK;
}

fmu_status fmu_unsupported(fmu_instance* instance, const char* function, const char* why)
{
    if (instance == NULL) {
        return FMU_ERROR;
    }
    fmu_log(instance, FMU_ERROR, "%s is not supported by this FMU: %s", function, why);
    return FMU_ERROR;
}

/* ---- many rows at once ---------------------------------------------------------------------- */

/* 1 if every value reference names a Real of one of the causalities in `wanted`. */
static int all_of(const fmu_model* model, const unsigned int vr[], size_t count, unsigned wanted)
{
    size_t k;
    for (k = 0; k < count; ++k) {
        const fmu_variable* v;
        if (vr[k] >= model->vr_limit || model->index_of_vr[vr[k]] < 0) {
            return 0;
        }
        v = &model->variables[model->index_of_vr[vr[k]]];
        if (v->type != FMU_REAL || !((1u << v->causality) & wanted)) {
            return 0;
        }
    }
    return 1;
}

/* A design's parameters set on a reset instance, and its initialisation; FMU_OK if
 * the instance is in step mode with them. */
static fmu_status start_design(fmu_instance* instance, int first, const unsigned int vr_p[],
                               size_t n_p, const double p[])
{
    static const fmu_experiment from_zero = {0.0, 0, 0.0};
    fmu_status status = first ? FMU_OK : fmu_reset(instance);
    if (status == FMU_OK && n_p > 0) {
        status = fmu_set_real(instance, vr_p, n_p, p, "dyadfmu_evaluate_rows");
    }
    if (status == FMU_OK) {
        status = fmu_enter_initialization(instance, &from_zero);
    }
    if (status == FMU_OK && fmu_exit_initialization(instance) == FMU_ERROR) {
        status = FMU_ERROR;
    }
    return status;
}

static void fill_nan(double values[], size_t count)
{
    size_t k;
    for (k = 0; k < count; ++k) {
        values[k] = NAN;
    }
}

fmu_status fmu_evaluate_rows(const fmu_model* model, const char* token, int time_at_vr_0,
                             const unsigned int vr_p[], size_t n_p, const double p[],
                             const unsigned int vr_i[], size_t n_i, const double x[],
                             const unsigned int vr_o[], size_t n_o, double y[], int status[],
                             size_t rows)
{
    const fmu_logger quiet = {NULL, NULL, NULL, "rows"};
    fmu_instance* instance;
    fmu_status design = FMU_OK;
    size_t r;
    if ((n_p > 0 && (vr_p == NULL || p == NULL)) || (n_i > 0 && (vr_i == NULL || x == NULL)) ||
        (n_o > 0 && (vr_o == NULL || y == NULL)) || (rows > 0 && status == NULL) ||
        !all_of(model, vr_p, n_p, 1u << FMU_PARAMETER) ||
        !all_of(model, vr_i, n_i, 1u << FMU_INPUT) ||
        !all_of(model, vr_o, n_o, (1u << FMU_OUTPUT) | (1u << FMU_INPUT) | (1u << FMU_PARAMETER))) {
        return FMU_ERROR;
    }
    instance = fmu_instantiate(model, "rows", token, quiet, 0, NULL, NULL, time_at_vr_0);
    if (instance == NULL) {
        return FMU_FATAL;
    }
    for (r = 0; r < rows; ++r) {
        /* no arithmetic on an absent (NULL) array */
        const double* row_p = n_p > 0 ? p + r * n_p : NULL;
        double* row_y = n_o > 0 ? y + r * n_o : NULL;
        fmu_status s;
        if (r == 0 || (n_p > 0 && memcmp(row_p, row_p - n_p, n_p * sizeof *row_p) != 0)) {
            design = start_design(instance, r == 0, vr_p, n_p, row_p);
        }
        s = design;
        if (s == FMU_OK && n_i > 0) {
            s = fmu_set_real(instance, vr_i, n_i, x + r * n_i, "dyadfmu_evaluate_rows");
        }
        if (s == FMU_OK && n_o > 0) {
            s = fmu_get_real(instance, vr_o, n_o, row_y, "dyadfmu_evaluate_rows");
        }
        status[r] = (int)s;
        if (s != FMU_OK) {
            fill_nan(row_y, n_o);
        }
    }
    fmu_free(instance);
    return FMU_OK;
}

/* ---- many samples in columns ---------------------------------------------------------------- */

/* Where a column's values come from: its first value, and the doubles between two. */
typedef struct column_source {
    const double* at;
    ptrdiff_t step;
} column_source;

/* Where an x column's values go in the input block (an angle as its unit vector), and
 * the interval a value must lie in to be stored (fmu_slot's low and high). */
typedef struct column_place {
    double* at;
    double low, high;
    int angle;
} column_place;

/* The variable of a value reference, NULL where it names none. */
static const fmu_variable* variable_of(const fmu_model* model, unsigned int vr)
{
    if (vr >= model->vr_limit || model->index_of_vr[vr] < 0) {
        return NULL;
    }
    return &model->variables[model->index_of_vr[vr]];
}

/* A Real the input block keeps: an input or a parameter, as a number or an angle. */
static int kept_in_input(const fmu_variable* v)
{
    return v != NULL && v->type == FMU_REAL &&
           (v->causality == FMU_INPUT || v->causality == FMU_PARAMETER) &&
           (v->target == FMU_TARGET_INPUT_REAL || v->target == FMU_TARGET_INPUT_ANGLE);
}

/* The columns of one call: x (inputs and parameters), y (outputs), a status each. */
typedef struct column_call {
    const unsigned int* vr_x;
    size_t n_x;
    const double* const* x;
    const ptrdiff_t* x_step;
    const unsigned int* vr_y;
    size_t n_y;
    double* const* y;
    const ptrdiff_t* y_step;
    int* status;
    size_t count;
} column_call;

/* 1 if the call can be made: an algebraic model, every column there, the x columns
 * inputs or parameters of the input block, the y columns Real outputs or such. */
static int columns_valid(const fmu_model* model, const column_call* c)
{
    size_t k;
    if (model->behaviour == NULL || model->behaviour->advance != NULL ||
        (c->n_x > 0 && (c->vr_x == NULL || c->x == NULL || c->x_step == NULL)) ||
        (c->n_y > 0 && (c->vr_y == NULL || c->y == NULL || c->y_step == NULL)) ||
        (c->count > 0 && c->status == NULL)) {
        return 0;
    }
    for (k = 0; k < c->n_x; ++k) {
        if (c->x[k] == NULL || !kept_in_input(variable_of(model, c->vr_x[k]))) {
            return 0;
        }
    }
    for (k = 0; k < c->n_y; ++k) {
        const fmu_variable* v = variable_of(model, c->vr_y[k]);
        if (c->y[k] == NULL || v == NULL ||
            !(kept_in_input(v) || (v->type == FMU_REAL && v->target == FMU_TARGET_RESULT_REAL))) {
            return 0;
        }
    }
    return 1;
}

/* The blocks a call evaluates in: the model's input block as an instance's is after
 * initialisation (its start values), and its output block. */
typedef struct column_blocks {
    void* input;
    void* output;
    fmu_evaluation evaluation;
} column_blocks;

/* The start values into the input block, angles as their unit vectors. */
static void load_starts(const fmu_model* model, void* input)
{
    size_t k;
    model->behaviour->initialise(model, input);
    for (k = 0; k < model->variable_count; ++k) {
        const fmu_variable* v = &model->variables[k];
        if (v->target == FMU_TARGET_INPUT_REAL) {
            *(double*)(void*)((char*)input + v->offset) = v->start;
        } else if (v->target == FMU_TARGET_INPUT_ANGLE) {
            double* unit = (double*)(void*)((char*)input + v->offset);
            dyad_cos_sin(v->start, &unit[0], &unit[1]);
        }
    }
}

/* Where each x column's values go, and what a value must be. */
static void place_columns(const fmu_model* model, const column_blocks* b, const column_call* c,
                          column_place place[])
{
    size_t k;
    for (k = 0; k < c->n_x; ++k) {
        const fmu_variable* v = variable_of(model, c->vr_x[k]);
        fmu_slot range;
        accepted_range(v, &range);
        place[k].at = (double*)(void*)((char*)b->input + v->offset);
        place[k].low = range.low;
        place[k].high = range.high;
        place[k].angle = v->target == FMU_TARGET_INPUT_ANGLE;
    }
}

/* Where each y column's values come from: the output block, the x column of the same
 * variable, or its start value. */
static void find_sources(const fmu_model* model, const column_blocks* b, const column_call* c,
                         column_source source[])
{
    size_t k, j;
    for (k = 0; k < c->n_y; ++k) {
        const fmu_variable* v = variable_of(model, c->vr_y[k]);
        source[k].step = 0;
        source[k].at = &v->start;
        if (v->target == FMU_TARGET_RESULT_REAL) {
            source[k].at = (const double*)(const void*)((const char*)b->output + v->offset);
        } else if (v->target == FMU_TARGET_INPUT_REAL) {
            source[k].at = (const double*)(const void*)((const char*)b->input + v->offset);
        }
        for (j = 0; j < c->n_x; ++j) {
            if (c->vr_x[j] == c->vr_y[k]) {
                source[k].at = c->x[j];
                source[k].step = c->x_step[j];
            }
        }
    }
}

/* Sample `i`'s x values into the input block, each to its place's `at` (an angle's unit
 * vector in two reals); 0 where the model refuses one (outside its bounds, or not finite),
 * as a set of it would. */
static int store_values(const column_call* c, const column_place place[], size_t i)
{
    size_t k;
    for (k = 0; k < c->n_x; ++k) {
        const double value = c->x[k][(ptrdiff_t)i * c->x_step[k]];
        double* at = place[k].at;
        if (!(value >= place[k].low && value <= place[k].high)) {
            return 0;
        }
        if (place[k].angle) {
            dyad_cos_sin(value, &at[0], &at[1]);
        } else {
            *at = value;
        }
    }
    return 1;
}

/* 1 if a y column reads an output of the model's fmu_later. */
static int reads_later(const fmu_model* model, const column_call* c)
{
    size_t k;
    for (k = 0; k < c->n_y; ++k) {
        if (is_later(model, c->vr_y[k])) {
            return 1;
        }
    }
    return 0;
}

/* As an importer's get after a set reports the evaluation: Warning where the model
 * has no answer. */
static fmu_status sample_status(fmu_status evaluated)
{
    if (evaluated == FMU_OK || evaluated == FMU_ERROR) {
        return evaluated;
    }
    return FMU_WARNING;
}

static void evaluate_samples(const fmu_model* model, column_blocks* b, const column_call* c,
                             const column_place place[], const column_source source[])
{
    const fmu_later* later = model->behaviour->later;
    void (*evaluate)(const fmu_model*, const void*, void*, fmu_evaluation*) =
        later != NULL && !reads_later(model, c) ? later->first : model->behaviour->evaluate;
    size_t i, k;
    for (i = 0; i < c->count; ++i) {
        fmu_status s = FMU_ERROR;
        if (store_values(c, place, i)) {
            evaluate(model, b->input, b->output, &b->evaluation);
            s = sample_status(b->evaluation.status);
        }
        c->status[i] = (int)s;
        for (k = 0; k < c->n_y; ++k) {
            c->y[k][(ptrdiff_t)i * c->y_step[k]] =
                s == FMU_OK ? source[k].at[(ptrdiff_t)i * source[k].step] : NAN;
        }
    }
}

/* ---- the same in a model's lanes (fmu_lanes): many samples at once ---------------------- */

/* `count` angles into the (cos, sin) of each (dyadfmu/angle.h: the bits of dyad_cos_sin,
 * which the input block's angles get); `angle` may be `cos_out`. */
typedef void (*turn_fn)(const double* angle, double* cos_out, double* sin_out, size_t count);

/* In pairs (dyad_cos_sin_pair: in about half the time of one at a time). */
static void turn_in_pairs(const double* angle, double* cos_out, double* sin_out, size_t count)
{
    size_t lane;
    for (lane = 0; lane + 1 < count; lane += 2) {
        double unit0[2], unit1[2];
        dyad_cos_sin_pair(angle[lane], angle[lane + 1], unit0, unit1);
        cos_out[lane] = unit0[0];
        sin_out[lane] = unit0[1];
        cos_out[lane + 1] = unit1[0];
        sin_out[lane + 1] = unit1[1];
    }
    if (lane < count) {
        dyad_cos_sin(angle[lane], &cos_out[lane], &sin_out[lane]);
    }
}

/* The widest turning this CPU runs up to `cap`, as the lanes are chosen (an angle in
 * AVX2's lanes in half the time of a pair's, in AVX-512's in a third). */
static turn_fn turn_for(dyad_lanes_isa cap)
{
#if defined(DYAD_ANGLE_HAVE_WIDE)
    if (cap >= DYAD_LANES_AVX512 && __builtin_cpu_supports("avx512f")) {
        return dyad_cos_sin_avx512;
    }
    if (cap >= DYAD_LANES_AVX2 && __builtin_cpu_supports("avx2")) {
        return dyad_cos_sin_avx2;
    }
#else
    (void)cap;
#endif
    return turn_in_pairs;
}

/* The call's lanes: the grid of columns; per x column, the lane column its values go to;
 * per y column, the lane column its values come from (NULL: where find_sources said); the
 * outputs wanted; which samples were stored. */
typedef struct lane_grid {
    const fmu_lanes* lanes;
    dyad_lanes_isa cap;    /* the widest lanes to take (fmu_lanes; DYADFMU_LANES) */
    fmu_lanes_fn evaluate; /* the lanes the call takes (lanes_for) */
    turn_fn turn;          /* how its angles are turned (turn_for) */
    int halves;            /* 1 where they are the first half's: a sample alone too */
    double* cells;         /* columns x lanes */
    double** to;           /* n_x */
    const double** from;   /* n_y */
    unsigned char* wanted; /* outputs */
    int* stored;           /* lanes */
    int partial;           /* 1 where a y column does not come from the lanes */
} lane_grid;

/* The column of the real at `at` in `block` (the input's or the output's). */
static size_t lane_column_of(const void* block, const void* at)
{
    return (size_t)((const char*)at - (const char*)block) / sizeof(double);
}

/* Where each x column goes and each y column comes from in the lanes, and which outputs
 * are wanted. */
static void place_lanes(const column_blocks* b, const column_call* c, const column_place place[],
                        const column_source source[], lane_grid* g)
{
    const size_t lanes = g->lanes->lanes;
    const char* in = (const char*)b->input;
    const char* out = (const char*)b->output;
    size_t k;
    for (k = 0; k < c->n_x; ++k) {
        g->to[k] = g->cells + lane_column_of(b->input, place[k].at) * lanes;
    }
    memset(g->wanted, 0, g->lanes->outputs);
    g->partial = 0;
    for (k = 0; k < c->n_y; ++k) {
        const char* at = (const char*)(const void*)source[k].at;
        g->from[k] = NULL;
        if (at >= out && at < out + g->lanes->outputs * sizeof(double)) {
            const size_t j = lane_column_of(b->output, at);
            g->wanted[j] = 1;
            g->from[k] = g->cells + (g->lanes->inputs + j) * lanes;
        } else if (at >= in && at < in + g->lanes->inputs * sizeof(double)) {
            g->from[k] = g->cells + lane_column_of(b->input, at) * lanes;
        }
        g->partial |= g->from[k] == NULL;
    }
}

/* The lanes a call takes: without the bounds where it reads none of them (fmu_lanes.bare),
 * else its first half where it reads none of the later outputs (`halves`), else the whole. */
static fmu_lanes_fn lanes_for(const fmu_lanes* lanes, int halves, const unsigned char* wanted)
{
    size_t j;
    int bounds = 0;
    for (j = 0; lanes->bare != NULL && j < lanes->outputs; ++j) {
        bounds |= wanted[j] && lanes->bounds[j];
    }
    if (lanes->bare != NULL && !bounds && (halves || lanes->first == NULL)) {
        return lanes->bare;
    }
    return halves ? lanes->first : lanes->whole;
}

/* Sample `i`, in lane `lane`, alone in the blocks: its status and its outputs as evaluate
 * gives them, where its checks failed in the lanes. */
static fmu_status evaluate_lane_alone(const fmu_model* model, column_blocks* b, const lane_grid* g,
                                      size_t lane)
{
    const fmu_behaviour* behaviour = model->behaviour;
    size_t j;
    for (j = 0; j < g->lanes->inputs; ++j) {
        ((double*)b->input)[j] = g->cells[j * g->lanes->lanes + lane];
    }
    (g->halves ? behaviour->later->first : behaviour->evaluate)(model, b->input, b->output,
                                                                &b->evaluation);
    return sample_status(b->evaluation.status);
}

/* `count` values from every `from_step`th of `from` to every `to_step`th of `to`: a block
 * copy where both are contiguous, the common case, else four at a time (a row-major
 * table's column, say: about half the instructions of one at a time). */
static void copy_strided(double* to, ptrdiff_t to_step, const double* from, ptrdiff_t from_step,
                         size_t count)
{
    size_t i = 0;
    ptrdiff_t f = 0, t = 0; /* offsets, not pointers: none is formed past a column's end */
    if (to_step == 1 && from_step == 1) {
        memcpy(to, from, count * sizeof *to);
        return;
    }
    for (; i + 4 <= count; i += 4) {
        const double a = from[f], b = from[f + from_step], c = from[f + 2 * from_step],
                     d = from[f + 3 * from_step];
        to[t] = a;
        to[t + to_step] = b;
        to[t + 2 * to_step] = c;
        to[t + 3 * to_step] = d;
        f += 4 * from_step;
        t += 4 * to_step;
    }
    for (; i < count; ++i) {
        to[t] = from[f];
        f += from_step;
        t += to_step;
    }
}

/* The x columns' values of the samples from `first` on into their lane columns, column by
 * column (an angle as its unit vector); per lane whether every value lies within its
 * variable's bounds (store_values' check; a sample that fails it is not evaluated). */
static void store_lanes(const column_call* c, const column_place place[], const lane_grid* g,
                        size_t first, size_t count)
{
    const size_t stride = g->lanes->lanes;
    int* stored = g->stored;
    size_t k, lane;
    for (lane = 0; lane < count; ++lane) {
        stored[lane] = 1;
    }
    for (k = 0; k < c->n_x; ++k) {
        const ptrdiff_t step = c->x_step[k];
        const double* x = c->x[k] + (ptrdiff_t)first * step;
        const double low = place[k].low, high = place[k].high;
        double* at = g->to[k];
        copy_strided(at, 1, x, step, count);
        for (lane = 0; lane < count; ++lane) { /* in this form it vectorises */
            const double value = at[lane];
            stored[lane] = value >= low && value <= high ? stored[lane] : 0;
        }
        if (place[k].angle) {
            g->turn(at, at, at + stride, count);
        }
    }
}

/* Sample i's y values where the lanes do not hold them: NaN where its status is not ok, as
 * evaluate gave them where it was evaluated alone, and otherwise those of the columns that
 * do not come from the lanes. */
static void put_sample_aside(const column_call* c, const column_source source[], const lane_grid* g,
                             size_t i, fmu_status s, int alone)
{
    size_t k;
    for (k = 0; k < c->n_y; ++k) {
        if (s != FMU_OK || alone || g->from[k] == NULL) {
            c->y[k][(ptrdiff_t)i * c->y_step[k]] =
                s == FMU_OK ? source[k].at[(ptrdiff_t)i * source[k].step] : NAN;
        }
    }
}

/* How many samples from `first` on a block of at most `lanes` holds: 0 past the last. */
static size_t block_count(const column_call* c, size_t first, size_t lanes)
{
    return first < c->count ? (c->count - first < lanes ? c->count - first : lanes) : 0;
}

/* The contiguous columns' cache lines of the samples from `first` on, at most `lanes`,
 * asked of memory while the lanes compute earlier samples: each phase of a block (its
 * columns in, the lanes, its columns out) would otherwise wait for memory in turn (the
 * slider-crank at 1,000,000 samples: 8 to 20 % off the call, three runs). A strided
 * column's samples, the rows of a table say, are left to the processor, which follows
 * them as well (measured: no gain). */
static void fetch_block(const column_call* c, size_t first, size_t lanes)
{
#if defined(__GNUC__)
    const size_t line = 64 / sizeof(double);
    const size_t count = block_count(c, first, lanes);
    size_t k, lane;
    for (k = 0; k < c->n_x; ++k) {
        for (lane = 0; c->x_step[k] == 1 && lane < count; lane += line) {
            __builtin_prefetch(c->x[k] + first + lane, 0);
        }
    }
    for (k = 0; k < c->n_y; ++k) {
        for (lane = 0; c->y_step[k] == 1 && lane < count; lane += line) {
            __builtin_prefetch(c->y[k] + first + lane, 1);
        }
    }
#else
    (void)c;
    (void)first;
    (void)lanes;
#endif
}

/* 1 where each of the `count` lanes was stored and none failed a check: their statuses are
 * all OK, and a call whose y columns all come from the lanes has written them. */
static int lanes_all_ok(const lane_grid* g, const double* failed, size_t count)
{
    int stored = 1;
    long long passed = 1; /* as wide as a double: the loops vectorise without packing */
    size_t lane;
    for (lane = 0; lane < count; ++lane) {
        stored &= g->stored[lane];
    }
    for (lane = 0; lane < count; ++lane) {
        passed = failed[lane] == 0 ? passed : 0;
    }
    return stored && passed;
}

/* The samples from `first` on, at most a call's lanes: stored, evaluated at once, their
 * outputs copied column by column; those whose checks failed once more alone in the blocks. */
static void evaluate_lanes(const fmu_model* model, column_blocks* b, const column_call* c,
                           const column_place place[], const column_source source[],
                           const lane_grid* g, size_t first)
{
    const fmu_lanes* lanes = g->lanes;
    const size_t count = block_count(c, first, lanes->lanes);
    const double* failed = g->cells + (lanes->inputs + lanes->outputs) * lanes->lanes;
    size_t lane, k;
    store_lanes(c, place, g, first, count);
    fetch_block(c, first + 2 * lanes->lanes, lanes->lanes); /* the block after the next */
    g->evaluate(g->cap, count, g->cells, g->wanted);
    for (k = 0; k < c->n_y; ++k) {
        if (g->from[k] != NULL) {
            copy_strided(c->y[k] + (ptrdiff_t)first * c->y_step[k], c->y_step[k], g->from[k], 1,
                         count);
        }
    }
    if (!g->partial && lanes_all_ok(g, failed, count)) {
        for (lane = 0; lane < count; ++lane) {
            c->status[first + lane] = (int)FMU_OK;
        }
        return;
    }
    for (lane = 0; lane < count; ++lane) {
        const size_t i = first + lane;
        const int alone = g->stored[lane] && failed[lane] != 0;
        const fmu_status s = !g->stored[lane] ? FMU_ERROR
                             : alone          ? evaluate_lane_alone(model, b, g, lane)
                                              : FMU_OK;
        c->status[i] = (int)s;
        if (s != FMU_OK || alone || g->partial) {
            put_sample_aside(c, source, g, i, s, alone);
        }
    }
}

/* The widest lanes DYADFMU_LANES lets a call take: "baseline" or "avx2" (to measure each,
 * fmu/README.md), and otherwise ("avx512", unset or unknown: dyadfmu's Python refuses an
 * unknown value before the call) the widest. */
static dyad_lanes_isa lanes_cap(const char* which)
{
    if (which != NULL && strcmp(which, "baseline") == 0) {
        return DYAD_LANES_BASELINE;
    }
    if (which != NULL && strcmp(which, "avx2") == 0) {
        return DYAD_LANES_AVX2;
    }
    return DYAD_LANES_AVX512;
}

/* Every sample in the model's lanes: the start values into every lane once, then the
 * samples a call's lanes at a time. 0 where memory ran out. */
static int evaluate_samples_in_lanes(const fmu_model* model, column_blocks* b, const column_call* c,
                                     const column_place place[], const column_source source[])
{
    lane_grid g;
    size_t first, j, lane;
    int ready;
    const char* which = getenv("DYADFMU_LANES");
    g.lanes = model->behaviour->lanes;
    g.cap = lanes_cap(which);
    g.turn = turn_for(g.cap);
    g.cells = (double*)malloc(g.lanes->columns * g.lanes->lanes * sizeof(double));
    g.to = (double**)malloc((c->n_x + 1) * sizeof *g.to);
    g.from = (const double**)malloc((c->n_y + 1) * sizeof *g.from);
    g.wanted = (unsigned char*)malloc(g.lanes->outputs + 1);
    g.stored = (int*)malloc(g.lanes->lanes * sizeof(int));
    ready =
        g.cells != NULL && g.to != NULL && g.from != NULL && g.wanted != NULL && g.stored != NULL;
    if (ready) {
        for (j = 0; j < g.lanes->inputs; ++j) {
            for (lane = 0; lane < g.lanes->lanes; ++lane) {
                g.cells[j * g.lanes->lanes + lane] = ((const double*)b->input)[j];
            }
        }
        place_lanes(b, c, place, source, &g);
        g.halves =
            model->behaviour->later != NULL && g.lanes->first != NULL && !reads_later(model, c);
        g.evaluate = lanes_for(g.lanes, g.halves, g.wanted);
        for (first = 0; first < c->count; first += g.lanes->lanes) {
            evaluate_lanes(model, b, c, place, source, &g, first);
        }
    }
    free(g.cells);
    free(g.to);
    free(g.from);
    free(g.wanted);
    free(g.stored);
    return ready;
}

fmu_status fmu_evaluate_columns(const fmu_model* model, const char* token, int time_at_vr_0,
                                const unsigned int vr_x[], size_t n_x, const double* const x[],
                                const ptrdiff_t x_step[], const unsigned int vr_y[], size_t n_y,
                                double* const y[], const ptrdiff_t y_step[], int status[],
                                size_t count)
{
    const column_call c = {vr_x, n_x, x, x_step, vr_y, n_y, y, y_step, status, count};
    column_blocks b;
    column_place* place;
    column_source* source;
    int ready;
    (void)time_at_vr_0; /* value reference 0 is no Real of the table: refused either way */
    if (!columns_valid(model, &c)) {
        return FMU_ERROR;
    }
    if (token == NULL || strcmp(token, model->token) != 0) {
        return FMU_FATAL; /* as an instance would not be made */
    }
    b.input = calloc(1, model->behaviour->input_size + 1);
    b.output = calloc(1, model->behaviour->output_size + 1);
    place = (column_place*)malloc((n_x + 1) * sizeof *place);
    source = (column_source*)malloc((n_y + 1) * sizeof *source);
    ready = b.input != NULL && b.output != NULL && place != NULL && source != NULL;
    if (ready) {
        load_starts(model, b.input);
        place_columns(model, &b, &c, place);
        find_sources(model, &b, &c, source);
        if (model->behaviour->lanes != NULL) {
            ready = evaluate_samples_in_lanes(model, &b, &c, place, source);
        } else {
            evaluate_samples(model, &b, &c, place, source);
        }
    }
    free(place);
    free(source);
    free(b.output);
    free(b.input);
    return ready ? FMU_OK : FMU_FATAL;
}

int fmu_variable_named(const fmu_model* model, const char* name)
{
    size_t k;
    for (k = 0; k < model->variable_count; ++k) {
        if (strcmp(model->variables[k].name, name) == 0) {
            return (int)k;
        }
    }
    return -1;
}
