/* dyadfmu: input validation, link resultants (paper eqs. 1 and 2), the pair
 * table, status handling and dispatch, shared by the five solvers. */
#include "dyad_internal.h"

#include <stddef.h>

static const dyad_pair_kind pair_table[DYAD_TYPE_COUNT][3] = {
    /*            D_m                      E                        D_n */
    [DYAD_RRR] = {DYAD_PAIR_REVOLUTE, DYAD_PAIR_REVOLUTE, DYAD_PAIR_REVOLUTE},
    [DYAD_RRT] = {DYAD_PAIR_TRANSLATIONAL, DYAD_PAIR_REVOLUTE, DYAD_PAIR_REVOLUTE},
    [DYAD_RTR] = {DYAD_PAIR_REVOLUTE, DYAD_PAIR_TRANSLATIONAL, DYAD_PAIR_REVOLUTE},
    [DYAD_TRT] = {DYAD_PAIR_TRANSLATIONAL, DYAD_PAIR_REVOLUTE, DYAD_PAIR_TRANSLATIONAL},
    [DYAD_RTT] = {DYAD_PAIR_TRANSLATIONAL, DYAD_PAIR_TRANSLATIONAL, DYAD_PAIR_REVOLUTE},
};

/* Which link lengths may be zero, as the paper states for each type: a link
 * whose outer pair slides may have its pin on the guide (RRT l_m, TRT l_m and
 * l_n), and so may the slider of an inner translational pair (RTR, RTT l_n).
 * Every other length is a divisor or a lever that must exist. */
static const int zero_length_table[DYAD_TYPE_COUNT][2] = {
    /*            m  n */
    [DYAD_RRR] = {0, 0},
    [DYAD_RRT] = {1, 0},
    [DYAD_RTR] = {0, 1},
    [DYAD_TRT] = {1, 1},
    [DYAD_RTT] = {0, 1},
};

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
    return pair_table[type][pair];
}

int dyad_length_may_be_zero(dyad_type type, dyad_link_id link)
{
    if ((unsigned)type >= DYAD_TYPE_COUNT || (unsigned)link > DYAD_LINK_N) {
        return 0;
    }
    return zero_length_table[type][link];
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
    }
    return "?";
}

const char* dyad_field_name(dyad_field field)
{
    return (unsigned)field < DYAD_FIELD_COUNT ? field_names[field] : "?";
}

/* The unit vector of a direction that is unit within DYAD_UNIT_TOLERANCE. */
static int normalise_direction(dyad_vec2 v, dyad_vec2* unit)
{
    dyad_real norm2;
    if (!dyad_is_valid_vec2(v)) {
        return 0;
    }
    norm2 = dyad_dot(v, v);
    if (!(dyad_abs(norm2 - 1) <= DYAD_UNIT_TOLERANCE)) {
        return 0;
    }
    *unit = dyad_scale(1 / dyad_length(v), v);
    return 1;
}

/* F_g and M_g for a link with frame (i, j): eq. (1) gives the acceleration of
 * the centre of mass, a_S = a_D - omega^2 r + epsilon k0 x r with
 * r = x_S i + y_S j; eq. (2) turns it into the inertia force -m a_S and
 * moment -J epsilon, to which the active load and the weight m g are added.
 * Also the moment of all that about D_g: the centripetal part m omega^2 r of
 * the inertia force points along r and has no moment about D_g, so it is left
 * out of that sum instead of being added and cancelled again; for a fast,
 * heavy link it would otherwise swamp the moment in round-off. */
static void link_resultant(const dyad_link* link, dyad_vec2 i, dyad_vec2 gravity,
                           dyad_vec2* force, dyad_real* moment, dyad_real* moment_about_d)
{
    const dyad_vec2 j = dyad_perp(i);
    const dyad_vec2 r = dyad_combine(link->com.x, i, link->com.y, j);
    const dyad_vec2 tangential = dyad_add(link->accel_d, dyad_scale(link->epsilon, dyad_perp(r)));
    const dyad_vec2 without_centripetal =
        dyad_add(link->force, dyad_scale(link->mass, dyad_sub(gravity, tangential)));
    *force = dyad_add(without_centripetal,
                      dyad_scale(link->mass * link->omega * link->omega, r));
    *moment = link->moment - link->inertia * link->epsilon;
    *moment_about_d = *moment + dyad_cross(r, without_centripetal);
}

void dyad_link_resultant(const dyad_link* link, dyad_vec2 gravity, dyad_vec2* force,
                         dyad_real* moment)
{
    dyad_real moment_about_d;
    link_resultant(link, link->dir, gravity, force, moment, &moment_about_d);
}

/* Validates one link and turns it into a body. Returns the offending field,
 * or DYAD_FIELD_NONE. */
static dyad_field prepare_link(const dyad_link* link, int may_be_zero, dyad_field first,
                               dyad_vec2 gravity, dyad_body* body)
{
    if (!normalise_direction(link->dir, &body->i)) {
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
    body->j = dyad_perp(body->i);
    body->l = link->length;
    body->com = link->com;
    link_resultant(link, body->i, gravity, &body->f, &body->m, &body->m_d);
    return DYAD_FIELD_NONE;
}

static void fill_outputs(dyad_result* result, dyad_real value)
{
    result->r_mk = dyad_vec2_make(value, value);
    result->r_np = dyad_vec2_make(value, value);
    result->r_mn = dyad_vec2_make(value, value);
    result->n_mk = value;
    result->n_np = value;
    result->n_mn = value;
    result->m_mk = value;
    result->m_np = value;
    result->m_mn = value;
}

dyad_status dyad_reject(dyad_result* result, dyad_status status, dyad_field field)
{
    fill_outputs(result, (dyad_real)NAN);
    result->status = status;
    result->field = field;
    return status;
}

static dyad_field validate(dyad_type type, const dyad_input* in, dyad_prepared* p)
{
    dyad_field bad;
    if (!dyad_is_valid_real(in->singular_threshold) || !(in->singular_threshold > 0) ||
        !(in->singular_threshold < 1)) {
        return DYAD_FIELD_SINGULAR_THRESHOLD;
    }
    if (!dyad_is_valid_vec2(in->gravity)) {
        return DYAD_FIELD_GRAVITY;
    }
    bad = prepare_link(&in->m, zero_length_table[type][DYAD_LINK_M], DYAD_FIELD_M_DIR,
                       in->gravity, &p->m);
    if (bad != DYAD_FIELD_NONE) {
        return bad;
    }
    bad = prepare_link(&in->n, zero_length_table[type][DYAD_LINK_N], DYAD_FIELD_N_DIR,
                       in->gravity, &p->n);
    if (bad != DYAD_FIELD_NONE) {
        return bad;
    }
    p->i_k = p->j_k = p->i_p = p->j_p = dyad_vec2_make(0, 0);
    if (pair_table[type][DYAD_PAIR_DM] == DYAD_PAIR_TRANSLATIONAL) {
        if (!normalise_direction(in->guide_k, &p->i_k)) {
            return DYAD_FIELD_GUIDE_K;
        }
        p->j_k = dyad_perp(p->i_k);
    }
    if (pair_table[type][DYAD_PAIR_DN] == DYAD_PAIR_TRANSLATIONAL) {
        if (!normalise_direction(in->guide_p, &p->i_p)) {
            return DYAD_FIELD_GUIDE_P;
        }
        p->j_p = dyad_perp(p->i_p);
    }
    return DYAD_FIELD_NONE;
}

dyad_status dyad_prepare(dyad_type type, const dyad_input* input, dyad_prepared* prepared,
                         dyad_result* result)
{
    dyad_field bad;
    if (result == NULL) {
        return DYAD_STATUS_INVALID_INPUT;
    }
    result->denominator = (dyad_real)NAN;
    result->conditioning = (dyad_real)NAN;
    result->amplification = (dyad_real)NAN;
    if (input == NULL) {
        return dyad_reject(result, DYAD_STATUS_INVALID_INPUT, DYAD_FIELD_INPUT);
    }
    bad = validate(type, input, prepared);
    if (bad != DYAD_FIELD_NONE) {
        return dyad_reject(result, DYAD_STATUS_INVALID_INPUT, bad);
    }
    fill_outputs(result, 0);
    result->status = DYAD_STATUS_OK;
    result->field = DYAD_FIELD_NONE;
    return DYAD_STATUS_OK;
}

dyad_status dyad_accept_conditioning(dyad_real denominator, dyad_real conditioning,
                                     dyad_real threshold, dyad_result* result)
{
    result->denominator = denominator;
    result->conditioning = conditioning;
    result->amplification = 1 / conditioning;
    if (!(conditioning >= threshold)) {
        return dyad_reject(result, DYAD_STATUS_SINGULAR, DYAD_FIELD_NONE);
    }
    return DYAD_STATUS_OK;
}

dyad_status dyad_finish(dyad_result* result)
{
    const int finite = dyad_is_valid_vec2(result->r_mk) && dyad_is_valid_vec2(result->r_np) &&
                       dyad_is_valid_vec2(result->r_mn) && dyad_is_valid_real(result->n_mk) &&
                       dyad_is_valid_real(result->n_np) && dyad_is_valid_real(result->n_mn) &&
                       dyad_is_valid_real(result->m_mk) && dyad_is_valid_real(result->m_np) &&
                       dyad_is_valid_real(result->m_mn);
    if (!finite) {
        return dyad_reject(result, DYAD_STATUS_OUT_OF_RANGE, DYAD_FIELD_NONE);
    }
    result->status = DYAD_STATUS_OK;
    result->field = DYAD_FIELD_NONE;
    return DYAD_STATUS_OK;
}
