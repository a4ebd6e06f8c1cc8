/* dyadfmu: TRT dyad, translational pairs at D_m and D_n, revolute at E
 * (paper, section 3). Typical: two sliders on fixed guides i_k and i_p,
 * pinned together at E.
 *
 * Unknowns: the normal forces N_mk = R_mk . j_k, N_np = R_np . j_p and the
 * reactive moments M^R_mk, M^R_np; R_mn at E follows.
 *
 * 1. Forces on the whole dyad (eq. 9): N_mk j_k + F_m + F_n + N_np j_p = 0.
 *    Dotting with i_p removes N_np, with i_k removes N_mk (eq. 10):
 *      N_mk = -(F_m + F_n) . i_p / (j_k . i_p)
 *      N_np = -(F_m + F_n) . i_k / (j_p . i_k)
 *    with j_p . i_k = -(j_k . i_p) = -d: it vanishes when the guides are parallel.
 * 2. Moment of link g about E (eq. 11), where R_mn drops out:
 *      M^R_gd = l_g i_g x R_gd - [(S_g - E) x F_g + M_g].
 * 3. Forces on link m (eq. 8): R_mn = -(R_mk + F_m), or equally on link n:
 *    R_mn = R_np + F_n. The solver takes the sum with the smaller terms (see
 *    dyad_smaller_sum): where link m is heavy and R_mn small, eq. 8 would lose
 *    R_mn's digits to cancellation.
 *
 * Floating-point operations of the closed forms (an add, subtract, multiply,
 * divide or square root each; a dot or cross product 3, a vector sum 2, a
 * combination a u + b v 6): the links' resultants 2 x 28 = 56 (dyad_resultant),
 * the reactions above 47 (both sums of R_mn, to keep the one of smaller terms), and the
 * amplification 50 (dyad_amplification.h: the links' sizes 2 x 17, this type's output sizes 10,
 * 1/|d| 1 and the two groups' data factors with the quotient by the conditioning 5). Closed forms:
 * 153 flops. The solve adds the checks of its inputs and of its outputs (scripts/run-study counts
 * what it executes).
 */
#include "dyad_internal.h"

/* The denominator j_k . i_p, 0 where the guides are parallel; the conditioning |d|. */
DYAD_CLOSED_FORM dyad_conditioned trt_conditioning(const dyad_loaded* p)
{
    dyad_conditioned c;
    c.d = dyad_dot(p->j_k, p->i_p);
    c.conditioning = dyad_abs(c.d);
    c.dist = 0;
    return c;
}

/* The reactions of a dyad whose conditioning is accepted; the sizes of their terms. */
DYAD_CLOSED_FORM dyad_output_sizes trt_closed_forms(const dyad_loaded* p, dyad_conditioned c,
                                                    dyad_result* result)
{
    const dyad_body* m = &p->m;
    const dyad_body* n = &p->n;
    const dyad_vec2 f_sum = dyad_add(m->f, n->f);
    dyad_size_terms terms;
    result->n_mk = -dyad_dot(f_sum, p->i_p) / c.d;
    result->n_np = dyad_dot(f_sum, p->i_k) / c.d;
    result->r_mk = dyad_scale(result->n_mk, p->j_k);
    result->r_np = dyad_scale(result->n_np, p->j_p);
    result->r_mn = dyad_smaller_sum(
        dyad_neg(dyad_add(result->r_mk, m->f)), dyad_norm1(result->r_mk) + dyad_norm1(m->f),
        dyad_add(result->r_np, n->f), dyad_norm1(result->r_np) + dyad_norm1(n->f));
    result->m_mk = m->l * dyad_cross(m->i, result->r_mk) - dyad_load_moment_about_e(m);
    result->m_np = n->l * dyad_cross(n->i, result->r_np) - dyad_load_moment_about_e(n);
    terms = dyad_size_terms_of(p, 1 / c.conditioning);
    return dyad_sizes_trt(&terms);
}

#ifndef DYAD_REACT_FORMULAS /* dyad_lanes.h takes the closed forms alone */

DYAD_CLOSED_FORM dyad_status trt_reactions(const dyad_loaded* p, dyad_result* result)
{
    return dyad_reactions(DYAD_TRT, p, trt_conditioning(p), trt_closed_forms, result);
}

dyad_status dyad_react_trt(const dyad_loaded* dyad, dyad_result* result)
{
    const dyad_status status = dyad_begin(dyad, result);
    return status == DYAD_STATUS_OK ? trt_reactions(dyad, result) : status;
}

dyad_status dyad_solve_valid_trt(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_prepare_valid(DYAD_TRT, input, &p, result);
    return trt_reactions(&p, result);
}

dyad_status dyad_solve_trt(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    const dyad_status status = dyad_prepare(DYAD_TRT, input, &p, result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    return dyad_name_failure(DYAD_TRT, input, trt_reactions(&p, result), result);
}

#endif /* DYAD_REACT_FORMULAS */
