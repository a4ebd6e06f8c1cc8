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
 *    a = R_np . i_beta. Dotting with i_m removes N_mn, with j_beta removes a (eq. 17):
 *      a    = -[s (j_beta . i_m) + F_n . i_m] / (i_beta . i_m)
 *      N_mn = [s + F_n . j_beta] / (j_m . j_beta)
 *    with j_m . j_beta = i_beta . i_m = d: it vanishes when the slot stands
 *    normal to D_m D_n.
 * 3. Forces on link m (eq. 18): R_mk = -(R_mn + F_m).
 * 4. Moment of link m about D_m: l_m i_m x R_mn + (S_m - D_m) x F_m + M_m + M^R_mn = 0,
 *      M^R_mn = -l_m N_mn - [(S_m - D_m) x F_m + M_m].
 *
 * Conditioning: the smaller of |d| and |D_m D_n| / (l_m + l_n); the second
 * vanishes when D_m and D_n coincide, where i_beta is undefined and the lever
 * of R_np about D_m is zero.
 */
#include "dyad_internal.h"

dyad_status dyad_solve_rtr(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_status status = dyad_prepare(DYAD_RTR, input, &p, result);
    const dyad_body* m = &p.m;
    const dyad_body* n = &p.n;
    dyad_vec2 dm_dn, i_beta, j_beta;
    dyad_real dist, spread, d, conditioning, s, a;

    if (status != DYAD_STATUS_OK) {
        return status;
    }
    dm_dn = dyad_combine(m->l, m->i, -n->l, n->i);
    dist = dyad_length(dm_dn);
    spread = dist / (m->l + n->l);
    if (dist > 0) {
        i_beta = dyad_scale(1 / dist, dm_dn);
        d = dyad_dot(i_beta, m->i);
    } else {
        i_beta = dyad_vec2_make(0, 0);
        d = 0;
    }
    conditioning = dyad_abs(d) < spread ? dyad_abs(d) : spread;
    status = dyad_accept_conditioning(d, conditioning, input->singular_threshold, result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    j_beta = dyad_perp(i_beta);

    s = -dyad_dot(n->f, j_beta) -
        (dyad_load_moment_about_d(m) + dyad_load_moment_about_d(n)) / dist;
    a = -(s * dyad_dot(j_beta, m->i) + dyad_dot(n->f, m->i)) / d;
    result->n_mn = (s + dyad_dot(n->f, j_beta)) / d;

    result->r_np = dyad_combine(a, i_beta, s, j_beta);
    result->r_mn = dyad_scale(result->n_mn, m->j);
    result->r_mk = dyad_neg(dyad_add(result->r_mn, m->f));
    result->m_mn = -m->l * result->n_mn - dyad_load_moment_about_d(m);
    return dyad_finish(result);
}
