/* dyadfmu: RRR dyad, all three pairs revolute (paper, section 2).
 *
 * Unknowns: R_mk at D_m and R_np at D_n, each with two components, and R_mn at E.
 *
 * The paper (eqs. 3 to 8):
 * 1. Moment of link g about E (eq. 3): R_mn passes through E and drops out,
 *      -l_g i_g x R_gd + (S_g - E) x F_g + M_g = 0,
 *    and since i_g x R = R . j_g this gives the normal component (eq. 4)
 *      t_g = R_gd . j_g = [(S_g - E) x F_g + M_g] / l_g.
 * 2. Forces on the whole dyad (eq. 5): R_mk + F_m + F_n + R_np = 0, with
 *    R_mk = a i_m + t_m j_m and R_np = b i_n + t_n j_n. Dotting with j_n
 *    removes b (eq. 7):
 *      a = -[t_m (j_m . j_n) + (F_m + F_n) . j_n + t_n] / (i_m . j_n).
 *    The denominator d = i_m . j_n is the sine of the angle between the links:
 *    it vanishes when m and n are aligned.
 * 3. Forces on link m (eq. 8): R_mn = -(R_mk + F_m).
 *
 * Rearranged, the same equations are solved for the inner reaction first.
 * With M_Dg = (S_g - D_g) x F_g + M_g, the moment of link g's load about D_g,
 * (S_g - E) x F_g = M_Dg - l_g F_g . j_g, so F_n . j_n + t_n = M_Dn / l_n: the
 * large terms of eq. 7 cancel exactly. What is left is the moment of each link
 * about its outer pair, where R_mk (or R_np) drops out:
 *      R_mn . j_m = -M_Dm / l_m,      R_mn . j_n = M_Dn / l_n,
 * two projections of R_mn, whence with R_mn = alpha i_m + beta j_m
 *      beta = -M_Dm / l_m,   alpha = [M_Dn / l_n - beta (j_m . j_n)] / d,
 * and the outer reactions close each link's forces:
 *      R_mk = -(R_mn + F_m),   R_np = R_mn - F_n.
 * Each output is then a sum without cancellation of large terms: where one
 * link's inertia dwarfs the reactions it does not cause (a heavy, fast link),
 * eq. 7 kept only the large reaction to full relative accuracy and lost digits
 * of the small ones (up to 1e-10 relative), the rearranged sums keep them all.
 *
 * Floating-point operations of the closed forms (an add, subtract, multiply,
 * divide or square root each; a dot or cross product 3, a vector sum 2, a
 * combination a u + b v 6): the links' resultants 2 x 28 = 56 (dyad_resultant),
 * the reactions above 21, and the amplification 45
 * (dyad_amplification.h: the links' sizes 2 x 17, this type's output sizes
 * 7, 1/|d| 1 and the data factor with the quotient by the conditioning 3).
 * Closed forms: 122 flops. The solve adds the checks of its inputs and of
 * its outputs (scripts/run-study counts what it executes).
 */
#include "dyad_internal.h"

/* The denominator i_m . j_n, the sine of the angle between the links; the conditioning |d|. */
DYAD_CLOSED_FORM dyad_conditioned rrr_conditioning(const dyad_loaded* p)
{
    dyad_conditioned c;
    c.d = dyad_dot(p->m.i, p->n.j);
    c.conditioning = dyad_abs(c.d);
    c.dist = 0;
    return c;
}

/* The reactions of a dyad whose conditioning is accepted; the sizes of their terms. */
DYAD_CLOSED_FORM dyad_output_sizes rrr_closed_forms(const dyad_loaded* p, dyad_conditioned c,
                                                    dyad_result* result)
{
    const dyad_body* m = &p->m;
    const dyad_body* n = &p->n;
    const dyad_real beta = -dyad_load_moment_about_d(m) / m->l;
    const dyad_real alpha =
        (dyad_load_moment_about_d(n) / n->l - beta * dyad_dot(m->j, n->j)) / c.d;
    dyad_size_terms terms;
    result->r_mn = dyad_combine(alpha, m->i, beta, m->j);
    result->r_mk = dyad_neg(dyad_add(result->r_mn, m->f));
    result->r_np = dyad_sub(result->r_mn, n->f);
    terms = dyad_size_terms_of(p, 1 / c.conditioning);
    return dyad_sizes_rrr(&terms);
}

#ifndef DYAD_REACT_FORMULAS /* dyad_lanes.h takes the closed forms alone */

DYAD_CLOSED_FORM dyad_status rrr_reactions(const dyad_loaded* p, dyad_result* result)
{
    return dyad_reactions(DYAD_RRR, p, rrr_conditioning(p), rrr_closed_forms, result);
}

dyad_status dyad_react_rrr(const dyad_loaded* dyad, dyad_result* result)
{
    const dyad_status status = dyad_begin(dyad, result);
    return status == DYAD_STATUS_OK ? rrr_reactions(dyad, result) : status;
}

dyad_status dyad_solve_valid_rrr(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_prepare_valid(DYAD_RRR, input, &p, result);
    return rrr_reactions(&p, result);
}

dyad_status dyad_solve_rrr(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    const dyad_status status = dyad_prepare(DYAD_RRR, input, &p, result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    return dyad_name_failure(DYAD_RRR, input, rrr_reactions(&p, result), result);
}

#endif /* DYAD_REACT_FORMULAS */
