/* dyadfmu: RRT dyad, translational pair at D_m, revolute at E and D_n
 * (paper, section 4). Typical: the slider (m) and connecting rod (n) of a
 * slider-crank, the guide i_k on the frame k.
 *
 * Unknowns: the normal force N_mk = R_mk . j_k and reactive moment M^R_mk of
 * the sliding pair, R_np (two components) and R_mn.
 *
 * The paper (section 4):
 * 1. Moment of link n about E, as for RRR (eq. 4):
 *      t_n = R_np . j_n = [(S_n - E) x F_n + M_n] / l_n.
 * 2. Forces on the whole dyad (eq. 12): N_mk j_k + F_m + F_n + b i_n + t_n j_n = 0
 *    with b = R_np . i_n. Dotting with j_n removes b (eq. 13):
 *      N_mk = -[(F_m + F_n) . j_n + t_n] / (j_k . j_n),
 *    with j_k . j_n = i_n . i_k = d: it vanishes when the rod stands normal to
 *    the guide.
 * 3. R_mn = -(R_mk + F_m) (eq. 8), and the moment of link m about E (eq. 11)
 *      M^R_mk = l_m i_m x R_mk - [(S_m - E) x F_m + M_m].
 *
 * Rearranged, as for RRR, for the inner reaction first. F_n . j_n + t_n =
 * M_Dn / l_n (M_Dg: the moment of link g's load about D_g), so the moment of
 * the rod about D_n gives one projection of R_mn, tau = R_mn . j_n = M_Dn / l_n,
 * and the forces on the slider, N_mk j_k + F_m + R_mn = 0 dotted with i_k, the
 * other: with R_mn = gamma i_n + tau j_n,
 *      gamma = -[F_m . i_k + tau (j_n . i_k)] / d,
 *      N_mk = -(F_m + R_mn) . j_k,   R_np = R_mn - F_n,
 * and the slider's moment about D_m, where R_mk drops out:
 *      M^R_mk = -M_Dm - l_m i_m x R_mn.
 * A heavy, fast rod then no longer costs the slider's reactions their digits
 * (eq. 13 subtracts the rod's inertia from itself: up to 1e-11 relative error
 * in N_mk and M^R_mk before).
 *
 * Floating-point operations of the closed forms (an add, subtract, multiply,
 * divide or square root each; a dot or cross product 3, a vector sum 2, a
 * combination a u + b v 6): the links' resultants 2 x 28 = 56 (dyad_resultant),
 * the reactions above 33, and the amplification 48
 * (dyad_amplification.h: the links' sizes 2 x 17, this type's output sizes
 * 8, 1/|d| 1 and the two groups' data factors with the quotient by the conditioning 5).
 * Closed forms: 137 flops. The solve adds the checks of its inputs and of
 * its outputs (scripts/run-study counts what it executes).
 */
#include "dyad_internal.h"

/* The denominator i_n . i_k, 0 where the rod stands normal to the guide; the conditioning |d|. */
DYAD_CLOSED_FORM dyad_conditioned rrt_conditioning(const dyad_loaded* p)
{
    dyad_conditioned c;
    c.d = dyad_dot(p->n.i, p->i_k);
    c.conditioning = dyad_abs(c.d);
    c.dist = 0;
    return c;
}

/* The reactions of a dyad whose conditioning is accepted; the sizes of their terms. */
DYAD_CLOSED_FORM dyad_output_sizes rrt_closed_forms(const dyad_loaded* p, dyad_conditioned c,
                                                    dyad_result* result)
{
    const dyad_body* m = &p->m;
    const dyad_body* n = &p->n;
    const dyad_real tau = dyad_load_moment_about_d(n) / n->l;
    const dyad_real gamma = -(dyad_dot(m->f, p->i_k) + tau * dyad_dot(n->j, p->i_k)) / c.d;
    dyad_size_terms terms;
    result->r_mn = dyad_combine(gamma, n->i, tau, n->j);
    result->n_mk = -dyad_dot(dyad_add(m->f, result->r_mn), p->j_k);
    result->r_mk = dyad_scale(result->n_mk, p->j_k);
    result->r_np = dyad_sub(result->r_mn, n->f);
    result->m_mk = -dyad_load_moment_about_d(m) - m->l * dyad_cross(m->i, result->r_mn);
    terms = dyad_size_terms_of(p, 1 / c.conditioning);
    return dyad_sizes_rrt(&terms);
}

#ifndef DYAD_REACT_FORMULAS /* dyad_lanes.h takes the closed forms alone */

DYAD_CLOSED_FORM dyad_status rrt_reactions(const dyad_loaded* p, dyad_result* result)
{
    return dyad_reactions(DYAD_RRT, p, rrt_conditioning(p), rrt_closed_forms, result);
}

dyad_status dyad_react_rrt(const dyad_loaded* dyad, dyad_result* result)
{
    const dyad_status status = dyad_begin(dyad, result);
    return status == DYAD_STATUS_OK ? rrt_reactions(dyad, result) : status;
}

dyad_status dyad_solve_valid_rrt(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_prepare_valid(DYAD_RRT, input, &p, result);
    return rrt_reactions(&p, result);
}

dyad_status dyad_solve_rrt(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    const dyad_status status = dyad_prepare(DYAD_RRT, input, &p, result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    return dyad_name_failure(DYAD_RRT, input, rrt_reactions(&p, result), result);
}

#endif /* DYAD_REACT_FORMULAS */
