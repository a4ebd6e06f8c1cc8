/* dyadfmu: RRR dyad, all three pairs revolute (paper, section 2).
 *
 * Unknowns: R_mk at D_m and R_np at D_n, each with two components; R_mn at E
 * follows from them.
 *
 * 1. Moment of link g about E (eq. 3): R_mn passes through E and drops out,
 *      -l_g i_g x R_gd + (S_g - E) x F_g + M_g = 0,
 *    and since i_g x R = R . j_g this gives the normal component (eq. 4)
 *      t_g = R_gd . j_g = [(S_g - E) x F_g + M_g] / l_g.
 * 2. Forces on the whole dyad (eq. 5): R_mk + F_m + F_n + R_np = 0, with
 *    R_mk = a i_m + t_m j_m and R_np = b i_n + t_n j_n. Dotting with j_n
 *    removes b, dotting with j_m removes a (eq. 7):
 *      a = -[t_m (j_m . j_n) + (F_m + F_n) . j_n + t_n] / (i_m . j_n)
 *      b = -[t_n (j_n . j_m) + (F_m + F_n) . j_m + t_m] / (i_n . j_m)
 *    with i_n . j_m = -(i_m . j_n). The denominator d = i_m . j_n is the sine
 *    of the angle between the links: it vanishes when m and n are aligned.
 * 3. Forces on link m (eq. 8): R_mn = -(R_mk + F_m), or equally on link n:
 *    R_mn = R_np + F_n. The solver takes the sum with the smaller terms (see
 *    dyad_smaller_sum): where link m is heavy and R_mn small, eq. 8 would lose
 *    R_mn's digits to cancellation.
 */
#include "dyad_internal.h"

dyad_status dyad_solve_rrr(const dyad_input* input, dyad_result* result)
{
    dyad_prepared p;
    dyad_status status = dyad_prepare(DYAD_RRR, input, &p, result);
    const dyad_body* m = &p.m;
    const dyad_body* n = &p.n;
    dyad_real d, inv_d, t_m, t_n, a, b;
    dyad_vec2 f_sum;

    if (status != DYAD_STATUS_OK) {
        return status;
    }
    d = dyad_dot(m->i, n->j);
    status = dyad_accept_conditioning(DYAD_RRR, input, d, dyad_abs(d), result);
    if (status != DYAD_STATUS_OK) {
        return status;
    }

    t_m = dyad_load_moment_about_e(m) / m->l;
    t_n = dyad_load_moment_about_e(n) / n->l;
    f_sum = dyad_add(m->f, n->f);
    inv_d = 1 / d;
    a = -(t_m * dyad_dot(m->j, n->j) + dyad_dot(f_sum, n->j) + t_n) * inv_d;
    b = (t_n * dyad_dot(n->j, m->j) + dyad_dot(f_sum, m->j) + t_m) * inv_d;

    result->r_mk = dyad_combine(a, m->i, t_m, m->j);
    result->r_np = dyad_combine(b, n->i, t_n, n->j);
    result->r_mn = dyad_smaller_sum(
        dyad_neg(dyad_add(result->r_mk, m->f)), dyad_norm1(result->r_mk) + dyad_norm1(m->f),
        dyad_add(result->r_np, n->f), dyad_norm1(result->r_np) + dyad_norm1(n->f));
    return dyad_finish(DYAD_RRR, input, result);
}
