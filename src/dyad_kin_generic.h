/* dyadfmu: the kinematics' shared formulas over a scalar of choice. Not part
 * of the public API. No include guard: included once per scalar ("pass").
 *
 * Without DYAD_KIN_DUAL the scalar dyad_ks is dyad_real and the vector dyad_kv
 * is dyad_vec2: the plain pass, what dyad_kinematics() runs. With it they are
 * the dual number dyad_dual and dyad_dual_vec2 (dyad_kin_internal.h): the
 * value and its derivative along a seed, what dyad_kinematics_tangent() runs.
 * The formulas are written once, in the operations below (ks_ on scalars,
 * kv_ on vectors); on the plain pass they are the plain operations and cost
 * nothing more. A branch on a value (ks_val) takes the same side in both
 * passes. DYAD_KIN(name) gives a function or type the pass's suffix, _plain or
 * _dual. Each type's file includes this header and then its own formulas
 * twice, once per pass (see dyad_kin_rrr.c).
 *
 * The motion of the dyad is built from one step, kin_arm: a point B moving as
 * given and a vector q u from it, u turning at omega, epsilon while q slides:
 *      P = B + q u,
 *      dP/dt   = dB/dt + q' u + q omega k0 x u,
 *      d2P/dt2 = d2B/dt2 + q'' u + (2 q' omega + q epsilon) k0 x u - q omega^2 u
 * (u' = omega k0 x u, (k0 x u)' = -omega u): the slide, the Coriolis term
 * 2 q' omega k0 x u, the tangential and the centripetal term. A pair point on
 * a guide is kin_arm of the guide's point with the slide; E is kin_arm of a
 * pair point with the link's length; a centre of mass is kin_arm with q = 1
 * and u the offset in the global frame.
 */

#undef DYAD_KIN
#undef DYAD_KIN_IS_DUAL
#undef dyad_ks
#undef dyad_kv
#undef ks_c
#undef ks_val
#undef ks_add
#undef ks_sub
#undef ks_mul
#undef ks_div
#undef ks_neg
#undef ks_sqrt
#undef ks_abs
#undef ks_in
#undef ks_put
#undef kv_c
#undef kv_val
#undef kv_make
#undef kv_x
#undef kv_y
#undef kv_add
#undef kv_sub
#undef kv_neg
#undef kv_scale
#undef kv_perp
#undef kv_dot
#undef kv_norm1
#undef kv_cross
#undef kv_cmul
#undef kv_in
#undef kv_in_unit
#undef kv_put
#undef kin_motion
#undef kin_coord
#undef kin_mount
#undef kin_in
#undef kin_state
#undef kin_position_fn
#undef kin_motion_fn
#undef kin_sides_fn

#ifdef DYAD_KIN_DUAL
#define DYAD_KIN(name)      name##_dual
#define DYAD_KIN_IS_DUAL    1
#define dyad_ks             dyad_dual
#define dyad_kv             dyad_dual_vec2
#define ks_c                dyad_dual_const
#define ks_val(a)           ((a).v)
#define ks_add              dyad_dual_add
#define ks_sub              dyad_kd_sub
#define ks_mul              dyad_dual_mul
#define ks_div              dyad_dual_div
#define ks_neg              dyad_kd_neg
#define ks_sqrt             dyad_kd_sqrt
#define ks_abs              dyad_kd_abs
#define ks_in(v, s)         dyad_dual_make((v), (s))
#define ks_put(a, to, rate) dyad_kd_put((a), (to), (rate))
#define kv_c                dyad_kdv_const
#define kv_val(a)           ((a).v)
#define kv_make             dyad_kdv_make
#define kv_x                dyad_kdv_x
#define kv_y                dyad_kdv_y
#define kv_add              dyad_kdv_add
#define kv_sub              dyad_kdv_sub
#define kv_neg              dyad_kdv_neg
#define kv_scale            dyad_kdv_scale
#define kv_perp             dyad_kdv_perp
#define kv_dot              dyad_kdv_dot
#define kv_norm1            dyad_kdv_norm1
#define kv_cross            dyad_kdv_cross
#define kv_cmul             dyad_kdv_cmul
#define kv_in(v, s)         dyad_kdv_in((v), (s))
#define kv_in_unit(v, s)    dyad_kdv_in_unit((v), (s))
#define kv_put(a, to, rate) dyad_kdv_put((a), (to), (rate))

#else
#define DYAD_KIN(name)      name##_plain
#define DYAD_KIN_IS_DUAL    0
#define dyad_ks             dyad_real
#define dyad_kv             dyad_vec2
#define ks_c(a)             ((dyad_real)(a))
#define ks_val(a)           (a)
#define ks_add(a, b)        ((a) + (b))
#define ks_sub(a, b)        ((a) - (b))
#define ks_mul(a, b)        ((a) * (b))
#define ks_div(a, b)        ((a) / (b))
#define ks_neg(a)           (-(a))
#define ks_sqrt             DYAD_SQRT
#define ks_abs              DYAD_FABS
#define ks_in(v, s)         (v)
#define ks_put(a, to, rate) ((void)(*(to) = (a)))
#define kv_c(a)             (a)
#define kv_val(a)           (a)
#define kv_make             dyad_vec2_make
#define kv_x(a)             ((a).x)
#define kv_y(a)             ((a).y)
#define kv_add              dyad_add
#define kv_sub              dyad_sub
#define kv_neg              dyad_neg
#define kv_scale            dyad_scale
#define kv_perp             dyad_perp
#define kv_dot              dyad_dot
#define kv_norm1            dyad_norm1
#define kv_cross            dyad_cross
#define kv_cmul             dyad_cmul
#define kv_in(v, s)         (v)
#define kv_in_unit(v, s)    dyad_unit_of(v)
#define kv_put(a, to, rate) ((void)(*(to) = (a)))
#endif

#define kin_motion      DYAD_KIN(dyad_kin_motion)
#define kin_coord       DYAD_KIN(dyad_kin_coord)
#define kin_mount       DYAD_KIN(dyad_kin_mount)
#define kin_in          DYAD_KIN(dyad_kin_in)
#define kin_state       DYAD_KIN(dyad_kin_state)
#define kin_position_fn DYAD_KIN(dyad_kin_position_fn)
#define kin_motion_fn   DYAD_KIN(dyad_kin_motion_fn)
#define kin_sides_fn    DYAD_KIN(dyad_kin_sides_fn)

/* Position (m), velocity (m/s), acceleration (m/s^2) of a point. */
typedef struct kin_motion {
    dyad_kv pos, vel, acc;
} kin_motion;

/* A length or slide q (m) with its rates q' (m/s) and q'' (m/s^2). */
typedef struct kin_coord {
    dyad_ks q, dq, ddq;
} kin_coord;

/* An external link where it meets the dyad: its point, and where the pair
 * slides its guide (unit) turning at omega, epsilon; zero where it does not. */
typedef struct kin_mount {
    kin_motion point;
    dyad_kv guide;
    dyad_ks omega, epsilon;
} kin_mount;

/* The inputs a type reads, turns and guides unit; what it does not read is 0. */
typedef struct kin_in {
    kin_mount k, p;
    dyad_ks l_m, l_n;
    dyad_kv turn_m, turn_n, com_m, com_n;
    dyad_real branch;    /* +1 or -1 */
    dyad_real threshold; /* singular threshold, not differentiated */
    dyad_ks mount_amp;   /* the amplification the mounts' motion carries in */
} kin_in;

/* What a type's formulas find: the assembly, then the rates. */
typedef struct kin_state {
    dyad_kin_failure failure;
    dyad_ks gap;          /* by how much the failed figure failed (m) */
    dyad_ks conditioning; /* the header's figure */
    dyad_ks closure;      /* the closure's own conditioning: distance over size */
    dyad_ks size;         /* the size of the terms the closure's distance is made of (m) */
    dyad_ks amplification;
    dyad_kv i_m, i_n;
    dyad_ks w_m, e_m, w_n, e_n;   /* omega, epsilon of the links */
    kin_coord l_m, l_n, s_k, s_p; /* lengths and slides with their rates */
    kin_motion d_m, d_n;          /* D_m, D_n as points of links m, n */
} kin_state;

/* A type's assembly: fills i_m, i_n, the lengths and slides, the conditioning;
 * or the failure and gap. */
typedef dyad_kin_failure (*kin_position_fn)(const kin_in* in, kin_state* st);
/* A type's rates, once assembled and conditioned. */
typedef void (*kin_motion_fn)(const kin_in* in, kin_state* st);
/* E seen from link m's side and from link n's, with the rates in st (those
 * not yet known 0). */
typedef void (*kin_sides_fn)(const kin_in* in, const kin_state* st, kin_motion* from_m,
                             kin_motion* from_n);

static inline kin_coord DYAD_KIN(dyad_kin_coord_of)(dyad_ks q, dyad_ks dq, dyad_ks ddq)
{
    kin_coord c;
    c.q = q;
    c.dq = dq;
    c.ddq = ddq;
    return c;
}

/* |a|. */
static inline dyad_ks DYAD_KIN(dyad_kin_norm)(dyad_kv a)
{
    return ks_sqrt(kv_dot(a, a));
}

/* s a + t b */
static inline dyad_kv DYAD_KIN(dyad_kin_combine)(dyad_ks s, dyad_kv a, dyad_ks t, dyad_kv b)
{
    return kv_add(kv_scale(s, a), kv_scale(t, b));
}

/* B + q u, u turning at omega and epsilon (the derivation at the top). */
static inline kin_motion DYAD_KIN(dyad_kin_arm)(const kin_motion* base, kin_coord q, dyad_kv u,
                                                dyad_ks omega, dyad_ks epsilon)
{
    const dyad_kv normal = kv_perp(u);
    const dyad_ks qw = ks_mul(q.q, omega);
    const dyad_ks turning = ks_add(ks_mul(ks_c(2), ks_mul(q.dq, omega)), ks_mul(q.q, epsilon));
    kin_motion p;
    p.pos = kv_add(base->pos, kv_scale(q.q, u));
    p.vel = kv_add(base->vel, DYAD_KIN(dyad_kin_combine)(q.dq, u, qw, normal));
    p.acc = kv_add(base->acc, DYAD_KIN(dyad_kin_combine)(ks_sub(q.ddq, ks_mul(qw, omega)), u,
                                                         turning, normal));
    return p;
}

/* The point at `at` in the frame {origin; dir, k0 x dir} of a link turning at
 * omega, epsilon. */
static inline kin_motion DYAD_KIN(dyad_kin_on_link)(const kin_motion* origin, dyad_kv dir,
                                                    dyad_ks omega, dyad_ks epsilon, dyad_kv at)
{
    const dyad_kv offset = DYAD_KIN(dyad_kin_combine)(kv_x(at), dir, kv_y(at), kv_perp(dir));
    return DYAD_KIN(dyad_kin_arm)(origin, DYAD_KIN(dyad_kin_coord_of)(ks_c(1), ks_c(0), ks_c(0)),
                                  offset, omega, epsilon);
}

/* A pair point sliding on the guide of mount g: its point plus s along the guide. */
static inline kin_motion DYAD_KIN(dyad_kin_on_guide)(const kin_mount* g, kin_coord s)
{
    return DYAD_KIN(dyad_kin_arm)(&g->point, s, g->guide, g->omega, g->epsilon);
}

/* x a + y b = r by Cramer's rule: x = (r x b) / (a x b), y = (a x r) / (a x b). */
static inline void DYAD_KIN(dyad_kin_solve2)(dyad_kv a, dyad_kv b, dyad_kv r, dyad_ks* x,
                                             dyad_ks* y)
{
    const dyad_ks det = kv_cross(a, b);
    *x = ks_div(kv_cross(r, b), det);
    *y = ks_div(kv_cross(a, r), det);
}

/* The rates of a type whose closure E(from m) = E(from n), differentiated,
 * reads x a + y b = r in the two unknown rates (x, y), and twice
 * differentiated the same in their derivatives (x', y'): r is the difference
 * of E's velocity (then acceleration) from the two sides with the unknowns at
 * 0. (x, x') and (y, y') point into st. */
DYAD_CLOSED_FORM void DYAD_KIN(dyad_kin_rates)(const kin_in* in, kin_state* st, kin_sides_fn sides,
                                               dyad_kv a, dyad_kv b, dyad_ks* x, dyad_ks* dx,
                                               dyad_ks* y, dyad_ks* dy)
{
    kin_motion from_m, from_n;
    *x = *dx = *y = *dy = ks_c(0);
    sides(in, st, &from_m, &from_n);
    DYAD_KIN(dyad_kin_solve2)(a, b, kv_sub(from_n.vel, from_m.vel), x, y);
    sides(in, st, &from_m, &from_n);
    DYAD_KIN(dyad_kin_solve2)(a, b, kv_sub(from_n.acc, from_m.acc), dx, dy);
}

/* A closure whose position is a root: its argument's distance from zero, over the
 * size of the terms that distance is the difference of. */
static inline void DYAD_KIN(dyad_kin_closure)(kin_state* st, dyad_ks distance, dyad_ks size)
{
    st->closure = ks_val(size) > 0 ? ks_div(distance, size) : ks_c(0); /* 0: degenerate */
    st->size = size;
}

/* The bound of the motion's round-off (kinematics.h): the closure's own and the
 * velocity equations', and the mounts' carried in, where their positions' round-off
 * (relative to their distance from the origin) is taken relative to the closure's
 * size. Norms of 1, whose rates are defined everywhere. */
static inline dyad_ks DYAD_KIN(dyad_kin_amplification)(const kin_in* in, const kin_state* st)
{
    const dyad_ks own =
        ks_add(ks_add(ks_c(1), ks_div(ks_c(1), st->closure)), ks_div(ks_c(1), st->conditioning));
    const dyad_ks far = ks_add(kv_norm1(in->k.point.pos), kv_norm1(in->p.point.pos));
    const dyad_ks ratio = ks_val(far) > 0 ? ks_div(far, st->size) : ks_c(0);
    const dyad_ks carried = ks_mul(in->mount_amp, ks_add(ks_c(1), ratio));
    return ks_mul(own, ks_add(ks_c(1), carried));
}

static inline dyad_kin_failure DYAD_KIN(dyad_kin_fail)(kin_state* st, dyad_kin_failure failure,
                                                       dyad_ks gap)
{
    st->failure = failure;
    st->gap = gap;
    return failure;
}

/* ---- from the public input to the pass's, and back ------------------------------------------- */

static inline void DYAD_KIN(dyad_kin_load_mount)(const dyad_mount* v, const dyad_mount* s,
                                                 int slides, kin_mount* out)
{
    (void)s; /* the seed: read on the dual pass only */
    out->point.pos = kv_in(v->point.position, s->point.position);
    out->point.vel = kv_in(v->point.velocity, s->point.velocity);
    out->point.acc = kv_in(v->point.acceleration, s->point.acceleration);
    out->guide = slides ? kv_in_unit(v->guide, s->guide) : kv_c(dyad_vec2_make(0, 0));
    out->omega = slides ? ks_in(v->omega, s->omega) : ks_c(0);
    out->epsilon = slides ? ks_in(v->epsilon, s->epsilon) : ks_c(0);
}

/* The fields the type reads (validated), turns and guides made unit. */
static inline void DYAD_KIN(dyad_kin_load)(dyad_type type, const dyad_kin_input* v,
                                           const dyad_kin_input* s, kin_in* in)
{
    const int slides_dm = dyad_kin_slides(type, DYAD_PAIR_DM);
    const int slides_e = dyad_kin_slides(type, DYAD_PAIR_E);
    const int slides_dn = dyad_kin_slides(type, DYAD_PAIR_DN);
    const dyad_kv none = kv_c(dyad_vec2_make(0, 0));
    (void)s;
    DYAD_KIN(dyad_kin_load_mount)(&v->k, &s->k, slides_dm, &in->k);
    DYAD_KIN(dyad_kin_load_mount)(&v->p, &s->p, slides_dn, &in->p);
    in->l_m = slides_e ? ks_c(0) : ks_in(v->length_m, s->length_m);
    in->l_n = ks_in(v->length_n, s->length_n);
    in->turn_m = slides_dm ? kv_in_unit(v->turn_m, s->turn_m) : none;
    in->turn_n = slides_e || slides_dn ? kv_in_unit(v->turn_n, s->turn_n) : none;
    in->com_m = kv_in(v->com_m, s->com_m);
    in->com_n = kv_in(v->com_n, s->com_n);
    in->branch =
        type == DYAD_RRR || type == DYAD_RRT || type == DYAD_RTR ? (dyad_real)v->branch : 1;
    in->threshold = v->singular_threshold;
    in->mount_amp = ks_in(v->mount_amplification, s->mount_amplification);
}

/* The state before a type's formulas: constant lengths, no slide, the pair
 * points where the mounts are. */
static inline void DYAD_KIN(dyad_kin_start)(const kin_in* in, kin_state* st)
{
    const dyad_ks zero = ks_c(0);
    st->failure = DYAD_KIN_CLOSES;
    st->gap = st->conditioning = st->amplification = zero;
    st->closure = ks_c(1); /* a closure without a root; a type with one sets it */
    st->size = zero;
    st->i_m = st->i_n = kv_c(dyad_vec2_make(0, 0));
    st->w_m = st->e_m = st->w_n = st->e_n = zero;
    st->l_m = DYAD_KIN(dyad_kin_coord_of)(in->l_m, zero, zero);
    st->l_n = DYAD_KIN(dyad_kin_coord_of)(in->l_n, zero, zero);
    st->s_k = st->s_p = DYAD_KIN(dyad_kin_coord_of)(zero, zero, zero);
    st->d_m = in->k.point;
    st->d_n = in->p.point;
}

static inline void DYAD_KIN(dyad_kin_put_motion)(const kin_motion* a, dyad_point_motion* to,
                                                 dyad_point_motion* rate)
{
    (void)rate;
    kv_put(a->pos, &to->position, &rate->position);
    kv_put(a->vel, &to->velocity, &rate->velocity);
    kv_put(a->acc, &to->acceleration, &rate->acceleration);
}

static inline void DYAD_KIN(dyad_kin_put_coord)(const kin_coord* a, dyad_real* q, dyad_real* dq,
                                                dyad_real* ddq, dyad_real* rate_q,
                                                dyad_real* rate_dq, dyad_real* rate_ddq)
{
    (void)rate_q, (void)rate_dq, (void)rate_ddq;
    ks_put(a->q, q, rate_q);
    ks_put(a->dq, dq, rate_dq);
    ks_put(a->ddq, ddq, rate_ddq);
}

/* One link's outputs: its frame, rates, length, D_g and centre of mass. */
static inline void DYAD_KIN(dyad_kin_put_link)(dyad_kv dir, dyad_ks omega, dyad_ks epsilon,
                                               const kin_coord* length, const kin_motion* d,
                                               dyad_kv com, dyad_kin_link* to, dyad_kin_link* rate)
{
    const kin_motion s = DYAD_KIN(dyad_kin_on_link)(d, dir, omega, epsilon, com);
    kv_put(dir, &to->dir, &rate->dir);
    ks_put(omega, &to->omega, &rate->omega);
    ks_put(epsilon, &to->epsilon, &rate->epsilon);
    DYAD_KIN(dyad_kin_put_coord)(length, &to->length, &to->length_rate, &to->length_accel,
                                 &rate->length, &rate->length_rate, &rate->length_accel);
    DYAD_KIN(dyad_kin_put_motion)(d, &to->d, &rate->d);
    DYAD_KIN(dyad_kin_put_motion)(&s, &to->com, &rate->com);
}

/* The conditioning, the closure and the amplification. */
static inline void DYAD_KIN(dyad_kin_put_figures)(const kin_state* st, dyad_kin_result* value,
                                                  dyad_kin_result* rate)
{
    (void)rate; /* the plain pass writes the values only */
    ks_put(st->conditioning, &value->conditioning, &rate->conditioning);
    ks_put(st->closure, &value->closure, &rate->closure);
    ks_put(st->amplification, &value->amplification, &rate->amplification);
}

/* Every output of a closed, conditioned dyad: value gets the values, rate
 * their derivatives (on the plain pass rate is value and never written). */
static inline void DYAD_KIN(dyad_kin_store)(const kin_in* in, const kin_state* st,
                                            dyad_kin_result* value, dyad_kin_result* rate)
{
    const kin_motion e =
        DYAD_KIN(dyad_kin_on_link)(&st->d_n, st->i_n, st->w_n, st->e_n, kv_make(in->l_n, ks_c(0)));
    DYAD_KIN(dyad_kin_put_link)(st->i_m, st->w_m, st->e_m, &st->l_m, &st->d_m, in->com_m, &value->m,
                                &rate->m);
    DYAD_KIN(dyad_kin_put_link)(st->i_n, st->w_n, st->e_n, &st->l_n, &st->d_n, in->com_n, &value->n,
                                &rate->n);
    DYAD_KIN(dyad_kin_put_motion)(&e, &value->e, &rate->e);
    DYAD_KIN(dyad_kin_put_coord)(&st->s_k, &value->slide_k.s, &value->slide_k.rate,
                                 &value->slide_k.accel, &rate->slide_k.s, &rate->slide_k.rate,
                                 &rate->slide_k.accel);
    DYAD_KIN(dyad_kin_put_coord)(&st->s_p, &value->slide_p.s, &value->slide_p.rate,
                                 &value->slide_p.accel, &rate->slide_p.s, &rate->slide_p.rate,
                                 &rate->slide_p.accel);
    DYAD_KIN(dyad_kin_put_figures)(st, value, rate);
}

/* A dyad that does not close: NaN outputs, the failure and its gap. */
static inline dyad_status DYAD_KIN(dyad_kin_failed)(const kin_state* st, dyad_kin_result* value,
                                                    dyad_kin_result* rate)
{
    dyad_kin_reject(value, rate, DYAD_STATUS_CANNOT_ASSEMBLE, DYAD_KIN_FIELD_NONE);
    value->failure = rate->failure = st->failure;
    ks_put(st->gap, &value->gap, &rate->gap);
    return DYAD_STATUS_CANNOT_ASSEMBLE;
}

/* A dyad below the singular threshold: NaN outputs, the conditioning kept. */
static inline dyad_status DYAD_KIN(dyad_kin_singular)(const kin_state* st, dyad_kin_result* value,
                                                      dyad_kin_result* rate)
{
    dyad_kin_reject(value, rate, DYAD_STATUS_SINGULAR, DYAD_KIN_FIELD_NONE);
    DYAD_KIN(dyad_kin_put_figures)(st, value, rate);
    return DYAD_STATUS_SINGULAR;
}

/* The whole of dyad_kinematics_<type> (plain pass: seed = input, rate =
 * value, neither read nor written as such)
 * and of its tangent (dual pass). Inlined into each, so that the type's two
 * functions are called directly. */
DYAD_CLOSED_FORM dyad_status DYAD_KIN(dyad_kin_run)(dyad_type type, kin_position_fn position,
                                                    kin_motion_fn motion,
                                                    const dyad_kin_input* input,
                                                    const dyad_kin_input* seed,
                                                    dyad_kin_result* value, dyad_kin_result* rate)
{
    kin_in in;
    kin_state st;
    dyad_kin_field bad;
    if (value == NULL || rate == NULL) {
        return value == NULL
                   ? DYAD_STATUS_INVALID_INPUT
                   : dyad_kin_reject(value, NULL, DYAD_STATUS_INVALID_INPUT, DYAD_KIN_FIELD_INPUT);
    }
    bad = input == NULL || (DYAD_KIN_IS_DUAL && seed == NULL) ? DYAD_KIN_FIELD_INPUT
          : dyad_kin_fields_good(type, input) ? DYAD_KIN_FIELD_NONE
                                              : dyad_kin_first_bad_field(type, input);
    if (bad != DYAD_KIN_FIELD_NONE) {
        return dyad_kin_reject(value, rate, DYAD_STATUS_INVALID_INPUT, bad);
    }
    DYAD_KIN(dyad_kin_load)(type, input, seed, &in);
    DYAD_KIN(dyad_kin_start)(&in, &st);
    if (position(&in, &st) != DYAD_KIN_CLOSES) {
        return DYAD_KIN(dyad_kin_failed)(&st, value, rate);
    }
    st.amplification = DYAD_KIN(dyad_kin_amplification)(&in, &st);
    if (!(ks_val(st.amplification) * in.threshold <= 1)) {
        return DYAD_KIN(dyad_kin_singular)(&st, value, rate);
    }
    motion(&in, &st);
    DYAD_KIN(dyad_kin_store)(&in, &st, value, rate);
    if (!dyad_kin_outputs_finite(value)) {
        return dyad_kin_reject(value, rate, DYAD_STATUS_OUT_OF_RANGE, DYAD_KIN_FIELD_NONE);
    }
    value->status = rate->status = DYAD_STATUS_OK;
    value->field = rate->field = DYAD_KIN_FIELD_NONE;
    value->failure = rate->failure = DYAD_KIN_CLOSES;
    value->gap = rate->gap = 0;
    return DYAD_STATUS_OK;
}

#if !DYAD_KIN_IS_DUAL
/* The motion of the point `at` in the frame of a link whose origin moves as `origin`
 * (dyad_point_on_link, and its twin in a batch's loop). */
static inline dyad_point_motion dyad_kin_point_on_link(const dyad_point_motion* origin,
                                                       dyad_vec2 dir, dyad_real omega,
                                                       dyad_real epsilon, dyad_vec2 at)
{
    kin_motion o, p;
    dyad_point_motion r;
    o.pos = origin->position;
    o.vel = origin->velocity;
    o.acc = origin->acceleration;
    p = dyad_kin_on_link_plain(&o, dir, omega, epsilon, at);
    r.position = p.pos;
    r.velocity = p.vel;
    r.acceleration = p.acc;
    return r;
}

/* One sample of a batch (dyad_lanes.h): dyad_kin_run's steps without a branch, so that
 * a loop over samples vectorises. Every check is made and counted: 0 is returned where
 * dyad_kin_run gives DYAD_STATUS_OK, and then `value` holds its outputs bit for bit
 * (not its status, field, failure or gap, which are not written); elsewhere the count
 * of the failed checks, and outputs that mean nothing (dyad_kinematics_<type> says
 * why). The assembly branch comes as the real `branch`, checked as input->branch is (which
 * a caller leaves at its default): an int chosen per sample would be the loop's one value
 * of 32 bits, and GCC would then take twice the lanes, each double in two registers. */
DYAD_CLOSED_FORM dyad_real dyad_kin_lane(dyad_type type, kin_position_fn position,
                                         kin_motion_fn motion, const dyad_kin_input* input,
                                         dyad_real branch, dyad_kin_result* value)
{
    kin_in in;
    kin_state st;
    dyad_real bad = dyad_kin_fields_failed(type, input);
    dyad_kin_load_plain(type, input, input, &in);
    if (type == DYAD_RRR || type == DYAD_RRT || type == DYAD_RTR) {
        bad += DYAD_FAILED((branch == 1) | (branch == -1));
        in.branch = branch;
    }
    dyad_kin_start_plain(&in, &st);
    bad += DYAD_FAILED(position(&in, &st) == DYAD_KIN_CLOSES);
    st.amplification = dyad_kin_amplification_plain(&in, &st);
    bad += DYAD_FAILED(st.amplification * in.threshold <= 1);
    motion(&in, &st);
    dyad_kin_store_plain(&in, &st, value, value);
    return bad + DYAD_FAILED(dyad_kin_motion_residue(value) == 0);
}
#endif
