/* dyadfmu FMU layer: FMU state (canGetAndSetFMUState, canSerializeFMUState), the
 * same for FMI 2 and FMI 3.
 *
 * What an instance is, beyond its model and its importer's settings: the state
 * machine's state, the time reached, the values as set (parameters, inputs,
 * angles), the model's input block (for the drive, its states too) and output
 * block with the last evaluation, and the angles' converted values. A saved state
 * holds exactly that, in the serialized form itself, so that get, set, serialize
 * and deserialize are one format and two copies:
 *
 *   magic "dyadfmu\0" | fingerprint | size | checksum | payload
 *
 * The fingerprint is of the model (its instantiation token) and of the sizes of
 * the blocks, so that a state from another FMU, or from another build of this
 * one, is refused; the checksum (FNV-1a over the payload) refuses a damaged one.
 * What the layer would use as an index (the state machine's state, the variable
 * an evaluation blames) is checked before it is restored, and so is every
 * parameter and input, as a set checks it (the models solve them without checking
 * again), and a model's states, as a step leaves them (fmu_behaviour.state_refused).
 * The saved states of an instance are kept in a list and freed with it. */
#include <stdint.h>
#include <string.h>

#include "fmu_instance.h"

struct fmu_saved {
    fmu_saved* next; /* the instance's other saved states */
    size_t size;     /* of bytes */
    unsigned char bytes[];
};

enum { HEADER_SIZE = 32 };
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

static uint64_t fingerprint(const fmu_instance* instance)
{
    const fmu_model* m = instance->model;
    const uint64_t sizes[4] = {m->variable_count, m->behaviour->input_size,
                               m->behaviour->output_size, instance->angle_count};
    uint64_t h = fnv1a(0xcbf29ce484222325ULL, m->token, strlen(m->token));
    return fnv1a(h, sizes, sizeof sizes);
}

/* The copies that make up the payload, in order: (where in the instance, size). */
typedef struct state_part {
    void* at;
    size_t size;
} state_part;

/* The parts of a state's payload, in order: the parts before the values are fixed
 * in size. */
enum { PART_VALUES = 6, PART_INPUT, PART_OUTPUT, PART_COUNT };

static void parts_of(fmu_instance* instance, state_part part[PART_COUNT])
{
    const fmu_model* m = instance->model;
    part[0] = (state_part){&instance->state, sizeof instance->state};
    part[1] = (state_part){&instance->time, sizeof instance->time};
    part[2] = (state_part){&instance->last_successful_time, sizeof instance->last_successful_time};
    part[3] = (state_part){&instance->terminate_requested, sizeof instance->terminate_requested};
    part[4] = (state_part){&instance->dirty, sizeof instance->dirty};
    part[5] = (state_part){&instance->evaluation, sizeof instance->evaluation};
    part[PART_VALUES] = (state_part){instance->values, m->variable_count * sizeof(double)};
    part[PART_INPUT] = (state_part){instance->input, m->behaviour->input_size};
    part[PART_OUTPUT] = (state_part){instance->output, m->behaviour->output_size};
}

static size_t state_size(fmu_instance* instance)
{
    state_part part[PART_COUNT];
    size_t size = HEADER_SIZE + instance->angle_count * sizeof(double);
    size_t k;
    parts_of(instance, part);
    for (k = 0; k < PART_COUNT; ++k) {
        size += part[k].size;
    }
    return size;
}

/* The instance's state into bytes (of state_size). */
static void write_state(fmu_instance* instance, unsigned char* bytes)
{
    state_part part[PART_COUNT];
    unsigned char* at = bytes + HEADER_SIZE;
    const uint64_t print = fingerprint(instance), size = state_size(instance);
    uint64_t check;
    size_t k;
    parts_of(instance, part);
    for (k = 0; k < PART_COUNT; ++k) {
        memcpy(at, part[k].at, part[k].size);
        at += part[k].size;
    }
    for (k = 0; k < instance->angle_count; ++k, at += sizeof(double)) {
        memcpy(at, &instance->angles[k].converted, sizeof(double));
    }
    check = fnv1a(0xcbf29ce484222325ULL, bytes + HEADER_SIZE, (size_t)size - HEADER_SIZE);
    memcpy(bytes, magic, 8);
    memcpy(bytes + 8, &print, 8);
    memcpy(bytes + 16, &size, 8);
    memcpy(bytes + 24, &check, 8);
}

/* Why `bytes` is not a state of this instance's FMU, or NULL. */
static const char* state_problem(fmu_instance* instance, const unsigned char* bytes, size_t size)
{
    uint64_t print, stored_size, check;
    if (size < HEADER_SIZE || memcmp(bytes, magic, 8) != 0) {
        return "not an FMU state of dyadfmu";
    }
    memcpy(&print, bytes + 8, 8);
    memcpy(&stored_size, bytes + 16, 8);
    memcpy(&check, bytes + 24, 8);
    if (print != fingerprint(instance) || stored_size != state_size(instance) ||
        size != stored_size) {
        return "a state of another FMU, or of another build of this one";
    }
    if (check != fnv1a(0xcbf29ce484222325ULL, bytes + HEADER_SIZE, size - HEADER_SIZE)) {
        return "a damaged state (its checksum does not match)";
    }
    return NULL;
}

/* The state's bytes into the instance (a state checked by state_problem). */
static void read_state(fmu_instance* instance, const unsigned char* bytes)
{
    state_part part[PART_COUNT];
    const unsigned char* at = bytes + HEADER_SIZE;
    size_t k;
    parts_of(instance, part);
    for (k = 0; k < PART_COUNT; ++k) {
        memcpy(part[k].at, at, part[k].size);
        at += part[k].size;
    }
    for (k = 0; k < instance->angle_count; ++k, at += sizeof(double)) {
        memcpy(&instance->angles[k].converted, at, sizeof(double));
    }
}

/* 1 if what the layer uses as an index is in range in the state's bytes: the
 * state machine's state, and the variable its evaluation blames. */
static int indices_valid(fmu_instance* instance, const unsigned char* bytes)
{
    state_part part[PART_COUNT];
    fmu_state state;
    fmu_evaluation e;
    size_t at = HEADER_SIZE, k;
    parts_of(instance, part);
    memcpy(&state, bytes + at, sizeof state);
    for (k = 0; k < 5; ++k) {
        at += part[k].size;
    }
    memcpy(&e, bytes + at, sizeof e); /* part 5 */
    return (state == FMU_STATE_INSTANTIATED || state == FMU_STATE_INITIALIZATION ||
            state == FMU_STATE_STEP || state == FMU_STATE_TERMINATED) &&
           e.bad_variable >= -1 && e.bad_variable < (int)instance->model->variable_count &&
           memchr(e.reason, '\0', sizeof e.reason) != NULL;
}

/* The name of the first parameter or input whose value in the state's bytes could
 * not have been set (not finite, or outside its bounds), or of a state that no step
 * could have reached, or NULL: a state is serialized from values that were checked
 * when they were set, and the model solves them without checking again. */
static const char* value_refused(fmu_instance* instance, const unsigned char* bytes, double* value)
{
    state_part part[PART_COUNT];
    const fmu_model* m = instance->model;
    const unsigned char *values, *input;
    size_t at = HEADER_SIZE, k;
    parts_of(instance, part);
    for (k = 0; k < PART_VALUES; ++k) {
        at += part[k].size;
    }
    values = bytes + at; /* the values as set, then the input block */
    input = values + part[PART_VALUES].size;
    for (k = 0; k < m->variable_count; ++k) {
        const fmu_variable* v = &m->variables[k];
        if (v->type != FMU_REAL || v->causality == FMU_OUTPUT) {
            continue;
        }
        if (v->target == FMU_TARGET_INPUT_REAL) {
            memcpy(value, input + v->offset, sizeof *value);
        } else if (v->target == FMU_TARGET_INPUT_ANGLE) {
            memcpy(value, values + k * sizeof(double), sizeof *value);
        } else {
            continue;
        }
        if (!fmu_value_allowed(v, *value)) {
            return v->name;
        }
    }
    return m->behaviour->state_refused != NULL ? m->behaviour->state_refused(m, input, value)
                                               : NULL;
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
    const size_t size = instance != NULL ? state_size(instance) : 0;
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
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK) {
        return status;
    }
    if (state == NULL || !owns(instance, state)) {
        return unknown_state(instance, function);
    }
    read_state(instance, state->bytes);
    fmu_rebuild_slots(instance);
    fmu_angles_stale(instance); /* the directions from the angles, not from the bytes */
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
    const char* problem;
    const char* refused;
    double value = 0;
    fmu_saved* saved = NULL;
    fmu_status status = fmu_check_call(instance, FMU_OP_STATE, function);
    if (status != FMU_OK) {
        return status;
    }
    problem =
        bytes == NULL || state == NULL ? "NULL arguments" : state_problem(instance, bytes, size);
    if (problem == NULL && !indices_valid(instance, bytes)) {
        problem = "a state out of range";
    }
    if (problem == NULL && (refused = value_refused(instance, bytes, &value)) != NULL) {
        fmu_log(instance, FMU_ERROR, "%s: refused: %s = %g could not have been set or reached",
                function, refused, value);
        return FMU_ERROR;
    }
    if (problem == NULL && (saved = new_saved(instance, size)) == NULL) {
        problem = "out of memory";
    }
    if (problem != NULL) {
        fmu_log(instance, FMU_ERROR, "%s: refused: %s", function, problem);
        return FMU_ERROR;
    }
    memcpy(saved->bytes, bytes, size);
    *state = saved;
    return FMU_OK;
}
