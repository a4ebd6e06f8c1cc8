/* dyadfmu: RRT dyad, translational pair at D_m, revolute at E and D_n
 * (paper, section 4). Typical: the slider (m) and connecting rod (n) of a
 * slider-crank, the guide i_k on the frame k.
 *
 * Unknowns: the normal force N_mk = R_mk . j_k and reactive moment M^R_mk of
 * the sliding pair, and R_np (two components); R_mn at E follows.
 *
 * 1. Moment of link n about E, as for RRR (eq. 4):
 *      t_n = R_np . j_n = [(S_n - E) x F_n + M_n] / l_n.
 * 2. Forces on the whole dyad (eq. 12): N_mk j_k + F_m + F_n + b i_n + t_n j_n = 0
 *    with b = R_np . i_n. Dotting with j_n removes b, with i_k removes N_mk (eq. 13):
 *      N_mk = -[(F_m + F_n) . j_n + t_n] / (j_k . j_n)
 *      b    = -[t_n (j_n . i_k) + (F_m + F_n) . i_k] / (i_n . i_k)
 *    with j_k . j_n = i_n . i_k = d: it vanishes when the rod stands normal to
 *    the guide.
 * 3. Forces on link m (eq. 8): R_mn = -(R_mk + F_m), or equally on link n:
 *    R_mn = R_np + F_n. The solver takes the sum with the smaller terms (see
 *    dyad_smaller_sum): where link m is heavy and R_mn small, eq. 8 would lose
 *    R_mn's digits to cancellation.
 * 4. Moment of link m about E (eq. 11), where R_mn drops out:
 *      -l_m i_m x R_mk + (S_m - E) x F_m + M_m + M^R_mk = 0, so
 *      M^R_mk = l_m i_m x R_mk - [(S_m - E) x F_m + M_m].
 */
#include "dyad_internal.h"

dyad_status dyad_solve_rrt(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_status status = dyad_prepare(DYAD_RRT, input, &p, result);
    const dyad_body* m = &p.m;
    const dyad_body* n = &p.n;
    dyad_real d, t_n, b;
    dyad_vec2 f_sum;

    if (status != DYAD_STATUS_OK) {
        return status;
    }
    d = dyad_dot(n->i, p.i_k);
    status = dyad_accept_conditioning(DYAD_RRT, input, d, dyad_abs(d), result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }

    t_n = dyad_load_moment_about_e(n) / n->l;
    f_sum = dyad_add(m->f, n->f);
    result->n_mk = -(dyad_dot(f_sum, n->j) + t_n) / d;
    b = -(t_n * dyad_dot(n->j, p.i_k) + dyad_dot(f_sum, p.i_k)) / d;

    result->r_mk = dyad_scale(result->n_mk, p.j_k);
    result->r_np = dyad_combine(b, n->i, t_n, n->j);
    result->r_mn = dyad_smaller_sum(
        dyad_neg(dyad_add(result->r_mk, m->f)), dyad_norm1(result->r_mk) + dyad_norm1(m->f),
        dyad_add(result->r_np, n->f), dyad_norm1(result->r_np) + dyad_norm1(n->f));
    result->m_mk = m->l * dyad_cross(m->i, result->r_mk) - dyad_load_moment_about_e(m);
    return dyad_finish(DYAD_RRT, input, result);
}
