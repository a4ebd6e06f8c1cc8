/* dyadfmu: a hydraulic cylinder between two pins driving a link about its pivot
 * (dyadfmu/cylinder.h): kinematics and kinetostatics in closed form.
 *
 * Bodies. The barrel c is pinned at A to a body of known motion, the rod r
 * slides in it along the axis u (from A towards B, j = k0 x u) and is pinned
 * at B to the link l, which turns about O (a point of known motion). s = |AB|
 * with its rates is the input; r_B = |OB| = |pin_b| is fixed.
 *
 * Position. The triangle O, A, B is the RRR dyad's with D_m = O, l_m = r_B,
 * D_n = A, l_n = s (dyad_kin_rrr.c): with d = A - O, L = |d|, u_d = d / L,
 * v = k0 x u_d, B - O = a u_d + h v and B - A = b u_d + h v,
 *      a = (r_B^2 - s^2 + L^2) / (2 L),   b = (r_B^2 - s^2 - L^2) / (2 L),
 *      4 L^2 h^2 = P (r_B + s + L) Q (L + |r_B - s|),
 *      P = r_B + s - L,   Q = L - |r_B - s|,
 * h = branch sqrt(.) / (2 L), so branch +1 puts B to the left of O -> A.
 * P < 0: the cylinder does not reach (TOO_FAR, gap -P); Q < 0: one circle
 * inside the other, the stroke beyond the triangle (TOO_CLOSE, gap -Q). Then
 * e = (B - O) / r_B, u = (B - A) / s and the link's frame turns e back by the
 * angle of pin_b: i_l = e (x) conj(pin_b) / r_B ((x) the complex product).
 *
 * Velocity and acceleration. B from O along the link and from A along the
 * cylinder (dyad_kin_arm: P = base + q w, with the slide, Coriolis,
 * tangential and centripetal terms):
 *      v_O + omega_l r_B k0 x e = v_A + s' u + omega_c s j,
 * linear in (omega_l, omega_c) with the columns r_B k0 x e and -s j, solved
 * by Cramer's rule; the accelerations the same with (epsilon_l, epsilon_c)
 * and the known terms (centripetal, Coriolis 2 s' omega_c j, s'' u) moved to
 * the right. The determinant is -r_B s (e x u), and from the position
 * e x u = h L / (r_B s): computed so it keeps its digits at the toggle, where
 * O, A and B fall in line (h -> 0) and the link's and the cylinder's rates
 * grow without bound. conditioning = |h L / (r_B s)|.
 *
 * Loads. Each body's resultant (its weight, d'Alembert force -m a_S and
 * moment -J epsilon, and for the link its active load) is reduced to a force
 * F_g and its moment M_g about the body's pin (A for the barrel, B for the
 * rod, O for the link), S_g - pin = q:
 *      F_g = f_g + m (g - a_pin - epsilon k0 x q) + m omega^2 q,
 *      M_g = m_g - J epsilon + q x [F_g without m omega^2 q],
 * the centripetal term left out of the moment, where it has none
 * (dyad_internal.h does the same for the dyads' links).
 *
 * Kinetostatics. Unknowns: R_A (on the barrel at A), R_B (on the link from
 * the rod at B), R_O (on the link at O), and the barrel's action on the rod:
 * the axial force F_ax u plus the normal force N j at B and the moment M
 * about B (the rod's reaction on the barrel is the opposite). Nine unknowns,
 * three bodies of three equations:
 *   rod, forces:       -R_B + F_ax u + N j + F_r = 0
 *   rod, about B:      M + M_r = 0
 *   barrel, forces:    R_A - F_ax u - N j + F_c = 0
 *   barrel, about A:   s u x (-N j) - M + M_c = 0,   u x j = 1
 *   link, forces:      R_O + R_B + F_l = 0
 *   link, about O:     r_B e x R_B + M_l = 0.
 * Solved in this order, each unknown from one equation:
 *      M = -M_r,   N = (M_c + M_r) / s,   q = N j + F_r,
 *      F_ax = -(M_l + r_B e x q) / (r_B e x u),
 *      R_B = F_ax u + q,   R_O = -(R_B + F_l),   R_A = F_ax u + N j - F_c.
 * F_ax divides by r_B (e x u) = h L / s: the toggle, where the cylinder
 * passes through the pivot and cannot turn the link, is the one division by
 * a vanishing quantity; N divides by s > 0 only.
 *
 * Energy. Summed over the bodies, the reactions at B and between barrel and
 * rod do no net work (the pin B and the sliding pair are ideal), so
 *      F_ax s' + R_A . v_A + R_O . v_O + f_l . v_Sl + m_l omega_l
 *          = d/dt (kinetic energy) - sum m g . v_S,
 * what tests/dyad_tests.c checks on the outputs.
 *
 * Round-off. The motion is the RRR dyad's: within eps kin_amplification of
 * its largest output of each unit, kin_amplification = (1 + 1 / closure +
 * 1 / conditioning) (1 + mount_amplification (1 + (|A|_1 + |O|_1) / size)),
 * closure = min(P, Q) / size, size = r_B + s + L, the mounts' own round-off
 * carried in as dyad_kin_generic.h does for the dyads. The status is
 * singular where 1 / kin_amplification falls below singular_threshold, which
 * with the default threshold comes before the motion (and the reactions built
 * on it) lose half their digits, and always before the triangle fails. The
 * reactions carry that, times the cancellation of the load terms: the sizes
 * (sums of the magnitudes of the terms) of F_g and M_g are carried through
 * the forms above as dyad_amplification.h does, and the data factor is the
 * largest size of the forces (and of M) over the largest output of that unit,
 * in [1, 1/eps]:
 *      amplification = data factor x kin_amplification.
 * scripts/tests/test_cylinder.py holds every output within a few eps x
 * amplification of the largest of its unit against a NumPy Newton-Euler solve.
 *
 * The formulas are written over a scalar of choice (dyad_kin_generic.h): this
 * file compiles them over dyad_real for dyad_cylinder, and
 * dyad_cylinder_tangent.c over dual numbers for the exact derivative; a scene's
 * batch (dyad_lanes.h) takes them over dyad_real once more for
 * dyad_cylinder_lane, one sample of a loop without branches.
 */
#ifndef DYAD_KIN_FORMULAS
#include "dyadfmu/cylinder.h"
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#include "dyad_kin_generic.h"
#include "dyad_cylinder.c"

static const char* const cylinder_field_names[DYAD_CYL_FIELD_COUNT] = {
    [DYAD_CYL_FIELD_NONE] = "",
    [DYAD_CYL_FIELD_INPUT] = "input",
    [DYAD_CYL_FIELD_A_POSITION] = "a.position",
    [DYAD_CYL_FIELD_A_VELOCITY] = "a.velocity",
    [DYAD_CYL_FIELD_A_ACCELERATION] = "a.acceleration",
    [DYAD_CYL_FIELD_O_POSITION] = "o.position",
    [DYAD_CYL_FIELD_O_VELOCITY] = "o.velocity",
    [DYAD_CYL_FIELD_O_ACCELERATION] = "o.acceleration",
    [DYAD_CYL_FIELD_PIN_B] = "pin_b",
    [DYAD_CYL_FIELD_LENGTH] = "length",
    [DYAD_CYL_FIELD_RATE] = "rate",
    [DYAD_CYL_FIELD_ACCEL] = "accel",
    [DYAD_CYL_FIELD_BRANCH] = "branch",
    [DYAD_CYL_FIELD_BARREL_MASS] = "barrel.mass",
    [DYAD_CYL_FIELD_BARREL_COM] = "barrel.com",
    [DYAD_CYL_FIELD_BARREL_INERTIA] = "barrel.inertia",
    [DYAD_CYL_FIELD_ROD_MASS] = "rod.mass",
    [DYAD_CYL_FIELD_ROD_COM] = "rod.com",
    [DYAD_CYL_FIELD_ROD_INERTIA] = "rod.inertia",
    [DYAD_CYL_FIELD_LINK_MASS] = "link.mass",
    [DYAD_CYL_FIELD_LINK_COM] = "link.com",
    [DYAD_CYL_FIELD_LINK_INERTIA] = "link.inertia",
    [DYAD_CYL_FIELD_LINK_FORCE] = "link.force",
    [DYAD_CYL_FIELD_LINK_MOMENT] = "link.moment",
    [DYAD_CYL_FIELD_GRAVITY] = "gravity",
    [DYAD_CYL_FIELD_SINGULAR_THRESHOLD] = "singular_threshold",
    [DYAD_CYL_FIELD_MOUNT_AMPLIFICATION] = "mount_amplification",
};

dyad_cylinder_input dyad_cylinder_input_default(void)
{
    /* one copy of a constant: a generated scene starts every cylinder's input from it */
    static const dyad_cylinder_input defaults = DYAD_CYL_INPUT_DEFAULTS;
    return defaults;
}

const char* dyad_cylinder_field_name(dyad_cylinder_field field)
{
    return (unsigned)field < DYAD_CYL_FIELD_COUNT ? cylinder_field_names[field] : "?";
}

static int cyl_finite(dyad_real a)
{
    return a - a == 0;
}

static int cyl_finite2(dyad_vec2 a)
{
    return cyl_finite(a.x) && cyl_finite(a.y);
}

static int cyl_part_bad(const dyad_cylinder_part* p, dyad_cylinder_field first,
                        dyad_cylinder_field* bad)
{
    const int mass = !(cyl_finite(p->mass) && p->mass >= 0);
    const int com = !cyl_finite(p->com);
    const int inertia = !(cyl_finite(p->inertia) && p->inertia >= 0);
    *bad = mass      ? first
           : com     ? (dyad_cylinder_field)(first + 1)
           : inertia ? (dyad_cylinder_field)(first + 2)
                     : DYAD_CYL_FIELD_NONE;
    return *bad != DYAD_CYL_FIELD_NONE;
}

/* 1 where cyl_first_bad finds no bad field: every check at once, without a branch per
 * field (DYAD_CYL_FIELD_CHECKS). */
static int cyl_fields_good(const dyad_cylinder_input* in)
{
    int good = 1;
#define DYAD_CYL_GOOD_IF(condition) good &= (condition)
    DYAD_CYL_FIELD_CHECKS(in, DYAD_CYL_GOOD_IF);
#undef DYAD_CYL_GOOD_IF
    return good;
}

/* The first field out of its domain, in the order of dyad_cylinder_field. */
static dyad_cylinder_field cyl_first_bad(const dyad_cylinder_input* in)
{
    const dyad_cylinder_link* l = &in->link;
    const int checks[] = {
        cyl_finite2(in->a.position),
        cyl_finite2(in->a.velocity),
        cyl_finite2(in->a.acceleration),
        cyl_finite2(in->o.position),
        cyl_finite2(in->o.velocity),
        cyl_finite2(in->o.acceleration),
        cyl_finite2(in->pin_b) && dyad_dot(in->pin_b, in->pin_b) > 0,
        cyl_finite(in->length) && in->length > 0,
        cyl_finite(in->rate),
        cyl_finite(in->accel),
        in->branch == 1 || in->branch == -1,
    };
    dyad_cylinder_field bad;
    size_t k;
    for (k = 0; k < sizeof checks / sizeof checks[0]; ++k) {
        if (!checks[k]) {
            return (dyad_cylinder_field)(DYAD_CYL_FIELD_A_POSITION + k);
        }
    }
    if (cyl_part_bad(&in->barrel, DYAD_CYL_FIELD_BARREL_MASS, &bad) ||
        cyl_part_bad(&in->rod, DYAD_CYL_FIELD_ROD_MASS, &bad)) {
        return bad;
    }
    return !(cyl_finite(l->mass) && l->mass >= 0)         ? DYAD_CYL_FIELD_LINK_MASS
           : !cyl_finite2(l->com)                         ? DYAD_CYL_FIELD_LINK_COM
           : !(cyl_finite(l->inertia) && l->inertia >= 0) ? DYAD_CYL_FIELD_LINK_INERTIA
           : !cyl_finite2(l->force)                       ? DYAD_CYL_FIELD_LINK_FORCE
           : !cyl_finite(l->moment)                       ? DYAD_CYL_FIELD_LINK_MOMENT
           : !cyl_finite2(in->gravity)                    ? DYAD_CYL_FIELD_GRAVITY
           : !(in->singular_threshold > 0 && in->singular_threshold < 1)
               ? DYAD_CYL_FIELD_SINGULAR_THRESHOLD
           : !(cyl_finite(in->mount_amplification) && in->mount_amplification >= 0)
               ? DYAD_CYL_FIELD_MOUNT_AMPLIFICATION
               : DYAD_CYL_FIELD_NONE;
}

dyad_cylinder_field dyad_cyl_first_bad_field(const dyad_cylinder_input* in)
{
    return cyl_fields_good(in) ? DYAD_CYL_FIELD_NONE : cyl_first_bad(in);
}

static void cyl_fill_motion(dyad_point_motion* p, dyad_real v)
{
    p->position = p->velocity = p->acceleration = dyad_vec2_make(v, v);
}

/* Every output NaN (the figures too unless keep_figures), status and field as given. */
static void cyl_fill_nan(dyad_cylinder_result* r, dyad_status status, dyad_cylinder_field field,
                         int keep_figures)
{
    const dyad_real nan = (dyad_real)NAN;
    const dyad_vec2 nan2 = dyad_vec2_make(nan, nan);
    r->status = status;
    r->field = field;
    r->failure = DYAD_KIN_CLOSES;
    r->gap = 0;
    r->link_dir = r->axis = r->r_a = r->r_b = r->r_o = nan2;
    r->link_angle = r->link_omega = r->link_epsilon = nan;
    r->cylinder_angle = r->cylinder_omega = r->cylinder_epsilon = nan;
    cyl_fill_motion(&r->b, nan);
    cyl_fill_motion(&r->barrel_com, nan);
    cyl_fill_motion(&r->rod_com, nan);
    cyl_fill_motion(&r->link_com, nan);
    r->axial_force = r->n_rod = r->m_rod = r->amplification = nan;
    if (!keep_figures) {
        r->conditioning = r->closure = r->kin_amplification = nan;
    }
}

dyad_status dyad_cyl_reject(dyad_cylinder_result* value, dyad_cylinder_result* rate,
                            dyad_status status, dyad_cylinder_field field, int keep_figures)
{
    if (value != NULL) {
        cyl_fill_nan(value, status, field, keep_figures);
    }
    if (rate != NULL && rate != value) {
        cyl_fill_nan(rate, status, field, keep_figures);
    }
    return status;
}

int dyad_cyl_outputs_finite(const dyad_cylinder_result* r)
{
    return dyad_cyl_outputs_residue(r) == 0;
}

dyad_status dyad_cylinder(const dyad_cylinder_input* input, dyad_cylinder_result* result)
{
    return cyl_run_plain(input, input, result, result);
}

#else /* the formulas, over the pass's scalar */

#ifndef DYAD_CYL_FIELD_CHECKS /* once, whatever the passes */
/* dyad_cylinder_input_default's values: pin_b (1, 0), length 1, branch +1, the default
 * threshold, everything else 0. */
#define DYAD_CYL_INPUT_DEFAULTS \
    {.pin_b = {1, 0},           \
     .length = 1,               \
     .branch = 1,               \
     .singular_threshold = DYAD_DEFAULT_SINGULAR_THRESHOLD}

/* x - x: 0 for a finite x, NaN otherwise; a sum of them is 0 where all are finite. */
static inline dyad_real dyad_cyl_part_residue(const dyad_cylinder_part* p)
{
    return (p->mass - p->mass) + (p->com - p->com) + (p->inertia - p->inertia);
}

static inline dyad_real dyad_cyl_link_residue(const dyad_cylinder_link* l)
{
    return (l->mass - l->mass) + dyad_kin_residue(l->com) + (l->inertia - l->inertia) +
           dyad_kin_residue(l->force) + (l->moment - l->moment);
}

/* Each check dyad_cyl_first_bad_field makes, all at once, without a branch per field:
 * CHECK(condition) for each. */
#define DYAD_CYL_FIELD_CHECKS(in, CHECK)                                                     \
    do {                                                                                     \
        CHECK(dyad_kin_point_residue(&(in)->a) + dyad_kin_point_residue(&(in)->o) +          \
                  dyad_kin_residue((in)->pin_b) + ((in)->length - (in)->length) +            \
                  ((in)->rate - (in)->rate) + ((in)->accel - (in)->accel) +                  \
                  dyad_cyl_part_residue(&(in)->barrel) + dyad_cyl_part_residue(&(in)->rod) + \
                  dyad_cyl_link_residue(&(in)->link) + dyad_kin_residue((in)->gravity) +     \
                  ((in)->mount_amplification - (in)->mount_amplification) ==                 \
              0);                                                                            \
        CHECK(dyad_dot((in)->pin_b, (in)->pin_b) > 0);                                       \
        CHECK((in)->length > 0);                                                             \
        CHECK(((in)->branch == 1) | ((in)->branch == -1));                                   \
        CHECK((in)->barrel.mass >= 0);                                                       \
        CHECK((in)->barrel.inertia >= 0);                                                    \
        CHECK((in)->rod.mass >= 0);                                                          \
        CHECK((in)->rod.inertia >= 0);                                                       \
        CHECK((in)->link.mass >= 0);                                                         \
        CHECK((in)->link.inertia >= 0);                                                      \
        CHECK((in)->singular_threshold > 0);                                                 \
        CHECK((in)->singular_threshold < 1);                                                 \
        CHECK((in)->mount_amplification >= 0);                                               \
    } while (0)

/* The four motions of a result (B and the centres of mass), one after the other: one
 * array of reals. */
#define CYL_MOTION_REALS 24
typedef char cyl_motions_are_contiguous[offsetof(dyad_cylinder_result, link_com) +
                                                    sizeof(dyad_point_motion) -
                                                    offsetof(dyad_cylinder_result, b) ==
                                                CYL_MOTION_REALS * sizeof(dyad_real)
                                            ? 1
                                            : -1];

/* 0 where every output dyad_cylinder checks is finite (x - x is 0 for a finite x and NaN
 * otherwise: the sum of them is 0 where all are). */
static inline dyad_real dyad_cyl_outputs_residue(const dyad_cylinder_result* r)
{
    const dyad_real* v =
        (const dyad_real*)(const void*)((const char*)r + offsetof(dyad_cylinder_result, b));
    return dyad_residue_of(v, CYL_MOTION_REALS) + (r->link_omega - r->link_omega) +
           (r->link_epsilon - r->link_epsilon) + (r->cylinder_omega - r->cylinder_omega) +
           (r->cylinder_epsilon - r->cylinder_epsilon) + (r->axial_force - r->axial_force) +
           (r->r_a.x - r->r_a.x) + (r->r_a.y - r->r_a.y) + (r->r_b.x - r->r_b.x) +
           (r->r_b.y - r->r_b.y) + (r->r_o.x - r->r_o.x) + (r->r_o.y - r->r_o.y) +
           (r->n_rod - r->n_rod) + (r->m_rod - r->m_rod);
}
#endif

dyad_cylinder_field dyad_cyl_first_bad_field(const dyad_cylinder_input* in);
dyad_status dyad_cyl_reject(dyad_cylinder_result* value, dyad_cylinder_result* rate,
                            dyad_status status, dyad_cylinder_field field, int keep_figures);
int dyad_cyl_outputs_finite(const dyad_cylinder_result* r);

/* A body on its pin: mass, inertia, active load, centre of mass at pin + q. */
typedef struct DYAD_KIN(cyl_body) {
    dyad_ks mass, inertia, moment;
    dyad_kv force;
} DYAD_KIN(cyl_body);

/* Its resultant: the force F, the moment M about the pin, and their sizes. */
typedef struct DYAD_KIN(cyl_load) {
    dyad_kv f;
    dyad_ks m, f_size, m_size;
} DYAD_KIN(cyl_load);

/* The inputs on the pass's scalar. */
typedef struct DYAD_KIN(cyl_in) {
    kin_motion a, o;
    dyad_kv pin_b, gravity;
    kin_coord s;
    dyad_ks com_c, com_r;
    dyad_kv com_l;
    DYAD_KIN(cyl_body) barrel, rod, link;
    dyad_ks mount_amp;
    dyad_real branch, threshold;
} DYAD_KIN(cyl_in);

/* What the formulas find. */
typedef struct DYAD_KIN(cyl_state) {
    dyad_kin_failure failure;
    dyad_ks gap, conditioning, closure, size, kin_amp, amp, den, r_b;
    dyad_kv e, u, i_l;
    dyad_ks w_l, e_l, w_c, e_c;
    kin_motion b, s_c, s_r, s_l;
    dyad_ks f_ax, n, m;
    dyad_kv r_a, r_bf, r_o;
} DYAD_KIN(cyl_state);

DYAD_KIN_STEP kin_motion DYAD_KIN(cyl_motion_in)(const dyad_point_motion* v,
                                                 const dyad_point_motion* s)
{
    kin_motion m;
    (void)s; /* the seed: read on the dual pass only */
    m.pos = kv_in(v->position, s->position);
    m.vel = kv_in(v->velocity, s->velocity);
    m.acc = kv_in(v->acceleration, s->acceleration);
    return m;
}

DYAD_KIN_STEP DYAD_KIN(cyl_body)
    DYAD_KIN(cyl_body_in)(dyad_real mass, dyad_real dmass, dyad_real inertia, dyad_real dinertia)
{
    DYAD_KIN(cyl_body) b;
    (void)dmass, (void)dinertia;
    b.mass = ks_in(mass, dmass);
    b.inertia = ks_in(inertia, dinertia);
    b.moment = ks_c(0);
    b.force = kv_c(dyad_vec2_make(0, 0));
    return b;
}

DYAD_KIN_STEP void DYAD_KIN(cyl_load_input)(const dyad_cylinder_input* v,
                                            const dyad_cylinder_input* s, DYAD_KIN(cyl_in) * in)
{
    in->a = DYAD_KIN(cyl_motion_in)(&v->a, &s->a);
    in->o = DYAD_KIN(cyl_motion_in)(&v->o, &s->o);
    in->pin_b = kv_in(v->pin_b, s->pin_b);
    in->gravity = kv_in(v->gravity, s->gravity);
    in->s = DYAD_KIN(dyad_kin_coord_of)(ks_in(v->length, s->length), ks_in(v->rate, s->rate),
                                        ks_in(v->accel, s->accel));
    in->com_c = ks_in(v->barrel.com, s->barrel.com);
    in->com_r = ks_in(v->rod.com, s->rod.com);
    in->com_l = kv_in(v->link.com, s->link.com);
    in->barrel =
        DYAD_KIN(cyl_body_in)(v->barrel.mass, s->barrel.mass, v->barrel.inertia, s->barrel.inertia);
    in->rod = DYAD_KIN(cyl_body_in)(v->rod.mass, s->rod.mass, v->rod.inertia, s->rod.inertia);
    in->link = DYAD_KIN(cyl_body_in)(v->link.mass, s->link.mass, v->link.inertia, s->link.inertia);
    in->link.force = kv_in(v->link.force, s->link.force);
    in->link.moment = ks_in(v->link.moment, s->link.moment);
    in->mount_amp = ks_in(v->mount_amplification, s->mount_amplification);
    in->branch = (dyad_real)v->branch;
    in->threshold = v->singular_threshold;
}

/* The triangle O, A, B (the derivation at the top). */
DYAD_KIN_STEP dyad_kin_failure DYAD_KIN(cyl_position)(const DYAD_KIN(cyl_in) * in,
                                                      DYAD_KIN(cyl_state) * st)
{
    const dyad_kv d = kv_sub(in->a.pos, in->o.pos);
    const dyad_ks l2 = kv_dot(d, d), len = ks_sqrt(l2);
    const dyad_ks r = ks_sqrt(kv_dot(in->pin_b, in->pin_b)), s = in->s.q;
    const dyad_ks reach = ks_add(r, s), spread = ks_abs(ks_sub(r, s));
    const dyad_ks far = ks_sub(reach, len), near = ks_sub(len, spread);
    const dyad_ks diff2 = ks_mul(ks_sub(r, s), reach); /* r_B^2 - s^2 */
    const dyad_kv conj = kv_make(ks_div(kv_x(in->pin_b), r), ks_neg(ks_div(kv_y(in->pin_b), r)));
    dyad_ks twice, h;
    dyad_kv ud, v;
    st->r_b = r;
    if (ks_val(far) < 0 || ks_val(near) < 0) {
        st->failure = ks_val(far) < 0 ? DYAD_KIN_TOO_FAR : DYAD_KIN_TOO_CLOSE;
        st->gap = ks_neg(ks_val(far) < 0 ? far : near);
        return st->failure;
    }
    st->size = ks_add(reach, len);
    st->closure = ks_div(ks_val(far) < ks_val(near) ? far : near, st->size);
    if (ks_val(len) == 0) {
        st->conditioning = st->den = ks_c(0); /* A on O: B anywhere on its circle */
        return DYAD_KIN_CLOSES;
    }
    twice = ks_add(len, len);
    ud = kv_scale(ks_div(ks_c(1), len), d);
    v = kv_perp(ud);
    h = ks_div(ks_sqrt(ks_mul(ks_mul(far, ks_add(reach, len)), ks_mul(near, ks_add(len, spread)))),
               twice);
    h = ks_mul(ks_c(in->branch), h);
    st->e = kv_scale(ks_div(ks_c(1), r),
                     DYAD_KIN(dyad_kin_combine)(ks_div(ks_add(diff2, l2), twice), ud, h, v));
    st->u = kv_scale(ks_div(ks_c(1), s),
                     DYAD_KIN(dyad_kin_combine)(ks_div(ks_sub(diff2, l2), twice), ud, h, v));
    st->i_l = kv_cmul(st->e, conj);
    st->den = ks_div(ks_mul(h, len), ks_mul(r, s)); /* e x u */
    st->conditioning = ks_abs(st->den);
    return DYAD_KIN_CLOSES;
}

/* The motion's round-off bound: the triangle's own, and the mounts' carried in,
 * their positions' round-off (relative to their distance from the origin) taken
 * relative to the triangle's size (dyad_kin_amplification does the same). */
DYAD_KIN_STEP dyad_ks DYAD_KIN(cyl_kin_amplification)(const DYAD_KIN(cyl_in) * in,
                                                      const DYAD_KIN(cyl_state) * st)
{
    const dyad_ks own =
        ks_add(ks_add(ks_c(1), ks_div(ks_c(1), st->closure)), ks_div(ks_c(1), st->conditioning));
    const dyad_ks far = ks_add(kv_norm1(in->a.pos), kv_norm1(in->o.pos));
    const dyad_ks carried = ks_mul(in->mount_amp, ks_add(ks_c(1), ks_div(far, st->size)));
    return ks_mul(own, ks_add(ks_c(1), carried));
}

/* B from O along the link and from A along the cylinder, with the rates in st. */
DYAD_KIN_STEP void DYAD_KIN(cyl_sides)(const DYAD_KIN(cyl_in) * in, const DYAD_KIN(cyl_state) * st,
                                       kin_motion* from_o, kin_motion* from_a)
{
    const kin_coord r = DYAD_KIN(dyad_kin_coord_of)(st->r_b, ks_c(0), ks_c(0));
    *from_o = DYAD_KIN(dyad_kin_arm)(&in->o, r, st->e, st->w_l, st->e_l);
    *from_a = DYAD_KIN(dyad_kin_arm)(&in->a, in->s, st->u, st->w_c, st->e_c);
}

DYAD_KIN_STEP void DYAD_KIN(cyl_motion)(const DYAD_KIN(cyl_in) * in, DYAD_KIN(cyl_state) * st)
{
    const dyad_kv col_l = kv_scale(st->r_b, kv_perp(st->e));
    const dyad_kv col_c = kv_scale(ks_neg(in->s.q), kv_perp(st->u));
    const kin_coord rod = DYAD_KIN(dyad_kin_coord_of)(ks_neg(in->com_r), ks_c(0), ks_c(0));
    const kin_coord barrel = DYAD_KIN(dyad_kin_coord_of)(in->com_c, ks_c(0), ks_c(0));
    kin_motion from_o, from_a;
    st->w_l = st->e_l = st->w_c = st->e_c = ks_c(0);
    DYAD_KIN(cyl_sides)(in, st, &from_o, &from_a);
    DYAD_KIN(dyad_kin_solve2)(col_l, col_c, kv_sub(from_a.vel, from_o.vel), &st->w_l, &st->w_c);
    DYAD_KIN(cyl_sides)(in, st, &from_o, &from_a);
    DYAD_KIN(dyad_kin_solve2)(col_l, col_c, kv_sub(from_a.acc, from_o.acc), &st->e_l, &st->e_c);
    DYAD_KIN(cyl_sides)(in, st, &st->b, &from_a);
    st->s_c = DYAD_KIN(dyad_kin_arm)(&in->a, barrel, st->u, st->w_c, st->e_c);
    st->s_r = DYAD_KIN(dyad_kin_arm)(&st->b, rod, st->u, st->w_c, st->e_c);
    st->s_l = DYAD_KIN(dyad_kin_on_link)(&in->o, st->i_l, st->w_l, st->e_l, in->com_l);
}

/* A body's resultant about its pin p, its centre of mass at p + q (the derivation). */
DYAD_KIN_STEP DYAD_KIN(cyl_load)
    DYAD_KIN(cyl_reduce)(const DYAD_KIN(cyl_body) * b, const kin_motion* p, dyad_kv q,
                         dyad_ks omega, dyad_ks epsilon, dyad_kv gravity)
{
    const dyad_kv tangential = kv_add(p->acc, kv_scale(epsilon, kv_perp(q)));
    const dyad_kv without = kv_add(b->force, kv_scale(b->mass, kv_sub(gravity, tangential)));
    const dyad_ks spin = ks_mul(b->mass, ks_mul(omega, omega));
    const dyad_ks lever = kv_norm1(q), turn = ks_abs(epsilon);
    const dyad_ks accel = ks_add(ks_add(kv_norm1(gravity), kv_norm1(p->acc)), ks_mul(turn, lever));
    const dyad_ks without_size = ks_add(kv_norm1(b->force), ks_mul(b->mass, accel));
    DYAD_KIN(cyl_load) l;
    l.f = kv_add(without, kv_scale(spin, q));
    l.m = ks_add(ks_sub(b->moment, ks_mul(b->inertia, epsilon)), kv_cross(q, without));
    l.f_size = ks_add(without_size, ks_mul(spin, lever));
    l.m_size =
        ks_add(ks_add(ks_abs(b->moment), ks_mul(b->inertia, turn)), ks_mul(lever, without_size));
    return l;
}

/* size / largest in [1, 1/eps], as dyad_data_factor. */
DYAD_KIN_STEP dyad_ks DYAD_KIN(cyl_data_factor)(dyad_ks size, dyad_ks largest)
{
    if (!(ks_val(size) <= ks_val(largest) * (1 / DYAD_REAL_EPSILON))) {
        return ks_c(1 / DYAD_REAL_EPSILON);
    }
    return ks_val(size) > ks_val(largest) ? ks_div(size, largest) : ks_c(1);
}

DYAD_KIN_STEP dyad_ks DYAD_KIN(cyl_max)(dyad_ks a, dyad_ks b)
{
    return ks_val(a) > ks_val(b) ? a : b;
}

DYAD_KIN_STEP dyad_ks DYAD_KIN(cyl_largest)(dyad_kv a)
{
    return DYAD_KIN(cyl_max)(ks_abs(kv_x(a)), ks_abs(kv_y(a)));
}

/* amplification = data factor x kin_amplification, from the loads' sizes. */
DYAD_KIN_STEP void DYAD_KIN(cyl_amplification)(const DYAD_KIN(cyl_load) * c,
                                               const DYAD_KIN(cyl_load) * r,
                                               const DYAD_KIN(cyl_load) * l,
                                               const DYAD_KIN(cyl_in) * in,
                                               DYAD_KIN(cyl_state) * st)
{
    const dyad_ks n_size = ks_div(ks_add(c->m_size, r->m_size), in->s.q);
    const dyad_ks q_size = ks_add(n_size, r->f_size);
    const dyad_ks ax_size =
        ks_div(ks_add(l->m_size, ks_mul(st->r_b, q_size)), ks_mul(st->r_b, st->conditioning));
    const dyad_ks force_size =
        ks_add(ks_add(ax_size, q_size), ks_add(ks_add(n_size, c->f_size), l->f_size));
    dyad_ks largest = DYAD_KIN(cyl_max)(ks_abs(st->f_ax), ks_abs(st->n));
    dyad_ks factor;
    largest = DYAD_KIN(cyl_max)(largest, DYAD_KIN(cyl_largest)(st->r_a));
    largest = DYAD_KIN(cyl_max)(largest, DYAD_KIN(cyl_largest)(st->r_bf));
    largest = DYAD_KIN(cyl_max)(largest, DYAD_KIN(cyl_largest)(st->r_o));
    factor = DYAD_KIN(cyl_max)(DYAD_KIN(cyl_data_factor)(force_size, largest),
                               DYAD_KIN(cyl_data_factor)(r->m_size, ks_abs(st->m)));
    st->amp = ks_mul(factor, st->kin_amp);
}

/* The nine unknowns, each from one equation (the derivation at the top). */
DYAD_KIN_STEP void DYAD_KIN(cyl_reactions)(const DYAD_KIN(cyl_in) * in, DYAD_KIN(cyl_state) * st)
{
    const dyad_kv j = kv_perp(st->u);
    const dyad_kv q_c = kv_scale(in->com_c, st->u), q_r = kv_scale(ks_neg(in->com_r), st->u);
    const dyad_kv q_l =
        DYAD_KIN(dyad_kin_combine)(kv_x(in->com_l), st->i_l, kv_y(in->com_l), kv_perp(st->i_l));
    const DYAD_KIN(cyl_load) c =
        DYAD_KIN(cyl_reduce)(&in->barrel, &in->a, q_c, st->w_c, st->e_c, in->gravity);
    const DYAD_KIN(cyl_load) r =
        DYAD_KIN(cyl_reduce)(&in->rod, &st->b, q_r, st->w_c, st->e_c, in->gravity);
    const DYAD_KIN(cyl_load) l =
        DYAD_KIN(cyl_reduce)(&in->link, &in->o, q_l, st->w_l, st->e_l, in->gravity);
    dyad_kv q;
    st->m = ks_neg(r.m);
    st->n = ks_div(ks_add(c.m, r.m), in->s.q);
    q = kv_add(kv_scale(st->n, j), r.f);
    st->f_ax =
        ks_neg(ks_div(ks_add(l.m, ks_mul(st->r_b, kv_cross(st->e, q))), ks_mul(st->r_b, st->den)));
    st->r_bf = kv_add(kv_scale(st->f_ax, st->u), q);
    st->r_o = kv_neg(kv_add(st->r_bf, l.f));
    st->r_a = kv_sub(DYAD_KIN(dyad_kin_combine)(st->f_ax, st->u, st->n, j), c.f);
    DYAD_KIN(cyl_amplification)(&c, &r, &l, in, st);
}

DYAD_KIN_STEP dyad_ks DYAD_KIN(cyl_angle)(dyad_kv a)
{
#if DYAD_KIN_IS_DUAL
    return dyad_kd_atan2(kv_y(a), kv_x(a));
#else
    return DYAD_ATAN2(a.y, a.x);
#endif
}

DYAD_KIN_STEP void DYAD_KIN(cyl_put_motion)(const kin_motion* a, dyad_point_motion* to,
                                            dyad_point_motion* rate)
{
    (void)rate;
    kv_put(a->pos, &to->position, &rate->position);
    kv_put(a->vel, &to->velocity, &rate->velocity);
    kv_put(a->acc, &to->acceleration, &rate->acceleration);
}

DYAD_KIN_STEP void DYAD_KIN(cyl_put_figures)(const DYAD_KIN(cyl_state) * st,
                                             dyad_cylinder_result* value,
                                             dyad_cylinder_result* rate)
{
    (void)rate;
    ks_put(st->conditioning, &value->conditioning, &rate->conditioning);
    ks_put(st->closure, &value->closure, &rate->closure);
    ks_put(st->kin_amp, &value->kin_amplification, &rate->kin_amplification);
}

/* Every output but the two angles (whose atan2 a batch's loop takes after it). */
DYAD_KIN_STEP void DYAD_KIN(cyl_store_but_angles)(const DYAD_KIN(cyl_state) * st,
                                                  dyad_cylinder_result* value,
                                                  dyad_cylinder_result* rate)
{
    (void)rate;
    kv_put(st->i_l, &value->link_dir, &rate->link_dir);
    ks_put(st->w_l, &value->link_omega, &rate->link_omega);
    ks_put(st->e_l, &value->link_epsilon, &rate->link_epsilon);
    kv_put(st->u, &value->axis, &rate->axis);
    ks_put(st->w_c, &value->cylinder_omega, &rate->cylinder_omega);
    ks_put(st->e_c, &value->cylinder_epsilon, &rate->cylinder_epsilon);
    DYAD_KIN(cyl_put_motion)(&st->b, &value->b, &rate->b);
    DYAD_KIN(cyl_put_motion)(&st->s_c, &value->barrel_com, &rate->barrel_com);
    DYAD_KIN(cyl_put_motion)(&st->s_r, &value->rod_com, &rate->rod_com);
    DYAD_KIN(cyl_put_motion)(&st->s_l, &value->link_com, &rate->link_com);
    ks_put(st->f_ax, &value->axial_force, &rate->axial_force);
    kv_put(st->r_a, &value->r_a, &rate->r_a);
    kv_put(st->r_bf, &value->r_b, &rate->r_b);
    kv_put(st->r_o, &value->r_o, &rate->r_o);
    ks_put(st->n, &value->n_rod, &rate->n_rod);
    ks_put(st->m, &value->m_rod, &rate->m_rod);
    ks_put(st->amp, &value->amplification, &rate->amplification);
    DYAD_KIN(cyl_put_figures)(st, value, rate);
}

DYAD_KIN_STEP void DYAD_KIN(cyl_store)(const DYAD_KIN(cyl_state) * st, dyad_cylinder_result* value,
                                       dyad_cylinder_result* rate)
{
    DYAD_KIN(cyl_store_but_angles)(st, value, rate);
    ks_put(DYAD_KIN(cyl_angle)(st->i_l), &value->link_angle, &rate->link_angle);
    ks_put(DYAD_KIN(cyl_angle)(st->u), &value->cylinder_angle, &rate->cylinder_angle);
}

/* The whole of dyad_cylinder (plain pass: seed = input, rate = value) and of
 * its tangent (dual pass). */
DYAD_KIN_STEP dyad_status DYAD_KIN(cyl_run)(const dyad_cylinder_input* input,
                                            const dyad_cylinder_input* seed,
                                            dyad_cylinder_result* value, dyad_cylinder_result* rate)
{
    static const DYAD_KIN(cyl_state) cleared;
    DYAD_KIN(cyl_state) st = cleared;
    DYAD_KIN(cyl_in) in;
    dyad_cylinder_field bad;
    if (value == NULL || rate == NULL) {
        return dyad_cyl_reject(value, NULL, DYAD_STATUS_INVALID_INPUT, DYAD_CYL_FIELD_INPUT, 0);
    }
    bad = input == NULL || seed == NULL ? DYAD_CYL_FIELD_INPUT : dyad_cyl_first_bad_field(input);
    if (bad != DYAD_CYL_FIELD_NONE) {
        return dyad_cyl_reject(value, rate, DYAD_STATUS_INVALID_INPUT, bad, 0);
    }
    DYAD_KIN(cyl_load_input)(input, seed, &in);
    if (DYAD_KIN(cyl_position)(&in, &st) != DYAD_KIN_CLOSES) {
        dyad_cyl_reject(value, rate, DYAD_STATUS_CANNOT_ASSEMBLE, DYAD_CYL_FIELD_NONE, 0);
        value->failure = rate->failure = st.failure;
        ks_put(st.gap, &value->gap, &rate->gap);
        return DYAD_STATUS_CANNOT_ASSEMBLE;
    }
    st.kin_amp = DYAD_KIN(cyl_kin_amplification)(&in, &st);
    if (!(ks_val(st.kin_amp) * in.threshold <= 1)) {
        dyad_cyl_reject(value, rate, DYAD_STATUS_SINGULAR, DYAD_CYL_FIELD_NONE, 1);
        DYAD_KIN(cyl_put_figures)(&st, value, rate);
        return DYAD_STATUS_SINGULAR;
    }
    DYAD_KIN(cyl_motion)(&in, &st);
    DYAD_KIN(cyl_reactions)(&in, &st);
    DYAD_KIN(cyl_store)(&st, value, rate);
    if (!dyad_cyl_outputs_finite(value)) {
        return dyad_cyl_reject(value, rate, DYAD_STATUS_OUT_OF_RANGE, DYAD_CYL_FIELD_NONE, 0);
    }
    value->status = rate->status = DYAD_STATUS_OK;
    value->field = rate->field = DYAD_CYL_FIELD_NONE;
    value->failure = rate->failure = DYAD_KIN_CLOSES;
    value->gap = rate->gap = 0;
    return DYAD_STATUS_OK;
}

#if !DYAD_KIN_IS_DUAL
/* One sample of a batch (dyad_lanes.h): cyl_run's steps without a branch, so that a loop
 * over samples vectorises. Every check is made and counted: 0 is returned where
 * dyad_cylinder gives DYAD_STATUS_OK, and then `value` holds its outputs bit for bit but
 * for the two angles, which are not written (an angle's atan2, a call, would keep the loop
 * from vectorising: a scene takes them from link_dir and axis after it), nor are the
 * status, field, failure and gap; elsewhere the count of the failed checks, and outputs
 * that mean nothing (dyad_cylinder says why). The branch comes as the real `branch`, as
 * dyad_kin_lane's does (dyad_kin_generic.h says why). */
DYAD_CLOSED_FORM dyad_real dyad_cylinder_lane(const dyad_cylinder_input* input, dyad_real branch,
                                              dyad_cylinder_result* value)
{
    static const DYAD_KIN(cyl_state) cleared;
    DYAD_KIN(cyl_state) st = cleared;
    DYAD_KIN(cyl_in) in;
    dyad_real bad = 0;
#define DYAD_CYL_COUNT_UNLESS(condition) bad += DYAD_FAILED(condition)
    DYAD_CYL_FIELD_CHECKS(input, DYAD_CYL_COUNT_UNLESS);
#undef DYAD_CYL_COUNT_UNLESS
    DYAD_KIN(cyl_load_input)(input, input, &in);
    bad += DYAD_FAILED((branch == 1) | (branch == -1));
    in.branch = branch;
    bad += DYAD_FAILED(DYAD_KIN(cyl_position)(&in, &st) == DYAD_KIN_CLOSES);
    st.kin_amp = DYAD_KIN(cyl_kin_amplification)(&in, &st);
    bad += DYAD_FAILED(st.kin_amp * in.threshold <= 1);
    DYAD_KIN(cyl_motion)(&in, &st);
    DYAD_KIN(cyl_reactions)(&in, &st);
    DYAD_KIN(cyl_store_but_angles)(&st, value, value);
    return bad + DYAD_FAILED(dyad_cyl_outputs_residue(value) == 0);
}
#endif

#endif
