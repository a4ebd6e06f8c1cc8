/* dyadfmu: RTT dyad, translational pairs at D_m and E, revolute at D_n
 * (paper, section 6). Typical: the Scotch yoke, whose yoke (m) slides on the
 * frame guide i_k and carries a slot along i_m in which the block (n), pinned
 * to the crank p at D_n, slides.
 *
 * Unknowns: the normal forces N_mk = R_mk . j_k, N_mn = R_mn . j_m and the
 * reactive moments M^R_mk, M^R_mn; R_np follows.
 *
 * 1. Forces on link m (eq. 19): N_mk j_k + F_m + N_mn j_m = 0. Dotting with i_m
 *    removes N_mn, with i_k removes N_mk (eq. 20):
 *      N_mk = -F_m . i_m / (j_k . i_m)
 *      N_mn = -F_m . i_k / (j_m . i_k)
 *    with j_m . i_k = -(j_k . i_m) = -d: it vanishes when slot and guide are
 *    parallel.
 * 2. Forces on the whole dyad (eq. 21): R_np = -(R_mk + F_m + F_n).
 * 3. Moment of link n about E: it receives -R_mn at E and -M^R_mn, so
 *      -l_n i_n x R_np + (S_n - E) x F_n + M_n - M^R_mn = 0,
 *      M^R_mn = -l_n i_n x R_np + [(S_n - E) x F_n + M_n].
 *    Correction: the paper (eq. 22) prints -l_n j_n x R_np; the lever from E
 *    to D_n is -l_n i_n, so the cross product is with i_n.
 * 4. Moment of link m about E:
 *      -l_m i_m x R_mk + (S_m - E) x F_m + M_m + M^R_mk + M^R_mn = 0,
 *      M^R_mk = l_m i_m x R_mk - [(S_m - E) x F_m + M_m] - M^R_mn.
 * Steps 2 to 4 each have a twin from the other link's equilibrium (R_np =
 * R_mn - F_n; M^R_mn = M_Dn - l_n i_n x R_mn about D_n; M^R_mk = -M_Dm -
 * l_m i_m x R_mn - M^R_mn about D_m, with M_Dg the moment of link g's load
 * about D_g). Equal in exact arithmetic, they differ in round-off when one
 * link's loads dwarf the other's. For R_np the solver takes the form summing
 * smaller terms. The moments it takes about D_n and D_m: their round-off is
 * never larger (dyad_amplification.h: the twins about E add the round-off of
 * R_np and of the loads' moment about E to theirs), and where the forms about
 * E were chosen before, componentwise errors on the extreme set reached 2e-12;
 * about D they stay below 3e-14.
 *
 * Floating-point operations of the closed forms (an add, subtract, multiply,
 * divide or square root each; a dot or cross product 3, a vector sum 2, a
 * combination a u + b v 6): the links' resultants 2 x 28 = 56 (dyad_resultant),
 * the reactions above 40 (both sums of R_np, to keep the one of smaller terms), and the
 * amplification 48 (dyad_amplification.h: the links' sizes 2 x 17, this type's output sizes 8,
 * 1/|d| 1 and the two groups' data factors with the quotient by the conditioning 5). Closed forms:
 * 144 flops. The solve adds the checks of its inputs and of its outputs (scripts/run-study counts
 * what it executes).
 */
#include "dyad_internal.h"

/* The denominator j_k . i_m, 0 where the slot is parallel to the guide; the conditioning |d|. */
DYAD_CLOSED_FORM dyad_conditioned rtt_conditioning(const dyad_loaded* p)
{
    dyad_conditioned c;
    c.d = dyad_dot(p->j_k, p->m.i);
    c.conditioning = dyad_abs(c.d);
    c.dist = 0;
    return c;
}

/* The reactions of a dyad whose conditioning is accepted; the sizes of their terms. */
DYAD_CLOSED_FORM dyad_output_sizes rtt_closed_forms(const dyad_loaded* p, dyad_conditioned c,
                                                    dyad_result* result)
{
    const dyad_body* m = &p->m;
    const dyad_body* n = &p->n;
    dyad_size_terms terms;
    result->n_mk = -dyad_dot(m->f, m->i) / c.d;
    result->n_mn = dyad_dot(m->f, p->i_k) / c.d;
    result->r_mk = dyad_scale(result->n_mk, p->j_k);
    result->r_mn = dyad_scale(result->n_mn, m->j);
    /* Where one link outweighs the other, the sums over the light one keep
     * their digits; the two forms of each are equal in exact arithmetic. */
    result->r_np =
        dyad_smaller_sum(dyad_neg(dyad_add(dyad_add(result->r_mk, m->f), n->f)),
                         dyad_norm1(result->r_mk) + dyad_norm1(m->f) + dyad_norm1(n->f),
                         dyad_sub(result->r_mn, n->f), dyad_norm1(result->r_mn) + dyad_norm1(n->f));
    /* The moments about the outer pairs, where R_np and R_mk drop out. */
    result->m_mn = dyad_load_moment_about_d(n) - n->l * dyad_cross(n->i, result->r_mn);
    result->m_mk =
        -dyad_load_moment_about_d(m) - m->l * dyad_cross(m->i, result->r_mn) - result->m_mn;
    terms = dyad_size_terms_of(p, 1 / c.conditioning);
    return dyad_sizes_rtt(&terms);
}

#ifndef DYAD_REACT_FORMULAS /* dyad_lanes.h takes the closed forms alone */

DYAD_CLOSED_FORM dyad_status rtt_reactions(const dyad_loaded* p, dyad_result* result)
{
    return dyad_reactions(DYAD_RTT, p, rtt_conditioning(p), rtt_closed_forms, result);
}

dyad_status dyad_react_rtt(const dyad_loaded* dyad, dyad_result* result)
{
    const dyad_status status = dyad_begin(dyad, result);
    return status == DYAD_STATUS_OK ? rtt_reactions(dyad, result) : status;
}

dyad_status dyad_solve_valid_rtt(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_prepare_valid(DYAD_RTT, input, &p, result);
    return rtt_reactions(&p, result);
}

dyad_status dyad_solve_rtt(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    const dyad_status status = dyad_prepare(DYAD_RTT, input, &p, result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    return dyad_name_failure(DYAD_RTT, input, rtt_reactions(&p, result), result);
}

#endif /* DYAD_REACT_FORMULAS */
