/* dyadfmu: RTR dyad, revolute pairs at D_m and D_n, translational at E
 * (paper, section 5). Typical: the slotted lever (m) of a quick-return
 * mechanism and the block (n) sliding in it, pinned to the crank p at D_n.
 * The guide of E is link m itself: R_mn is normal to i_m.
 *
 * Unknowns: R_np (two components), the normal force N_mn = R_mn . j_m and the
 * reactive moment M^R_mn; R_mk follows.
 *
 * The basis {i_beta, j_beta} lies along D_m D_n. Since D_n = E - l_n i_n and
 * E = D_m + l_m i_m,
 *      D_n - D_m = l_m i_m - l_n i_n,   i_beta = (l_m i_m - l_n i_n) / |D_m D_n|.
 * Correction: the paper prints i_beta = (l_m j_m - l_n j_n) / |D_m D_n|, which is
 * that vector turned by 90 degrees; with it the equilibrium of the links fails.
 *
 * 1. Moment of the whole dyad about D_m (eq. 14): R_mk passes through D_m and
 *    the pair E is internal, so
 *      |D_m D_n| i_beta x R_np + |D_m D_n| i_beta x F_n + sum_g [(S_g - D_g) x F_g + M_g] = 0
 *    (the lever of F_n is (D_n - D_m) + (S_n - D_n)), which gives (eq. 15)
 *      s = R_np . j_beta = -F_n . j_beta - sum_g [(S_g - D_g) x F_g + M_g] / |D_m D_n|.
 * 2. Forces on link n (eq. 16): a i_beta + s j_beta + F_n - N_mn j_m = 0 with
 *    a = R_np . i_beta. Dotting with j_beta removes a (eq. 17):
 *      N_mn = [s + F_n . j_beta] / (j_m . j_beta),   j_m . j_beta = i_beta . i_m = d,
 *    which vanishes when the slot stands normal to D_m D_n.
 *    Rearranged: with s from eq. 15 the term F_n . j_beta cancels exactly, so
 *      N_mn = -sum_g [(S_g - D_g) x F_g + M_g] / (|D_m D_n| d).
 *    Computed as printed, s + F_n . j_beta subtracts two numbers of the size of
 *    F_n, and where the block's inertia is large against the reaction the
 *    difference kept only a few digits (componentwise errors up to 1e-8, and a
 *    normwise 3e-12, on well-conditioned configurations before this change).
 * 3. R_np then closes the balance of link n, R_np = N_mn j_m - F_n, which is
 *    eq. 17's a i_beta + s j_beta without its cancellation, and R_mk that of
 *    link m (eq. 18), R_mk = -(R_mn + F_m).
 * 4. Moment of link m about D_m: l_m i_m x R_mn + (S_m - D_m) x F_m + M_m + M^R_mn = 0,
 *      M^R_mn = -l_m N_mn - [(S_m - D_m) x F_m + M_m],
 *    or of link n about E: -l_n i_n x R_np + (S_n - E) x F_n + M_n - M^R_mn = 0,
 *      M^R_mn = -l_n i_n x R_np + [(S_n - E) x F_n + M_n];
 *    the form of the smaller size wins (the bound on its round-off,
 *    dyad_amplification.h): a light block's moment is otherwise the
 *    difference of the heavy lever's large moments. (Weighing the forms by
 *    their terms' magnitudes alone, as before, left componentwise errors of
 *    2e-11 on the extreme set; by their sizes, 7e-14.)
 *
 * Conditioning: the smaller of |d| and |D_m D_n| / (l_m + l_n); the second
 * vanishes when D_m and D_n coincide, where i_beta is undefined and the lever
 * of R_np about D_m is zero.
 *
 * Floating-point operations of the closed forms (an add, subtract, multiply,
 * divide or square root each; a dot or cross product 3, a vector sum 2, a
 * combination a u + b v 6): the links' resultants 2 x 28 = 56 (dyad_resultant),
 * the reactions above 27 (M_mn in its first form), and the amplification 51
 * (dyad_amplification.h: the links' sizes 2 x 17, this type's output sizes
 * 10, 1/|D_m D_n d| 2 and the two groups' data factors with the quotient by the conditioning 5).
 * Closed forms: 134 flops. The solve adds the checks of its inputs and of
 * its outputs (scripts/run-study counts what it executes).
 */
#include "dyad_internal.h"

/* The denominator i_beta . i_m (i_beta the direction of D_m D_n) and the conditioning,
 * at most |D_m D_n| / (l_m + l_n) too. */
DYAD_CLOSED_FORM dyad_conditioned rtr_conditioning(const dyad_loaded* p)
{
    const dyad_body* m = &p->m;
    const dyad_body* n = &p->n;
    const dyad_vec2 dm_dn = dyad_combine(m->l, m->i, -n->l, n->i);
    const dyad_real dist = dyad_length(dm_dn);
    const dyad_real spread = dist / (m->l + n->l);
    dyad_conditioned c;
    c.dist = dist;
    c.d = c.dist > 0 ? dyad_dot(dm_dn, m->i) / c.dist : 0;
    c.conditioning = dyad_abs(c.d) < spread ? dyad_abs(c.d) : spread;
    return c;
}

/* The reactions of a dyad whose conditioning is accepted; the sizes of their terms. */
DYAD_CLOSED_FORM dyad_output_sizes rtr_closed_forms(const dyad_loaded* p, dyad_conditioned c,
                                                    dyad_result* result)
{
    const dyad_body* m = &p->m;
    const dyad_body* n = &p->n;
    const dyad_real n_mn =
        -(dyad_load_moment_about_d(m) + dyad_load_moment_about_d(n)) / (c.dist * c.d);
    dyad_size_terms terms;
    dyad_output_sizes sizes;
    result->n_mn = n_mn;
    result->r_mn = dyad_scale(n_mn, m->j);
    result->r_np = dyad_sub(result->r_mn, n->f);
    result->r_mk = dyad_neg(dyad_add(result->r_mn, m->f));
    terms = dyad_size_terms_of(p, 1 / dyad_abs(c.dist * c.d));
    sizes = dyad_sizes_rtr(&terms);
    /* M^R_mn from link m about D_m, or from link n about E: the form of the smaller
     * size (dyad_amplification.h) keeps more digits. */
    result->m_mn = sizes.first_form
                       ? -m->l * n_mn - dyad_load_moment_about_d(m)
                       : -n->l * dyad_cross(n->i, result->r_np) + dyad_load_moment_about_e(n);
    return sizes;
}

#ifndef DYAD_REACT_FORMULAS /* dyad_lanes.h takes the closed forms alone */

DYAD_CLOSED_FORM dyad_status rtr_reactions(const dyad_loaded* p, dyad_result* result)
{
    return dyad_reactions(DYAD_RTR, p, rtr_conditioning(p), rtr_closed_forms, result);
}

dyad_status dyad_react_rtr(const dyad_loaded* dyad, dyad_result* result)
{
    const dyad_status status = dyad_begin(dyad, result);
    return status == DYAD_STATUS_OK ? rtr_reactions(dyad, result) : status;
}

dyad_status dyad_solve_valid_rtr(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_prepare_valid(DYAD_RTR, input, &p, result);
    return rtr_reactions(&p, result);
}

dyad_status dyad_solve_rtr(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    const dyad_status status = dyad_prepare(DYAD_RTR, input, &p, result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    return dyad_name_failure(DYAD_RTR, input, rtr_reactions(&p, result), result);
}

#endif /* DYAD_REACT_FORMULAS */
