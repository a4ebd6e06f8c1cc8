/* dyadfmu FMU layer: the version-neutral instance (see fmu_instance.h). */
#include "fmu_instance.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
};

/* Parameters (fixed) may change only while these hold. */
enum { PARAMETER_STATES = FMU_STATE_INSTANTIATED | FMU_STATE_INITIALIZATION };

const char* const fmu_log_category_names[] = {"logStatusError", "logStatusWarning",
                                              "logStatusDiscard", "logCalls"};
const size_t fmu_log_category_count =
    sizeof fmu_log_category_names / sizeof fmu_log_category_names[0];
enum { LOG_ERROR = 0, LOG_WARNING, LOG_DISCARD, LOG_CALLS };

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
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void log_to(const fmu_logger* logger, fmu_status status, const char* format, ...)
{
    va_list args;
    va_start(args, format);
    emit(logger, 0, status, format, args);
    va_end(args);
}

/* Stores a value as set and where the solver reads it (an angle as its unit
 * vector), so that a solve needs no pass over the variables. */
static void store(fmu_instance* instance, size_t index, double value)
{
    const fmu_variable* v = &instance->model->variables[index];
    double* member = (double*)(void*)((char*)instance->input + v->offset);
    instance->values[index] = value;
    if (v->target == FMU_TARGET_INPUT_ANGLE) {
        member[0] = cos(value);
        member[1] = sin(value);
    } else if (v->target == FMU_TARGET_INPUT_REAL) {
        member[0] = value;
    }
}

/* Sizes rounded up so that every block is aligned for any scalar. */
static size_t round_up(size_t size)
{
    const size_t unit = 16;
    return (size + unit - 1) / unit * unit;
}

static void load_start_values(fmu_instance* instance)
{
    size_t k;
    instance->model->behaviour->initialise(instance->model, instance->input);
    for (k = 0; k < instance->model->variable_count; ++k) {
        store(instance, k, instance->model->variables[k].start);
    }
    if (instance->model->behaviour->start != NULL) {
        instance->model->behaviour->start(instance->model, instance->input);
    }
    instance->state = FMU_STATE_INSTANTIATED;
    instance->time = 0;
    instance->last_successful_time = 0;
    instance->terminate_requested = 0;
    instance->dirty = 1;
}

fmu_instance* fmu_instantiate(const fmu_model* model, const char* instance_name, const char* token,
                              fmu_logger logger, int logging_on, fmu_allocate allocate,
                              fmu_release release)
{
    fmu_instance* instance;
    size_t values_size, name_size, input_size, output_size;
    char *block, *name;

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
    values_size = model->variable_count * sizeof(double);
    name_size = strlen(instance_name) + 1;
    input_size = round_up(model->behaviour->input_size);
    output_size = round_up(model->behaviour->output_size);
    instance = (fmu_instance*)allocate(1, round_up(sizeof(fmu_instance)) + values_size +
                                              2 * input_size + 3 * output_size + name_size);
    if (instance == NULL) {
        log_to(&logger, FMU_ERROR, "instantiate: out of memory");
        return NULL;
    }
    block = (char*)instance + round_up(sizeof(fmu_instance));
    instance->values = (double*)(void*)block;
    block += values_size;
    instance->input = block;
    instance->seed = block + input_size;
    block += 2 * input_size;
    instance->output = block;
    instance->value = block + output_size;
    instance->rate = block + 2 * output_size;
    name = block + 3 * output_size;
    memcpy(name, instance_name, name_size);

    instance->model = model;
    instance->logger = logger;
    instance->logger.instance_name = name;
    instance->release = release;
    instance->log_categories = logging_on ? ~0u : 0u;
    load_start_values(instance);
    fmu_log(instance, FMU_OK, "instantiated %s", model->identifier);
    return instance;
}

void fmu_free(fmu_instance* instance)
{
    if (instance != NULL) {
        instance->release(instance);
    }
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
    fmu_log(instance, FMU_OK, "%s", function);
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
    return FMU_OK;
}

fmu_status fmu_setup_experiment(fmu_instance* instance, double start_time)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_SETUP_EXPERIMENT, "setupExperiment");
    if (status == FMU_OK) {
        instance->time = start_time;
        instance->last_successful_time = start_time;
    }
    return status;
}

/* ---- the solve ------------------------------------------------------------------------------ */

/* Logs why the last evaluation failed. */
static void log_failure(fmu_instance* instance, fmu_status not_solvable, const char* function)
{
    const fmu_evaluation* e = &instance->evaluation;
    if (e->status == FMU_ERROR && e->bad_variable >= 0) {
        fmu_log(instance, FMU_ERROR, "%s: %s = %g: %s", function,
                instance->model->variables[e->bad_variable].name, instance->values[e->bad_variable],
                e->reason);
    } else if (e->status != FMU_OK) {
        fmu_log(instance, e->status == FMU_ERROR ? FMU_ERROR : not_solvable, "%s: at t = %g s: %s",
                function, instance->time, e->reason);
    }
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
        instance->model->behaviour->evaluate(instance->model, instance->input, instance->output, e);
        instance->dirty = 0;
        log_failure(instance, not_solvable, function);
    } else if (e->status == FMU_ERROR && each_error) {
        log_failure(instance, not_solvable, function);
    }
    if (e->status == FMU_OK || e->status == FMU_ERROR) {
        return e->status;
    }
    return not_solvable;
}

/* ---- the state machine ---------------------------------------------------------------------- */

fmu_status fmu_enter_initialization(fmu_instance* instance, double start_time)
{
    fmu_status status =
        fmu_check_call(instance, FMU_OP_ENTER_INITIALIZATION, "enterInitializationMode");
    if (status == FMU_OK) {
        instance->state = FMU_STATE_INITIALIZATION;
        instance->time = start_time;
        instance->last_successful_time = start_time;
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
        instance->state = FMU_STATE_STEP;
    }
    return status;
}

/* Refuses a step whose size is not positive or whose end is not a later finite
 * time: a sum that overflows would leave the instance at an infinite time, one
 * below the resolution of double at current_time would advance the states but
 * not the time. */
static fmu_status check_step(fmu_instance* instance, double current_time, double step_size,
                             const char* function)
{
    if (!isfinite(current_time) || !isfinite(step_size) || !(step_size > 0)) {
        fmu_log(instance, FMU_ERROR,
                "%s: currentCommunicationPoint = %g s and communicationStepSize = %g s: the "
                "step size must be positive and both finite",
                function, current_time, step_size);
        return FMU_ERROR;
    }
    if (!isfinite(current_time + step_size) || !(current_time + step_size > current_time)) {
        fmu_log(instance, FMU_ERROR,
                "%s: currentCommunicationPoint = %.17g s + communicationStepSize = %.17g s "
                "= %.17g s is not a finite time after the current one",
                function, current_time, step_size, current_time + step_size);
        return FMU_ERROR;
    }
    return FMU_OK;
}

/* A step of a model with states: the outputs at its start, the states
 * advanced, the outputs at its end. */
static fmu_status advance_states(fmu_instance* instance, double current_time, double step_size,
                                 const char* function)
{
    fmu_status status = solve(instance, FMU_DISCARD, function, 1);
    if (status == FMU_OK) {
        fmu_evaluation* e = &instance->evaluation;
        instance->model->behaviour->advance(instance->model, instance->input, step_size, e);
        instance->dirty = 1;
        if (e->status == FMU_ERROR) {
            /* A step the model refuses (it left its states as they were). */
            fmu_log(instance, FMU_ERROR, "%s: at t = %g s: %s", function, current_time, e->reason);
            return FMU_ERROR;
        }
        if (e->status != FMU_OK) {
            fmu_log(instance, FMU_DISCARD, "%s: at t = %g s: %s", function, current_time,
                    e->reason);
            instance->last_successful_time = current_time;
            instance->terminate_requested = 1;
            return FMU_DISCARD;
        }
        instance->time = current_time + step_size;
        status = solve(instance, FMU_DISCARD, function, 1);
        if (status == FMU_OK) {
            instance->last_successful_time = instance->time;
            instance->terminate_requested = 0;
            return FMU_OK;
        }
    }
    instance->last_successful_time = current_time;
    instance->terminate_requested = status == FMU_DISCARD;
    return status;
}

fmu_status fmu_do_step(fmu_instance* instance, double current_time, double step_size,
                       const char* function)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_DO_STEP, function);
    if (status != FMU_OK) {
        return status;
    }
    if (check_step(instance, current_time, step_size, function) != FMU_OK) {
        return FMU_ERROR;
    }
    instance->time = current_time;
    if (instance->model->behaviour->advance != NULL) {
        return advance_states(instance, current_time, step_size, function);
    }
    status = solve(instance, FMU_DISCARD, function, 1);
    if (status == FMU_OK) {
        instance->time = current_time + step_size;
        instance->last_successful_time = instance->time;
        instance->terminate_requested = 0;
    } else if (status == FMU_DISCARD) {
        instance->last_successful_time = current_time;
        instance->terminate_requested = 1;
    }
    return status;
}

fmu_status fmu_terminate(fmu_instance* instance)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_TERMINATE, "terminate");
    if (status == FMU_OK) {
        instance->state = FMU_STATE_TERMINATED;
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
    return type == FMU_REAL ? "Real" : "Integer";
}

/* The variable of a value reference of the given type, or NULL with a logged error. */
static const fmu_variable* lookup(const fmu_instance* instance, unsigned int vr,
                                  fmu_value_type type, const char* function)
{
    const fmu_model* model = instance->model;
    const fmu_variable* v;
    if (vr >= model->vr_limit || model->index_of_vr[vr] < 0) {
        fmu_log(instance, FMU_ERROR, "%s: unknown value reference %u", function, vr);
        return NULL;
    }
    v = &model->variables[model->index_of_vr[vr]];
    if (v->type != type) {
        fmu_log(instance, FMU_ERROR, "%s: value reference %u (%s) is of type %s, not %s", function,
                vr, v->name, type_name(v->type), type_name(type));
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

/* Whether a value may be stored in v now; logs the reason if not. */
static fmu_status check_settable(const fmu_instance* instance, const fmu_variable* v, double value,
                                 const char* function)
{
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
    if (!isfinite(value)) {
        fmu_log(instance, FMU_ERROR, "%s: %s = %g is not a finite number", function, v->name,
                value);
        return FMU_ERROR;
    }
    if ((v->bounds & FMU_HAS_MIN) &&
        ((v->bounds & FMU_MIN_EXCLUSIVE) ? !(value > v->min) : !(value >= v->min))) {
        fmu_log(instance, FMU_ERROR, "%s: %s = %g %s: it must be %s %g", function, v->name, value,
                v->unit, (v->bounds & FMU_MIN_EXCLUSIVE) ? ">" : ">=", v->min);
        return FMU_ERROR;
    }
    if ((v->bounds & FMU_HAS_MAX) &&
        ((v->bounds & FMU_MAX_EXCLUSIVE) ? !(value < v->max) : !(value <= v->max))) {
        fmu_log(instance, FMU_ERROR, "%s: %s = %g %s: it must be %s %g", function, v->name, value,
                v->unit, (v->bounds & FMU_MAX_EXCLUSIVE) ? "<" : "<=", v->max);
        return FMU_ERROR;
    }
    return FMU_OK;
}

/* The importer's arrays are double (Real) or int (Integer); the store is double. */
static double value_at(const void* values, fmu_value_type type, size_t k)
{
    return type == FMU_REAL ? ((const double*)values)[k] : (double)((const int*)values)[k];
}

static void store_at(void* values, fmu_value_type type, size_t k, double value)
{
    if (type == FMU_REAL) {
        ((double*)values)[k] = value;
    } else {
        ((int*)values)[k] = (int)value;
    }
}

static fmu_status set_values(fmu_instance* instance, const unsigned int vr[], size_t count,
                             const void* values, fmu_value_type type, const char* function)
{
    size_t k;
    fmu_status status = fmu_check_call(instance, FMU_OP_SET, function);
    if (status != FMU_OK || check_arrays(instance, vr, count, values, function) != FMU_OK) {
        return FMU_ERROR;
    }
    /* All values are checked before any is stored: a rejected call changes nothing. */
    for (k = 0; k < count; ++k) {
        const fmu_variable* v = lookup(instance, vr[k], type, function);
        if (v == NULL ||
            check_settable(instance, v, value_at(values, type, k), function) != FMU_OK) {
            return FMU_ERROR;
        }
    }
    for (k = 0; k < count; ++k) {
        store(instance, (size_t)instance->model->index_of_vr[vr[k]], value_at(values, type, k));
    }
    if (count > 0) {
        instance->dirty = 1;
        /* Until initialization ends, the states follow their start parameters. */
        if (instance->model->behaviour->start != NULL &&
            ((unsigned)instance->state & PARAMETER_STATES)) {
            instance->model->behaviour->start(instance->model, instance->input);
        }
    }
    return FMU_OK;
}

/* The value of a variable as a double; an output as of the last evaluation. */
static double read_variable(const fmu_instance* instance, const fmu_variable* v)
{
    const char* member = (const char*)instance->output + v->offset;
    if (v->causality != FMU_OUTPUT) {
        return instance->values[v - instance->model->variables];
    }
    if (v->target == FMU_TARGET_RESULT_STATUS) {
        return (double)*(const int*)(const void*)member;
    }
    return *(const double*)(const void*)member;
}

/* Reads the values, solving once before the first output. Returns FMU_ERROR
 * for a value reference that is not of `type`; otherwise, if `solve_counts`,
 * the status of that solve (a failed one as FMU_WARNING), else FMU_OK. */
static fmu_status get_values(fmu_instance* instance, const unsigned int vr[], size_t count,
                             void* values, fmu_value_type type, int solve_counts,
                             const char* function)
{
    fmu_status worst = FMU_OK;
    int solved = 0;
    size_t k;
    fmu_status status = fmu_check_call(instance, FMU_OP_GET, function);
    if (status != FMU_OK || check_arrays(instance, vr, count, values, function) != FMU_OK) {
        return FMU_ERROR;
    }
    for (k = 0; k < count; ++k) {
        const fmu_variable* v = lookup(instance, vr[k], type, function);
        if (v == NULL) {
            return FMU_ERROR;
        }
        if (v->causality == FMU_OUTPUT && !solved) {
            const fmu_status solved_status = solve(instance, FMU_WARNING, function, solve_counts);
            worst = solve_counts ? solved_status : FMU_OK;
            solved = 1;
        }
        store_at(values, type, k, read_variable(instance, v));
    }
    return worst;
}

fmu_status fmu_set_real(fmu_instance* instance, const unsigned int vr[], size_t count,
                        const double values[], const char* function)
{
    return set_values(instance, vr, count, values, FMU_REAL, function);
}

fmu_status fmu_set_integer(fmu_instance* instance, const unsigned int vr[], size_t count,
                           const int values[], const char* function)
{
    return set_values(instance, vr, count, values, FMU_INTEGER, function);
}

fmu_status fmu_get_real(fmu_instance* instance, const unsigned int vr[], size_t count,
                        double values[], const char* function)
{
    return get_values(instance, vr, count, values, FMU_REAL, 1, function);
}

fmu_status fmu_get_integer(fmu_instance* instance, const unsigned int vr[], size_t count,
                           int values[], const char* function)
{
    /* The status output is how the model reports a singular configuration or
     * a rejected input (logged when it was evaluated): reading it succeeds
     * whatever it says. */
    return get_values(instance, vr, count, values, FMU_INTEGER, 0, function);
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
        const fmu_variable* v = lookup(instance, knowns[k], FMU_REAL, function);
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
        const fmu_variable* v = lookup(instance, unknowns[k], FMU_REAL, function);
        if (v == NULL) {
            return FMU_ERROR;
        }
        if (v->causality != FMU_OUTPUT) {
            fmu_log(instance, FMU_ERROR, "%s: unknown %s is not an output", function, v->name);
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
    if (seed_knowns(instance, knowns, n_knowns, seed, function) != FMU_OK ||
        check_unknowns(instance, unknowns, n_unknowns, function) != FMU_OK) {
        return FMU_ERROR;
    }
    behaviour->derivative(instance->model, instance->input, instance->seed, instance->value,
                          instance->rate, &evaluation);
    if (evaluation.status != FMU_OK) {
        fmu_log(instance, FMU_DISCARD, "%s: no derivative where the outputs are not defined: %s",
                function, evaluation.reason);
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
