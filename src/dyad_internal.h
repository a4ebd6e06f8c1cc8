/* dyadfmu: what the per-type solvers share. Not part of the public API. */
#ifndef DYADFMU_INTERNAL_H
#define DYADFMU_INTERNAL_H

#include "dyadfmu/dyad.h"
#include "dyadfmu/loaded.h"
#include "dyadfmu/vec2.h"
#include "dyad_amplification.h"

#include <math.h>
#include <stddef.h>

/* A link ready for the formulas, and the dyad: the public dyad_loaded of
 * dyadfmu/loaded.h, under the names the formulas were written with. */
typedef dyad_loaded_link dyad_body;
typedef dyad_loaded dyad_prepared;

/* A solver's steps (its input prepared, its closed forms), inlined into each
 * entry (dyad_solve_<type>, dyad_solve_valid_<type>, dyad_react_<type>) even
 * where the compiler's size heuristics would not: a call would cost the solve a
 * tenth. */
#if defined(__GNUC__) || defined(__clang__)
#define DYAD_CLOSED_FORM static inline __attribute__((always_inline))
#else
#define DYAD_CLOSED_FORM static inline
#endif

/* 0 where `ok`, else 1, as a real: a batch's count of failed checks (dyad_lanes.h), in the
 * scalar of the values it is taken from, so that the count stays in the vector's lanes. */
#define DYAD_FAILED(ok) ((ok) ? (dyad_real)0 : (dyad_real)1)

/* Marks the result with a failure status and field, outputs NaN; returns status. */
dyad_status dyad_reject(dyad_result* result, dyad_status status, dyad_field field);

/* The first input field out of its domain (non-finite included), in the order
 * of dyad_field, or DYAD_FIELD_NONE: the slow path that names a bad input. */
dyad_field dyad_first_bad_field(dyad_type type, const dyad_input* input);

/* Moment about D_g of the link's resultant load: (S_g - D_g) x F_g + M_g. */
static inline dyad_real dyad_load_moment_about_d(const dyad_body* b)
{
    return b->m_d;
}

/* Moment about E of the link's resultant load: (S_g - E) x F_g + M_g
 * = [(S_g - D_g) x F_g + M_g] - l_g i_g x F_g, since E - D_g = l_g i_g. */
static inline dyad_real dyad_load_moment_about_e(const dyad_body* b)
{
    return b->m_d - b->l * dyad_dot(b->f, b->j);
}

static inline dyad_real dyad_abs(dyad_real a)
{
    return a < 0 ? -a : a;
}

/* x - x is 0 for a finite x and NaN otherwise: the sum of them over `count` (even) reals,
 * 0 where all are finite. Summed in two lanes, which the compiler makes one vector of two
 * (SSE2): half the operations of one chain of dependent adds; unrolled whole where
 * `count` is a constant, since a batch's loop over samples (dyad_lanes.h) vectorises only
 * without a loop inside. */
static inline dyad_real dyad_residue_of(const dyad_real* v, size_t count)
{
    dyad_real even = 0, odd = 0;
    size_t k;
#if defined(__GNUC__)
#pragma GCC unroll 32
#endif
    for (k = 0; k < count; k += 2) {
        even += v[k] - v[k];
        odd += v[k + 1] - v[k + 1];
    }
    return even + odd;
}

static inline dyad_real dyad_largest_of3(dyad_real a, dyad_real b, dyad_real c)
{
    return a > b ? (a > c ? a : c) : (b > c ? b : c);
}

/* Where two sums are equal in exact arithmetic (a force or moment closing one
 * link's balance or the other's), the one built from smaller terms loses
 * fewer digits to cancellation: a stiff dyad, one link's inertia dwarfing the
 * other's, then keeps the light link's reactions to full relative accuracy. */
static inline dyad_vec2 dyad_smaller_sum(dyad_vec2 a, dyad_real a_terms, dyad_vec2 b,
                                         dyad_real b_terms)
{
    return a_terms <= b_terms ? a : b;
}

/* ---- the shared first and last steps of every solver -------------------------
 * Inline, so that each solver's copy is specialised for its constant type: the
 * pair table lookups and unused guide checks fold away on the hot path. */

static const dyad_pair_kind dyad_pair_table[DYAD_TYPE_COUNT][3] = {
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
static const int dyad_zero_length_table[DYAD_TYPE_COUNT][2] = {
    /* clang-format off */
    /*            m  n */
    [DYAD_RRR] = {0, 0},
    [DYAD_RRT] = {1, 0},
    [DYAD_RTR] = {0, 1},
    [DYAD_TRT] = {1, 1},
    [DYAD_RTT] = {0, 1},
    /* clang-format on */
};

static inline int dyad_is_unit(dyad_vec2 v)
{
    return dyad_abs(dyad_dot(v, v) - 1) <= DYAD_UNIT_TOLERANCE;
}

/* The unit vector of a direction that passed is_unit. One already unit to
 * rounding, as cos/sin or a normalised difference give, is kept as it is. */
static inline dyad_vec2 dyad_unit_of(dyad_vec2 v)
{
    const dyad_real norm2 = dyad_dot(v, v);
    if (dyad_abs(norm2 - 1) <= 4 * DYAD_REAL_EPSILON) {
        return v;
    }
    return dyad_scale(1 / dyad_length(v), v);
}

/* F_g and M_g for a link with frame (i, j): eq. (1) gives the acceleration of
 * the centre of mass, a_S = a_D - omega^2 r + epsilon k0 x r with
 * r = x_S i + y_S j; eq. (2) turns it into the inertia force -m a_S and
 * moment -J epsilon, to which the active load and the weight m g are added.
 * Also the moment of all that about D_g: the centripetal part m omega^2 r of
 * the inertia force points along r and has no moment about D_g, so it is left
 * out of that sum instead of being added and cancelled again; for a fast,
 * heavy link it would otherwise swamp the moment in round-off. And the sizes
 * of both sums (dyad_amplification.h), for the amplification.
 * Flops: r 6, the tangential acceleration 4, F without its centripetal part 6,
 * that part 6, M 2, M_D 4: 28; the sizes 17 (dyad_link_sizes_of). */
static inline void dyad_resultant(const dyad_link* link, dyad_vec2 i, dyad_vec2 gravity,
                                  dyad_body* body)
{
    static const dyad_link no_rate;
    const dyad_vec2 zero = dyad_vec2_make(0, 0);
    const dyad_vec2 j = dyad_perp(i);
    const dyad_vec2 r = dyad_combine(link->com.x, i, link->com.y, j);
    const dyad_vec2 tangential = dyad_add(link->accel_d, dyad_scale(link->epsilon, dyad_perp(r)));
    const dyad_vec2 without_centripetal =
        dyad_add(link->force, dyad_scale(link->mass, dyad_sub(gravity, tangential)));
    const dyad_link_sizes sizes = dyad_link_sizes_of(link, &no_rate, r, zero, gravity, zero);
    body->f = dyad_add(without_centripetal, dyad_scale(link->mass * link->omega * link->omega, r));
    body->m = link->moment - link->inertia * link->epsilon;
    body->m_d = body->m + dyad_cross(r, without_centripetal);
    body->f_size = sizes.f.v;
    body->m_d_size = sizes.m_d.v;
}

static inline int dyad_guide_used(dyad_type type, dyad_pair pair)
{
    return dyad_pair_table[type][pair] == DYAD_PAIR_TRANSLATIONAL;
}

static inline int dyad_link_in_domain(const dyad_link* link, int may_be_zero)
{
    /* length - length == 0 also rules out an infinite length, the one input
     * that could vanish from the result (as a divisor) instead of spoiling it. */
    return link->length - link->length == 0 && link->length >= 0 &&
           (link->length > 0 || may_be_zero) && link->mass >= 0 && link->inertia >= 0 &&
           dyad_is_unit(link->dir);
}

/* The fast check: domains, and the unit directions. It does not test every
 * number for being finite: an infinite or NaN load, kinematic quantity, mass
 * or inertia always reaches the reactions as inf or NaN (IEEE arithmetic keeps
 * them through every sum and product, and no input but a length divides), so
 * dyad_name_failure sees it and asks first_bad_field to name it. That keeps the
 * common path to a handful of comparisons. */
static inline int dyad_in_domain(dyad_type type, const dyad_input* in)
{
    return in->singular_threshold > 0 && in->singular_threshold < 1 &&
           dyad_link_in_domain(&in->m, dyad_zero_length_table[type][DYAD_LINK_M]) &&
           dyad_link_in_domain(&in->n, dyad_zero_length_table[type][DYAD_LINK_N]) &&
           (!dyad_guide_used(type, DYAD_PAIR_DM) || dyad_is_unit(in->guide_k)) &&
           (!dyad_guide_used(type, DYAD_PAIR_DN) || dyad_is_unit(in->guide_p));
}

static inline dyad_field dyad_validate(dyad_type type, const dyad_input* in)
{
    return dyad_in_domain(type, in) ? DYAD_FIELD_NONE : dyad_first_bad_field(type, in);
}

static inline void dyad_prepare_body(const dyad_link* link, dyad_vec2 gravity, dyad_body* body)
{
    body->i = dyad_unit_of(link->dir);
    body->j = dyad_perp(body->i);
    body->l = link->length;
    dyad_resultant(link, body->i, gravity, body);
}

static inline void dyad_fill_outputs(dyad_result* result, dyad_real value)
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

/* The frames and resultants of an input known to be valid, and the outputs
 * cleared for the closed forms. */
DYAD_CLOSED_FORM void dyad_prepare_valid(dyad_type type, const dyad_input* input,
                                         dyad_prepared* prepared, dyad_result* result)
{
    dyad_prepare_body(&input->m, input->gravity, &prepared->m);
    dyad_prepare_body(&input->n, input->gravity, &prepared->n);
    prepared->i_k =
        dyad_guide_used(type, DYAD_PAIR_DM) ? dyad_unit_of(input->guide_k) : dyad_vec2_make(0, 0);
    prepared->j_k = dyad_perp(prepared->i_k);
    prepared->i_p =
        dyad_guide_used(type, DYAD_PAIR_DN) ? dyad_unit_of(input->guide_p) : dyad_vec2_make(0, 0);
    prepared->j_p = dyad_perp(prepared->i_p);
    prepared->singular_threshold = input->singular_threshold;
    dyad_fill_outputs(result, 0);
    result->status = DYAD_STATUS_OK;
    result->field = DYAD_FIELD_NONE;
}

static inline dyad_status dyad_prepare(dyad_type type, const dyad_input* input,
                                       dyad_prepared* prepared, dyad_result* result)
{
    static const dyad_prepared nothing;
    const dyad_field bad = result == NULL  ? DYAD_FIELD_NONE
                           : input == NULL ? DYAD_FIELD_INPUT
                                           : dyad_validate(type, input);
    if (result == NULL || bad != DYAD_FIELD_NONE) {
        /* Never read on this path; cleared so that no compiler has to prove it. */
        *prepared = nothing;
        if (result == NULL) {
            return DYAD_STATUS_INVALID_INPUT;
        }
        result->denominator = result->conditioning = result->amplification = (dyad_real)NAN;
        return dyad_reject(result, DYAD_STATUS_INVALID_INPUT, bad);
    }
    dyad_prepare_valid(type, input, prepared, result);
    return DYAD_STATUS_OK;
}

/* A type's denominator d and its conditioning (in [0, 1]; |d| but for RTR), and for
 * RTR the distance |D_m D_n| its closed forms divide by too. */
typedef struct dyad_conditioned {
    dyad_real d, conditioning, dist;
} dyad_conditioned;

/* The conditioning into the result. The amplification is 1 / conditioning until
 * dyad_finish adds the data factor: what a singular or out-of-range result reports. */
static inline void dyad_store_conditioning(dyad_conditioned c, dyad_result* result)
{
    result->denominator = c.d;
    result->conditioning = c.conditioning;
    result->amplification = 1 / c.conditioning;
}

/* Stores the conditioning; below the threshold (or NaN) the dyad is singular. */
static inline dyad_status dyad_accept_conditioning(dyad_real threshold, dyad_conditioned c,
                                                   dyad_result* result)
{
    dyad_store_conditioning(c, result);
    if (!(c.conditioning >= threshold)) {
        return dyad_reject(result, DYAD_STATUS_SINGULAR, DYAD_FIELD_NONE);
    }
    return DYAD_STATUS_OK;
}

/* The sizes of the loads of a prepared dyad, for dyad_sizes_<type>; inv is the
 * inverse of the type's divisor (dyad_amplification.h). */
static inline dyad_size_terms dyad_size_terms_of(const dyad_loaded* p, dyad_real inv)
{
    dyad_size_terms t;
    t.f_m = dyad_dual_const(p->m.f_size);
    t.m_m = dyad_dual_const(p->m.m_d_size);
    t.f_n = dyad_dual_const(p->n.f_size);
    t.m_n = dyad_dual_const(p->n.m_d_size);
    t.l_m = dyad_dual_const(p->m.l);
    t.l_n = dyad_dual_const(p->n.l);
    t.inv = dyad_dual_const(inv);
    return t;
}

/* x - x is 0 for a finite x and NaN otherwise: one sum, 0 where every reaction is finite. */
static inline dyad_real dyad_outputs_residue(const dyad_result* r)
{
    return (r->r_mk.x - r->r_mk.x) + (r->r_mk.y - r->r_mk.y) + (r->r_np.x - r->r_np.x) +
           (r->r_np.y - r->r_np.y) + (r->r_mn.x - r->r_mn.x) + (r->r_mn.y - r->r_mn.y) +
           (r->n_mk - r->n_mk) + (r->n_np - r->n_np) + (r->n_mn - r->n_mn) + (r->m_mk - r->m_mk) +
           (r->m_np - r->m_np) + (r->m_mn - r->m_mn);
}

/* The last step of every type: a reaction that is not finite is out of range. */
static inline dyad_status dyad_check_finite(dyad_result* result)
{
    if (dyad_outputs_residue(result) != 0) {
        return dyad_reject(result, DYAD_STATUS_OUT_OF_RANGE, DYAD_FIELD_NONE);
    }
    return DYAD_STATUS_OK;
}

/* The amplification of a finite result from its output sizes (the rates are never read
 * here). */
static inline dyad_real dyad_result_amplification(dyad_type type, dyad_output_sizes sizes,
                                                  const dyad_result* result)
{
    return dyad_amplification_of(sizes, dyad_largest_force(result, result),
                                 dyad_largest_moment(result, result,
                                                     dyad_guide_used(type, DYAD_PAIR_DM),
                                                     dyad_guide_used(type, DYAD_PAIR_E),
                                                     dyad_guide_used(type, DYAD_PAIR_DN)),
                                 dyad_dual_const(result->conditioning))
        .v;
}

/* The last step of every type: out of range unless finite; then the amplification. */
static inline dyad_status dyad_finish(dyad_type type, dyad_output_sizes sizes, dyad_result* result)
{
    const dyad_status status = dyad_check_finite(result);
    if (status == DYAD_STATUS_OK) {
        result->amplification = dyad_result_amplification(type, sizes, result);
    }
    return status;
}

/* dyad_solve_<type>: a NaN or infinite input reaches the conditioning or the
 * reactions (the fast validation lets non-finite loads through), so a failure
 * of the closed forms is first blamed on the input field that caused it. */
static inline dyad_status dyad_name_failure(dyad_type type, const dyad_input* input,
                                            dyad_status status, dyad_result* result)
{
    if (status != DYAD_STATUS_OK) {
        const dyad_field bad = dyad_first_bad_field(type, input);
        if (bad != DYAD_FIELD_NONE) {
            result->denominator = result->conditioning = result->amplification = (dyad_real)NAN;
            return dyad_reject(result, DYAD_STATUS_INVALID_INPUT, bad);
        }
    }
    return status;
}

/* A type's closed forms: the reactions of a dyad whose conditioning c is accepted, and
 * the sizes of their terms. */
typedef dyad_output_sizes (*dyad_closed_forms_fn)(const dyad_loaded* p, dyad_conditioned c,
                                                  dyad_result* result);

/* A type's reactions: its conditioning accepted, its closed forms, finished. */
DYAD_CLOSED_FORM dyad_status dyad_reactions(dyad_type type, const dyad_loaded* p,
                                            dyad_conditioned c, dyad_closed_forms_fn closed_forms,
                                            dyad_result* result)
{
    const dyad_status status = dyad_accept_conditioning(p->singular_threshold, c, result);
    return status == DYAD_STATUS_OK ? dyad_finish(type, closed_forms(p, c, result), result)
                                    : status;
}

/* dyad_react_<type>: the result starts ok with zero outputs. */
static inline dyad_status dyad_begin(const dyad_loaded* dyad, dyad_result* result)
{
    if (result == NULL) {
        return DYAD_STATUS_INVALID_INPUT;
    }
    dyad_fill_outputs(result, 0);
    result->status = DYAD_STATUS_OK;
    result->field = DYAD_FIELD_NONE;
    if (dyad == NULL) {
        result->denominator = result->conditioning = result->amplification = (dyad_real)NAN;
        return dyad_reject(result, DYAD_STATUS_INVALID_INPUT, DYAD_FIELD_INPUT);
    }
    return DYAD_STATUS_OK;
}

#endif /* DYADFMU_INTERNAL_H */
