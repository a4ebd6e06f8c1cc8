/* dyadfmu FMU layer: FMU state (canGetAndSetFMUState, canSerializeFMUState), the
 * same for FMI 2 and FMI 3.
 *
 * A state holds what the FMU cannot compute again and nothing it can: the state
 * machine's state, the time and the last successful time, the terminate flag, the
 * value of every parameter, input and setting as set, and the model's own states (the
 * drive's crank angle and speed: fmu_behaviour.states). The outputs, the evaluation
 * and the angles' unit vectors are not kept: a restored instance evaluates again
 * before its outputs are read, so that no byte of a state can make an output disagree
 * with its inputs. A saved state is the serialized form itself, so that get, set,
 * serialize and deserialize are one format and two copies:
 *
 *   magic "dyadfmu\0" | fingerprint | size | checksum | payload
 *
 * and the payload is 8-byte fields: the state machine's state (int64), the time and
 * the last successful time (double, s), the terminate flag (int64), one double per
 * parameter, input and setting in the order of the variable table, one per model
 * state, one per first derivative of an input the model interpolates (canInterpolateInputs:
 * a rate, like a value, holds until set again). The fingerprint is of the model (its instantiation
 * token), of this format's version and of the counts of the fields, so that a state of another FMU,
 * of another build or of an older format is refused; the checksum (FNV-1a over the payload) refuses
 * a damaged one: it guards against accidents, not against a crafted state. That is what the checks
 * of every field are for, each as a setter or a step would check it, so that a state holds only
 * what calls could have left: a value a setter would accept, times that are finite and ordered as
 * steps leave them, one of the four states of the machine, model states a start or step could
 * leave. A refused state names its field. The saved states of an instance are kept in a list and
 * freed with it. */
#include <inttypes.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "dyadfmu/angle.h"
#include "fmu_instance.h"

struct fmu_saved {
    fmu_saved* next; /* the instance's other saved states */
    size_t size;     /* of bytes */
    unsigned char bytes[];
};

enum { HEADER_SIZE = 32, FIELD_SIZE = 8 };
/* The fields of the payload before the values, in order. */
enum { AT_MACHINE = 0, AT_TIME, AT_LAST_TIME, AT_TERMINATE, AT_VALUES };
/* The format of the payload; a state of another format is refused by its fingerprint. */
enum { FORMAT_VERSION = 3 };
/* The machine's states before initialization ends: the model's states follow their
 * start values, and no step was taken. */
enum { BEFORE_STEPS = FMU_STATE_INSTANTIATED | FMU_STATE_INITIALIZATION };
static const char magic[8] = "dyadfmu";

static uint64_t fnv1a(uint64_t h, const void* data, size_t size)
{
    const unsigned char* p = (const unsigned char*)data;
    size_t k;
    for (k = 0; k < size; ++k) {
        h = (h ^ p[k]) * 0x100000001b3ULL;
    }
    return h;
}

/* The number of parameters, inputs and settings: the variables that are not outputs. */
static size_t kept_count(const fmu_model* m)
{
    size_t k, count = 0;
    for (k = 0; k < m->variable_count; ++k) {
        count += m->variables[k].causality != FMU_OUTPUT;
    }
    return count;
}

static size_t model_state_count(const fmu_model* m)
{
    return m->behaviour->states != NULL ? m->behaviour->states->count : 0;
}

/* The inputs whose first derivatives the model keeps (fmu_behaviour.interpolation). */
static size_t input_rate_count(const fmu_model* m)
{
    return m->behaviour->interpolation != NULL ? m->behaviour->interpolation->input_count : 0;
}

static uint64_t fingerprint(const fmu_model* m)
{
    const uint64_t counts[5] = {FORMAT_VERSION, m->variable_count, kept_count(m),
                                model_state_count(m), input_rate_count(m)};
    uint64_t h = fnv1a(0xcbf29ce484222325ULL, m->token, strlen(m->token));
    return fnv1a(h, counts, sizeof counts);
}

static size_t state_size(const fmu_model* m)
{
    return HEADER_SIZE +
           FIELD_SIZE * (AT_VALUES + kept_count(m) + model_state_count(m) + input_rate_count(m));
}

/* The fields of a payload, which need not be aligned. */
static double real_at(const unsigned char* payload, size_t field)
{
    double x;
    memcpy(&x, payload + FIELD_SIZE * field, sizeof x);
    return x;
}

static int64_t integer_at(const unsigned char* payload, size_t field)
{
    int64_t x;
    memcpy(&x, payload + FIELD_SIZE * field, sizeof x);
    return x;
}

static void put_real(unsigned char* payload, size_t field, double x)
{
    memcpy(payload + FIELD_SIZE * field, &x, sizeof x);
}

static void put_integer(unsigned char* payload, size_t field, int64_t x)
{
    memcpy(payload + FIELD_SIZE * field, &x, sizeof x);
}

/* The double at `offset` of a block. */
static double* block_real(void* block, size_t offset)
{
    return (double*)(void*)((char*)block + offset);
}

/* The instance's state into bytes (of state_size). */
static void write_state(fmu_instance* instance, unsigned char* bytes)
{
    const fmu_model* m = instance->model;
    const fmu_states* states = m->behaviour->states;
    unsigned char* payload = bytes + HEADER_SIZE;
    const uint64_t print = fingerprint(m), size = state_size(m);
    size_t k, field = AT_VALUES;
    uint64_t check;
    put_integer(payload, AT_MACHINE, (int64_t)instance->state);
    put_real(payload, AT_TIME, instance->time);
    put_real(payload, AT_LAST_TIME, instance->last_successful_time);
    put_integer(payload, AT_TERMINATE, instance->terminate_requested);
    for (k = 0; k < m->variable_count; ++k) {
        if (m->variables[k].causality != FMU_OUTPUT) {
            put_real(payload, field++, *fmu_kept_value(instance, k));
        }
    }
    for (k = 0; k < model_state_count(m); ++k) {
        put_real(payload, field++, *block_real(instance->input, states->states[k].offset));
    }
    for (k = 0; k < input_rate_count(m); ++k) {
        const size_t at = m->behaviour->interpolation->inputs[k].rate_offset;
        put_real(payload, field++, *block_real(instance->input, at));
    }
    check = fnv1a(0xcbf29ce484222325ULL, payload, (size_t)size - HEADER_SIZE);
    memcpy(bytes, magic, 8);
    memcpy(bytes + 8, &print, 8);
    memcpy(bytes + 16, &size, 8);
    memcpy(bytes + 24, &check, 8);
}

/* Why `bytes` is not a state of this FMU as a whole, or NULL. */
static const char* header_problem(const fmu_model* m, const unsigned char* bytes, size_t size)
{
    uint64_t print, stored_size, check;
    if (size < HEADER_SIZE || memcmp(bytes, magic, 8) != 0) {
        return "not an FMU state of dyadfmu";
    }
    memcpy(&print, bytes + 8, 8);
    memcpy(&stored_size, bytes + 16, 8);
    memcpy(&check, bytes + 24, 8);
    if (print != fingerprint(m) || stored_size != state_size(m) || size != stored_size) {
        return "a state of another FMU, or of another build or format of this one";
    }
    if (check != fnv1a(0xcbf29ce484222325ULL, bytes + HEADER_SIZE, size - HEADER_SIZE)) {
        return "a damaged state (its checksum does not match)";
    }
    return NULL;
}

/* Why the state machine's state is none of its four; 0 if it is one. */
static int machine_refused(int64_t machine, char* why, size_t size)
{
    if (machine == FMU_STATE_INSTANTIATED || machine == FMU_STATE_INITIALIZATION ||
        machine == FMU_STATE_STEP || machine == FMU_STATE_TERMINATED) {
        return 0;
    }
    snprintf(why, size,
             "the state machine's state = %" PRId64 " is none of 1 (Instantiated), 2 "
             "(Initialization Mode), 4 (Step Mode), 8 (Terminated)",
             machine);
    return 1;
}

/* Why the times and the terminate flag are not as calls leave them, 0 if they are: both
 * times finite; where the last step was not discarded (the flag 0, as before any step)
 * the last successful time is the time, else no later. */
static int times_refused(const unsigned char* payload, char* why, size_t size)
{
    const double time = real_at(payload, AT_TIME), last = real_at(payload, AT_LAST_TIME);
    const int64_t machine = integer_at(payload, AT_MACHINE);
    const int64_t terminate = integer_at(payload, AT_TERMINATE);
    if (!isfinite(time) || !isfinite(last)) {
        snprintf(why, size, "%s = %g s is not a finite time",
                 isfinite(time) ? "last successful time" : "time", isfinite(time) ? last : time);
        return 1;
    }
    if (terminate != 0 && (terminate != 1 || (machine & BEFORE_STEPS))) {
        snprintf(why, size, "the terminate flag = %" PRId64 " is not %s", terminate,
                 (machine & BEFORE_STEPS) ? "0 before any step" : "0 or 1");
        return 1;
    }
    if (terminate == 0 && last != time) {
        snprintf(why, size,
                 "last successful time = %.17g s differs from time = %.17g s, but the "
                 "terminate flag = 0 says no step was discarded",
                 last, time);
        return 1;
    }
    if (!(last <= time)) {
        snprintf(why, size, "last successful time = %.17g s is after time = %.17g s", last, time);
        return 1;
    }
    return 0;
}

/* Why a parameter, input or setting holds a value no setter would accept, naming it;
 * 0 if each holds one. */
static int values_refused(const fmu_model* m, const unsigned char* payload, char* why, size_t size)
{
    size_t k, field = AT_VALUES;
    for (k = 0; k < m->variable_count; ++k) {
        const fmu_variable* v = &m->variables[k];
        if (v->causality != FMU_OUTPUT &&
            fmu_value_refused(v, real_at(payload, field++), why, size)) {
            return 1;
        }
    }
    return 0;
}

/* The input block of the state's values (checked) in `block`: initialised, each value
 * where the model reads it, an angle as its unit vector. */
static void build_block(const fmu_model* m, const unsigned char* payload, void* block)
{
    size_t k, field = AT_VALUES;
    m->behaviour->initialise(m, block);
    for (k = 0; k < m->variable_count; ++k) {
        const fmu_variable* v = &m->variables[k];
        if (v->causality == FMU_OUTPUT) {
            continue;
        }
        if (v->target == FMU_TARGET_INPUT_REAL) {
            *block_real(block, v->offset) = real_at(payload, field);
        } else if (v->target == FMU_TARGET_INPUT_ANGLE) {
            double* unit = block_real(block, v->offset);
            dyad_cos_sin(real_at(payload, field), &unit[0], &unit[1]);
        }
        ++field;
    }
}

/* Why a model state is not one the model's start (before initialization ends) or a
 * step could leave, naming it; 0 if none. `block`: scratch of the input block's size. */
static int model_states_refused(const fmu_model* m, const unsigned char* payload, void* block,
                                char* why, size_t size)
{
    const fmu_states* states = m->behaviour->states;
    const size_t first = AT_VALUES + kept_count(m);
    size_t k;
    int bad = -1;
    if (states == NULL) {
        return 0;
    }
    build_block(m, payload, block);
    if ((integer_at(payload, AT_MACHINE) & BEFORE_STEPS) && m->behaviour->start != NULL) {
        m->behaviour->start(m, block);
        for (k = 0; k < states->count && bad < 0; ++k) {
            const double kept = real_at(payload, first + k);
            bad = memcmp(&kept, block_real(block, states->states[k].offset), sizeof kept) != 0
                      ? (int)k
                      : -1;
        }
    } else {
        for (k = 0; k < states->count; ++k) {
            *block_real(block, states->states[k].offset) = real_at(payload, first + k);
        }
        bad = states->refused != NULL ? states->refused(m, block) : -1;
    }
    if (bad >= 0) {
        const fmu_model_state* s = &states->states[bad];
        snprintf(why, size, "%s = %g%s%s is not a state %s could leave", s->name,
                 real_at(payload, first + (size_t)bad), s->unit[0] != '\0' ? " " : "", s->unit,
                 (integer_at(payload, AT_MACHINE) & BEFORE_STEPS)
                     ? "its start values before initialization ends"
                     : "a step");
    }
    return bad >= 0;
}

/* Why an input's first derivative is not one its setter would accept (finite), naming
 * the input; 0 if none. FMI 3 (the time at value reference 0) sets no input derivatives:
 * there they are 0. */
static int input_rates_refused(const fmu_model* m, const unsigned char* payload, int fmi3,
                               char* why, size_t size)
{
    const size_t first = AT_VALUES + kept_count(m) + model_state_count(m);
    size_t k, j;
    for (k = 0; k < input_rate_count(m); ++k) {
        const double rate = real_at(payload, first + k);
        const size_t at = m->behaviour->interpolation->inputs[k].value_offset;
        if (isfinite(rate) && (rate == 0 || !fmi3)) {
            continue;
        }
        for (j = 0; j < m->variable_count; ++j) {
            const fmu_variable* v = &m->variables[j];
            if (v->causality == FMU_INPUT && v->target == FMU_TARGET_INPUT_REAL &&
                v->offset == at) {
                snprintf(why, size, "the derivative of %s = %g %s/s is %s", v->name, rate, v->unit,
                         isfinite(rate) ? "not 0 (FMI 3 sets no input derivatives)" : "not finite");
                return 1;
            }
        }
        snprintf(why, size, "the derivative of input %zu = %g cannot be set", k, rate);
        return 1;
    }
    return 0;
}

/* Why `bytes` is not a state this instance's FMU could be in, naming the field, into
 * `why`; 0 if it is one. */
static int state_refused(fmu_instance* instance, const unsigned char* bytes, size_t size, char* why,
                         size_t why_size)
{
    const fmu_model* m = instance->model;
    const unsigned char* payload = bytes + HEADER_SIZE;
    const char* problem = header_problem(m, bytes, size);
    if (problem != NULL) {
        snprintf(why, why_size, "%s", problem);
        return 1;
    }
    /* the scratch of directional derivatives, which set it before each use */
    return machine_refused(integer_at(payload, AT_MACHINE), why, why_size) ||
           times_refused(payload, why, why_size) || values_refused(m, payload, why, why_size) ||
           model_states_refused(m, payload, instance->seed, why, why_size) ||
           input_rates_refused(m, payload, instance->time_at_vr_0, why, why_size);
}

/* The state's bytes (checked by state_refused) into the instance: the input block
 * initialised, every value stored as a set stores it, the model's states, and every
 * output to be evaluated again. */
static void read_state(fmu_instance* instance, const unsigned char* bytes)
{
    const fmu_model* m = instance->model;
    const fmu_states* states = m->behaviour->states;
    const unsigned char* payload = bytes + HEADER_SIZE;
    size_t k, field = AT_VALUES;
    m->behaviour->initialise(m, instance->input);
    for (k = 0; k < m->variable_count; ++k) {
        if (m->variables[k].causality != FMU_OUTPUT) {
            *fmu_kept_value(instance, k) = real_at(payload, field++);
        }
    }
    for (k = 0; k < model_state_count(m); ++k) {
        *block_real(instance->input, states->states[k].offset) = real_at(payload, field++);
    }
    for (k = 0; k < input_rate_count(m); ++k) {
        const size_t at = m->behaviour->interpolation->inputs[k].rate_offset;
        *block_real(instance->input, at) = real_at(payload, field++);
    }
    instance->time = real_at(payload, AT_TIME);
    instance->last_successful_time = real_at(payload, AT_LAST_TIME);
    instance->terminate_requested = (int)integer_at(payload, AT_TERMINATE);
    fmu_restored(instance, (fmu_state)integer_at(payload, AT_MACHINE));
}

static fmu_saved* new_saved(fmu_instance* instance, size_t size)
{
    fmu_saved* saved = (fmu_saved*)instance->allocate(1, sizeof(fmu_saved) + size);
    if (saved != NULL) {
        saved->size = size;
        saved->next = instance->saved;
        instance->saved = saved;
    }
    return saved;
}

/* 1 if `saved` is one of the instance's saved states. */
static int owns(const fmu_instance* instance, const fmu_saved* saved)
{
    const fmu_saved* s;
    for (s = instance->saved; s != NULL; s = s->next) {
        if (s == saved) {
            return 1;
        }
    }
    return 0;
}

static fmu_status unknown_state(fmu_instance* instance, const char* function)
{
    fmu_log(instance, FMU_ERROR, "%s: the FMU state is NULL or not one of this instance's",
            function);
    return FMU_ERROR;
}

fmu_status fmu_get_state(fmu_instance* instance, fmu_saved** state, const char* function)
{
    const size_t size = instance != NULL ? state_size(instance->model) : 0;
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK) {
        return status;
    }
    if (state == NULL) {
        fmu_log(instance, FMU_ERROR, "%s: the pointer to the FMU state is NULL", function);
        return FMU_ERROR;
    }
    if (*state != NULL && (!owns(instance, *state) || (*state)->size != size)) {
        return unknown_state(instance, function);
    }
    if (*state == NULL && (*state = new_saved(instance, size)) == NULL) {
        fmu_log(instance, FMU_ERROR, "%s: out of memory", function);
        return FMU_ERROR;
    }
    write_state(instance, (*state)->bytes);
    return FMU_OK;
}

fmu_status fmu_set_state(fmu_instance* instance, const fmu_saved* state, const char* function)
{
    char why[300];
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK) {
        return status;
    }
    if (state == NULL || !owns(instance, state)) {
        return unknown_state(instance, function);
    }
    /* checked when it was deserialized; again, since nothing a state holds is trusted */
    if (state_refused(instance, state->bytes, state->size, why, sizeof why)) {
        fmu_log(instance, FMU_ERROR, "%s: refused: %s", function, why);
        return FMU_ERROR;
    }
    read_state(instance, state->bytes);
    return FMU_OK;
}

fmu_status fmu_free_state(fmu_instance* instance, fmu_saved** state, const char* function)
{
    fmu_saved** link;
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK || state == NULL || *state == NULL) {
        return status; /* freeing NULL is nothing */
    }
    for (link = &instance->saved; *link != NULL; link = &(*link)->next) {
        if (*link == *state) {
            *link = (*state)->next;
            instance->release(*state);
            *state = NULL;
            return FMU_OK;
        }
    }
    return unknown_state(instance, function);
}

void fmu_free_states(fmu_instance* instance)
{
    while (instance->saved != NULL) {
        fmu_saved* next = instance->saved->next;
        instance->release(instance->saved);
        instance->saved = next;
    }
}

fmu_status fmu_serialized_state_size(fmu_instance* instance, const fmu_saved* state, size_t* size,
                                     const char* function)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK) {
        return status;
    }
    if (state == NULL || !owns(instance, state) || size == NULL) {
        return unknown_state(instance, function);
    }
    *size = state->size;
    return FMU_OK;
}

fmu_status fmu_serialize_state(fmu_instance* instance, const fmu_saved* state, unsigned char* bytes,
                               size_t size, const char* function)
{
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK) {
        return status;
    }
    if (state == NULL || !owns(instance, state)) {
        return unknown_state(instance, function);
    }
    if (bytes == NULL || size < state->size) {
        fmu_log(instance, FMU_ERROR, "%s: the serialized state needs %lu bytes, the array has %lu",
                function, (unsigned long)state->size, (unsigned long)(bytes != NULL ? size : 0));
        return FMU_ERROR;
    }
    memcpy(bytes, state->bytes, state->size);
    return FMU_OK;
}

fmu_status fmu_deserialize_state(fmu_instance* instance, const unsigned char* bytes, size_t size,
                                 fmu_saved** state, const char* function)
{
    char why[300];
    fmu_saved* saved = NULL;
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK) {
        return status;
    }
    if (bytes == NULL || state == NULL) {
        snprintf(why, sizeof why, "NULL arguments");
    } else if (!state_refused(instance, bytes, size, why, sizeof why) &&
               (saved = new_saved(instance, size)) == NULL) {
        snprintf(why, sizeof why, "out of memory");
    }
    if (saved == NULL) {
        fmu_log(instance, FMU_ERROR, "%s: refused: %s", function, why);
        return FMU_ERROR;
    }
    memcpy(saved->bytes, bytes, size);
    *state = saved;
    return FMU_OK;
}
