/* dyadfmu: the public helpers (defaults, names, the pair table), the slow path
 * that names a bad input field, and rejection. The steps every solver shares
 * on its hot path are inline in dyad_internal.h; dispatch is in dyad_solve.c. */
#include "dyad_internal.h"
#include "dyadfmu/angle.h"

#include <stddef.h>

static const char* const type_names[DYAD_TYPE_COUNT] = {"RRR", "RRT", "RTR", "TRT", "RTT"};

static const char* const field_names[DYAD_FIELD_COUNT] = {
    [DYAD_FIELD_NONE] = "",
    [DYAD_FIELD_INPUT] = "input",
    [DYAD_FIELD_TYPE] = "type",
    [DYAD_FIELD_M_DIR] = "link_m.dir",
    [DYAD_FIELD_M_LENGTH] = "link_m.length",
    [DYAD_FIELD_M_OMEGA] = "link_m.omega",
    [DYAD_FIELD_M_EPSILON] = "link_m.epsilon",
    [DYAD_FIELD_M_ACCEL_D] = "link_m.accel_d",
    [DYAD_FIELD_M_COM] = "link_m.com",
    [DYAD_FIELD_M_MASS] = "link_m.mass",
    [DYAD_FIELD_M_INERTIA] = "link_m.inertia",
    [DYAD_FIELD_M_FORCE] = "link_m.force",
    [DYAD_FIELD_M_MOMENT] = "link_m.moment",
    [DYAD_FIELD_N_DIR] = "link_n.dir",
    [DYAD_FIELD_N_LENGTH] = "link_n.length",
    [DYAD_FIELD_N_OMEGA] = "link_n.omega",
    [DYAD_FIELD_N_EPSILON] = "link_n.epsilon",
    [DYAD_FIELD_N_ACCEL_D] = "link_n.accel_d",
    [DYAD_FIELD_N_COM] = "link_n.com",
    [DYAD_FIELD_N_MASS] = "link_n.mass",
    [DYAD_FIELD_N_INERTIA] = "link_n.inertia",
    [DYAD_FIELD_N_FORCE] = "link_n.force",
    [DYAD_FIELD_N_MOMENT] = "link_n.moment",
    [DYAD_FIELD_GUIDE_K] = "guide_k",
    [DYAD_FIELD_GUIDE_P] = "guide_p",
    [DYAD_FIELD_GRAVITY] = "gravity",
    [DYAD_FIELD_SINGULAR_THRESHOLD] = "singular_threshold",
};

/* Offsets of a link's fields from its DYAD_FIELD_x_DIR. */
enum {
    LINK_DIR = 0,
    LINK_LENGTH,
    LINK_OMEGA,
    LINK_EPSILON,
    LINK_ACCEL_D,
    LINK_COM,
    LINK_MASS,
    LINK_INERTIA,
    LINK_FORCE,
    LINK_MOMENT
};

dyad_input dyad_input_default(void)
{
    dyad_input in;
    const dyad_vec2 zero = dyad_vec2_make(0, 0);
    const dyad_vec2 x_axis = dyad_vec2_make(1, 0);
    dyad_link link;

    link.dir = x_axis;
    link.length = 1;
    link.omega = 0;
    link.epsilon = 0;
    link.accel_d = zero;
    link.com = zero;
    link.mass = 0;
    link.inertia = 0;
    link.force = zero;
    link.moment = 0;

    in.m = link;
    in.n = link;
    in.guide_k = x_axis;
    in.guide_p = x_axis;
    in.gravity = zero;
    in.singular_threshold = DYAD_DEFAULT_SINGULAR_THRESHOLD;
    return in;
}

dyad_pair_kind dyad_pair_kind_of(dyad_type type, dyad_pair pair)
{
    if ((unsigned)type >= DYAD_TYPE_COUNT || (unsigned)pair > DYAD_PAIR_DN) {
        return DYAD_PAIR_REVOLUTE;
    }
    return dyad_pair_table[type][pair];
}

int dyad_length_may_be_zero(dyad_type type, dyad_link_id link)
{
    if ((unsigned)type >= DYAD_TYPE_COUNT || (unsigned)link > DYAD_LINK_N) {
        return 0;
    }
    return dyad_zero_length_table[type][link];
}

const char* dyad_type_name(dyad_type type)
{
    return (unsigned)type < DYAD_TYPE_COUNT ? type_names[type] : "?";
}

const char* dyad_status_name(dyad_status status)
{
    switch (status) {
    case DYAD_STATUS_OK: return "ok";
    case DYAD_STATUS_SINGULAR: return "singular";
    case DYAD_STATUS_INVALID_INPUT: return "invalid input";
    case DYAD_STATUS_OUT_OF_RANGE: return "out of range";
    case DYAD_STATUS_CANNOT_ASSEMBLE: return "cannot assemble";
    }
    return "?";
}

const char* dyad_field_name(dyad_field field)
{
    return (unsigned)field < DYAD_FIELD_COUNT ? field_names[field] : "?";
}

void dyad_link_resultant(const dyad_link* link, dyad_vec2 gravity, dyad_vec2* force,
                         dyad_real* moment)
{
    dyad_body body;
    dyad_resultant(link, link->dir, gravity, &body);
    *force = body.f;
    *moment = body.m;
}

void dyad_angle_cos_sin(double angle, double* cos_out, double* sin_out)
{
    dyad_cos_sin(angle, cos_out, sin_out);
}

/* amplification x the largest of three output magnitudes, NaN unless ok. */
static dyad_real dyad_error_scale(const dyad_result* result, dyad_real mk, dyad_real np,
                                  dyad_real mn)
{
    return result->status == DYAD_STATUS_OK ? result->amplification * dyad_largest_of3(mk, np, mn)
                                            : (dyad_real)NAN;
}

dyad_real dyad_force_size(const dyad_result* result)
{
    return dyad_error_scale(result, dyad_norm1(result->r_mk), dyad_norm1(result->r_np),
                            dyad_norm1(result->r_mn));
}

dyad_real dyad_moment_size(const dyad_result* result)
{
    return dyad_error_scale(result, dyad_abs(result->m_mk), dyad_abs(result->m_np),
                            dyad_abs(result->m_mn));
}

/* The first field of a link that is out of its domain, or DYAD_FIELD_NONE.
 * Only run once the fast check in dyad_validate() has failed, to name the field. */
static dyad_field first_bad_link_field(const dyad_link* link, int may_be_zero, dyad_field first)
{
    if (!dyad_is_valid_vec2(link->dir) || !dyad_is_unit(link->dir)) {
        return (dyad_field)(first + LINK_DIR);
    }
    if (!dyad_is_valid_real(link->length) || link->length < 0 ||
        (link->length == 0 && !may_be_zero)) {
        return (dyad_field)(first + LINK_LENGTH);
    }
    if (!dyad_is_valid_real(link->omega)) {
        return (dyad_field)(first + LINK_OMEGA);
    }
    if (!dyad_is_valid_real(link->epsilon)) {
        return (dyad_field)(first + LINK_EPSILON);
    }
    if (!dyad_is_valid_vec2(link->accel_d)) {
        return (dyad_field)(first + LINK_ACCEL_D);
    }
    if (!dyad_is_valid_vec2(link->com)) {
        return (dyad_field)(first + LINK_COM);
    }
    if (!dyad_is_valid_real(link->mass) || link->mass < 0) {
        return (dyad_field)(first + LINK_MASS);
    }
    if (!dyad_is_valid_real(link->inertia) || link->inertia < 0) {
        return (dyad_field)(first + LINK_INERTIA);
    }
    if (!dyad_is_valid_vec2(link->force)) {
        return (dyad_field)(first + LINK_FORCE);
    }
    if (!dyad_is_valid_real(link->moment)) {
        return (dyad_field)(first + LINK_MOMENT);
    }
    return DYAD_FIELD_NONE;
}

dyad_field dyad_first_bad_field(dyad_type type, const dyad_input* in)
{
    dyad_field bad;
    if (!dyad_is_valid_real(in->singular_threshold) || !(in->singular_threshold > 0) ||
        !(in->singular_threshold < 1)) {
        return DYAD_FIELD_SINGULAR_THRESHOLD;
    }
    if (!dyad_is_valid_vec2(in->gravity)) {
        return DYAD_FIELD_GRAVITY;
    }
    bad = first_bad_link_field(&in->m, dyad_zero_length_table[type][DYAD_LINK_M], DYAD_FIELD_M_DIR);
    if (bad != DYAD_FIELD_NONE) {
        return bad;
    }
    bad = first_bad_link_field(&in->n, dyad_zero_length_table[type][DYAD_LINK_N], DYAD_FIELD_N_DIR);
    if (bad != DYAD_FIELD_NONE) {
        return bad;
    }
    if (dyad_guide_used(type, DYAD_PAIR_DM) &&
        (!dyad_is_valid_vec2(in->guide_k) || !dyad_is_unit(in->guide_k))) {
        return DYAD_FIELD_GUIDE_K;
    }
    if (dyad_guide_used(type, DYAD_PAIR_DN) &&
        (!dyad_is_valid_vec2(in->guide_p) || !dyad_is_unit(in->guide_p))) {
        return DYAD_FIELD_GUIDE_P;
    }
    return DYAD_FIELD_NONE;
}

dyad_field dyad_check_input(dyad_type type, const dyad_input* input)
{
    if ((unsigned)type >= DYAD_TYPE_COUNT) {
        return DYAD_FIELD_TYPE;
    }
    return input == NULL ? DYAD_FIELD_INPUT : dyad_first_bad_field(type, input);
}

dyad_status dyad_reject(dyad_result* result, dyad_status status, dyad_field field)
{
    dyad_fill_outputs(result, (dyad_real)NAN);
    result->status = status;
    result->field = field;
    return status;
}
