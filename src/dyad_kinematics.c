/* dyadfmu: the kinematics' public helpers (defaults, names, the motion of a
 * point on a link), the validation that names a bad field, and rejection. Each
 * type's closed forms are in its own file, dyad_kin_<type>.c, their tangents in
 * dyad_kin_<type>_tangent.c and the motion of a point on dual numbers in
 * dyad_kinematics_tangent.c; the formulas they share in dyad_kin_generic.h. */
#include "dyad_kin_internal.h"
#include "dyad_kin_generic.h"

static const char* const kin_field_names[DYAD_KIN_FIELD_COUNT] = {
    [DYAD_KIN_FIELD_NONE] = "",
    [DYAD_KIN_FIELD_INPUT] = "input",
    [DYAD_KIN_FIELD_TYPE] = "type",
    [DYAD_KIN_FIELD_K_POSITION] = "k.point.position",
    [DYAD_KIN_FIELD_K_VELOCITY] = "k.point.velocity",
    [DYAD_KIN_FIELD_K_ACCELERATION] = "k.point.acceleration",
    [DYAD_KIN_FIELD_K_GUIDE] = "k.guide",
    [DYAD_KIN_FIELD_K_OMEGA] = "k.omega",
    [DYAD_KIN_FIELD_K_EPSILON] = "k.epsilon",
    [DYAD_KIN_FIELD_P_POSITION] = "p.point.position",
    [DYAD_KIN_FIELD_P_VELOCITY] = "p.point.velocity",
    [DYAD_KIN_FIELD_P_ACCELERATION] = "p.point.acceleration",
    [DYAD_KIN_FIELD_P_GUIDE] = "p.guide",
    [DYAD_KIN_FIELD_P_OMEGA] = "p.omega",
    [DYAD_KIN_FIELD_P_EPSILON] = "p.epsilon",
    [DYAD_KIN_FIELD_LENGTH_M] = "length_m",
    [DYAD_KIN_FIELD_LENGTH_N] = "length_n",
    [DYAD_KIN_FIELD_TURN_M] = "turn_m",
    [DYAD_KIN_FIELD_TURN_N] = "turn_n",
    [DYAD_KIN_FIELD_COM_M] = "com_m",
    [DYAD_KIN_FIELD_COM_N] = "com_n",
    [DYAD_KIN_FIELD_BRANCH] = "branch",
    [DYAD_KIN_FIELD_SINGULAR_THRESHOLD] = "singular_threshold",
    [DYAD_KIN_FIELD_MOUNT_AMPLIFICATION] = "mount_amplification",
};

static const char* const kin_failure_names[DYAD_KIN_FAILURE_COUNT] = {
    [DYAD_KIN_CLOSES] = "",
    [DYAD_KIN_TOO_FAR] = "|D_m D_n| > l_m + l_n",
    [DYAD_KIN_TOO_CLOSE] = "|D_m D_n| < |l_m - l_n|",
    [DYAD_KIN_OFF_LINE] = "distance of D_n from the line of E > l_n",
    [DYAD_KIN_OFF_SLOT] = "|D_m D_n| < l_n |sin delta_n|",
    [DYAD_KIN_BEHIND_PIVOT] = "l_m <= 0",
};

dyad_kin_input dyad_kin_input_default(void)
{
    /* one copy of a constant: a generated scene starts every dyad's input from it */
    static const dyad_kin_input defaults = DYAD_KIN_INPUT_DEFAULTS;
    return defaults;
}

const char* dyad_kin_field_name(dyad_kin_field field)
{
    return (unsigned)field < DYAD_KIN_FIELD_COUNT ? kin_field_names[field] : "?";
}

const char* dyad_kin_failure_name(dyad_kin_failure failure)
{
    return (unsigned)failure < DYAD_KIN_FAILURE_COUNT ? kin_failure_names[failure] : "?";
}

dyad_point_motion dyad_point_on_link(const dyad_point_motion* origin, dyad_vec2 dir,
                                     dyad_real omega, dyad_real epsilon, dyad_vec2 at)
{
    return dyad_kin_point_on_link(origin, dir, omega, epsilon, at);
}

/* ---- validation ---------------------------------------------------------------------------------
 */

static int unit_ok(dyad_vec2 v)
{
    return dyad_is_valid_vec2(v) && dyad_is_unit(v);
}

/* The first bad field of a mount, or NONE; `first` is its K_ or P_POSITION. */
static dyad_kin_field bad_mount_field(const dyad_mount* g, int slides, dyad_kin_field first)
{
    const int offset = !dyad_is_valid_vec2(g->point.position)       ? 0
                       : !dyad_is_valid_vec2(g->point.velocity)     ? 1
                       : !dyad_is_valid_vec2(g->point.acceleration) ? 2
                       : !slides                                    ? -1
                       : !unit_ok(g->guide)                         ? 3
                       : !dyad_is_valid_real(g->omega)              ? 4
                       : !dyad_is_valid_real(g->epsilon)            ? 5
                                                                    : -1;
    return offset < 0 ? DYAD_KIN_FIELD_NONE : (dyad_kin_field)(first + offset);
}

/* A length in its domain: finite, and positive or non-negative. */
static int length_ok(dyad_real l, int may_be_zero)
{
    return dyad_is_valid_real(l) && (l > 0 || (may_be_zero && l == 0));
}

/* The fields after the mounts, in order. */
static dyad_kin_field bad_dyad_field(dyad_type type, const dyad_kin_input* in)
{
    const int slides_dm = dyad_kin_slides(type, DYAD_PAIR_DM);
    const int slides_e = dyad_kin_slides(type, DYAD_PAIR_E);
    const int slides_dn = dyad_kin_slides(type, DYAD_PAIR_DN);
    const int two_ways = type == DYAD_RRR || type == DYAD_RRT || type == DYAD_RTR;
    if (!slides_e && !length_ok(in->length_m, type != DYAD_RRR)) {
        return DYAD_KIN_FIELD_LENGTH_M;
    }
    if (!length_ok(in->length_n, type != DYAD_RRR && type != DYAD_RRT)) {
        return DYAD_KIN_FIELD_LENGTH_N;
    }
    if (slides_dm && !unit_ok(in->turn_m)) {
        return DYAD_KIN_FIELD_TURN_M;
    }
    if ((slides_e || slides_dn) && !unit_ok(in->turn_n)) {
        return DYAD_KIN_FIELD_TURN_N;
    }
    if (!dyad_is_valid_vec2(in->com_m)) {
        return DYAD_KIN_FIELD_COM_M;
    }
    if (!dyad_is_valid_vec2(in->com_n)) {
        return DYAD_KIN_FIELD_COM_N;
    }
    if (two_ways && in->branch != 1 && in->branch != -1) {
        return DYAD_KIN_FIELD_BRANCH;
    }
    if (!dyad_is_valid_real(in->singular_threshold) || !(in->singular_threshold > 0) ||
        !(in->singular_threshold < 1)) {
        return DYAD_KIN_FIELD_SINGULAR_THRESHOLD;
    }
    if (!dyad_is_valid_real(in->mount_amplification) || !(in->mount_amplification >= 0)) {
        return DYAD_KIN_FIELD_MOUNT_AMPLIFICATION;
    }
    return DYAD_KIN_FIELD_NONE;
}

dyad_kin_field dyad_kin_first_bad_field(dyad_type type, const dyad_kin_input* in)
{
    dyad_kin_field bad =
        bad_mount_field(&in->k, dyad_kin_slides(type, DYAD_PAIR_DM), DYAD_KIN_FIELD_K_POSITION);
    if (bad == DYAD_KIN_FIELD_NONE) {
        bad =
            bad_mount_field(&in->p, dyad_kin_slides(type, DYAD_PAIR_DN), DYAD_KIN_FIELD_P_POSITION);
    }
    return bad == DYAD_KIN_FIELD_NONE ? bad_dyad_field(type, in) : bad;
}

/* ---- rejection ----------------------------------------------------------------------------------
 */

static void fill_motion(dyad_point_motion* p, dyad_real value)
{
    p->position = p->velocity = p->acceleration = dyad_vec2_make(value, value);
}

static void fill_link(dyad_kin_link* link, dyad_real value)
{
    link->dir = dyad_vec2_make(value, value);
    link->omega = link->epsilon = value;
    link->length = link->length_rate = link->length_accel = value;
    fill_motion(&link->d, value);
    fill_motion(&link->com, value);
}

void dyad_kin_fill_nan(dyad_kin_result* result, dyad_status status, dyad_kin_field field)
{
    const dyad_real nan = (dyad_real)NAN;
    result->status = status;
    result->field = field;
    result->failure = DYAD_KIN_CLOSES;
    result->gap = 0;
    fill_link(&result->m, nan);
    fill_link(&result->n, nan);
    fill_motion(&result->e, nan);
    result->slide_k.s = result->slide_k.rate = result->slide_k.accel = nan;
    result->slide_p.s = result->slide_p.rate = result->slide_p.accel = nan;
    result->conditioning = result->closure = result->amplification = nan;
}

dyad_status dyad_kin_reject(dyad_kin_result* value, dyad_kin_result* derivative, dyad_status status,
                            dyad_kin_field field)
{
    if (value != NULL) {
        dyad_kin_fill_nan(value, status, field);
    }
    if (derivative != NULL) {
        dyad_kin_fill_nan(derivative, status, field);
    }
    return status;
}

int dyad_kin_outputs_finite(const dyad_kin_result* r)
{
    return dyad_kin_motion_residue(r) == 0;
}
