/* dyadfmu: what result.amplification is made of. Not part of the public API.
 *
 * The contract: for status ok, every output o of a unit group G (the forces
 * r_mk, r_np, r_mn, n_mk, n_np, n_mn in N; the reactive moments m_mk, m_np,
 * m_mn in N m) satisfies
 *
 *      |o - o_exact| <= c * eps * amplification * max_{o' in G} |o'|,
 *
 * o_exact being the reactions of the same (double or float) inputs in exact
 * arithmetic, the maximum taken over the reported outputs, and c a small
 * constant (scripts/tests/test_accuracy.py holds it to 16). Once eps x
 * amplification reaches 1 it says no more than that no digit is certain:
 * an output may then even be 0 where the exact one is not.
 *
 * Where it comes from. Every quantity q a solver computes is a sum of terms;
 * its "size" s_q bounds the sum of the magnitudes of those terms, carried
 * through the closed forms: sizes add where quantities add, scale with a
 * lever where a quantity is multiplied by one, and grow by 1/|d| where the
 * type divides by its denominator d. Round-off of q is then a few eps times
 * s_q, and since d itself is only known to a few eps, a quotient by d carries
 * a relative error of a few eps / |d| more: with the conditioning c_d <= |d|,
 * |q - q_exact| <= c eps s_q / c_d. Per group,
 *
 *      data factor = (largest size of the group's outputs) / (largest output),
 *      amplification = max over the groups of the data factor / conditioning,
 *
 * with the data factor at least 1 and at most 1/eps (where the group's outputs
 * lie below their own round-off, no digit is left to count; it also keeps the
 * value finite when a group's outputs are all 0). The data factor measures the
 * cancellation of the load terms: a heavy, fast link whose inertia force
 * nearly cancels its active load, or a reactive moment that is the small
 * difference of two large moments of the same forces. Without cancellation it
 * is 1 to 3, and the amplification is the geometric 1 / conditioning.
 *
 * The singular flag stays geometric: the status is singular when the
 * conditioning falls below singular_threshold, whatever the data factor. A
 * large data factor with a good conditioning means the loads themselves fix
 * the reactions only to eps x amplification; it is reported, not refused.
 *
 * The sizes are computed on dual numbers (a value and its rate along a seed),
 * so that the directional derivative of the amplification (dyad_tangent.c)
 * follows the same formulas; on the solvers' path every rate is zero and never
 * read, and the compiler drops it.
 */
#ifndef DYADFMU_AMPLIFICATION_H
#define DYADFMU_AMPLIFICATION_H

#include "dyadfmu/dual.h"
#include "dyadfmu/types.h"

#include <math.h>

/* |v.x| + |v.y| and its rate. */
static inline dyad_dual dyad_dual_norm1(dyad_vec2 v, dyad_vec2 dv)
{
    return dyad_dual_add(dyad_dual_abs(v.x, dv.x), dyad_dual_abs(v.y, dv.y));
}

/* Written as the x86 maxsd / minsd compute them, so that each is one instruction. */
static inline dyad_dual dyad_dual_max(dyad_dual a, dyad_dual b)
{
    return a.v > b.v ? a : b;
}

static inline dyad_dual dyad_dual_min(dyad_dual a, dyad_dual b)
{
    return a.v < b.v ? a : b;
}

/* ---- the sizes of a link's resultant --------------------------------------
 * The resultant (dyad_resultant in dyad_internal.h) sums, with r = S_g - D_g,
 *      F   = force + m g - m a_D - m epsilon k0 x r  +  m omega^2 r,
 *      M_D = moment - J epsilon + r x (F without its centripetal part m omega^2 r).
 * f_size is the sum of |x| + |y| of every term of F; m_d_size that of every
 * term of M_D, with |r x v| bounded by (|r.x| + |r.y|)(|v.x| + |v.y|). */
typedef struct dyad_link_sizes {
    dyad_dual f;   /* of F (N) */
    dyad_dual m_d; /* of M_D (N m) */
} dyad_link_sizes;

/* link and rate: the link's inputs and their rates (all zero on the solvers'
 * path); r, dr: its centre-of-mass offset in the global frame and its rate;
 * gravity, dgravity likewise. */
static inline dyad_link_sizes dyad_link_sizes_of(const dyad_link* link, const dyad_link* rate,
                                                 dyad_vec2 r, dyad_vec2 dr, dyad_vec2 gravity,
                                                 dyad_vec2 dgravity)
{
    const dyad_dual mass = dyad_dual_make(link->mass, rate->mass);
    const dyad_dual omega = dyad_dual_make(link->omega, rate->omega);
    const dyad_dual lever = dyad_dual_norm1(r, dr);
    const dyad_dual turn = dyad_dual_abs(link->epsilon, rate->epsilon);
    const dyad_dual accel =
        dyad_dual_add(dyad_dual_add(dyad_dual_norm1(gravity, dgravity),
                                    dyad_dual_norm1(link->accel_d, rate->accel_d)),
                      dyad_dual_mul(turn, lever));
    const dyad_dual without_centripetal =
        dyad_dual_add(dyad_dual_norm1(link->force, rate->force), dyad_dual_mul(mass, accel));
    const dyad_dual centripetal =
        dyad_dual_mul(dyad_dual_mul(dyad_dual_mul(mass, omega), omega), lever);
    dyad_link_sizes s;
    s.f = dyad_dual_add(without_centripetal, centripetal); /* m omega^2 |r| >= 0 */
    s.m_d = dyad_dual_add(
        dyad_dual_add(dyad_dual_abs(link->moment, rate->moment),
                      dyad_dual_mul(dyad_dual_make(link->inertia, rate->inertia), turn)),
        dyad_dual_mul(lever, without_centripetal));
    return s;
}

/* ---- the sizes of each type's outputs --------------------------------------
 * From the link sizes (f_g, m_g of F_g and M_Dg), the lengths l_g and the
 * inverse of the divisor (inv: 1/|d|; for RTR 1/(|D_m D_n| |d|)), the largest
 * size of the forces and of the reactive moments, following each solver's
 * closed forms (see its file). */
typedef struct dyad_output_sizes {
    dyad_dual force;  /* N */
    dyad_dual moment; /* N m; 0 where every pair is revolute */
    int first_form;   /* RTR: M^R_mn from link m (1) or from link n (0) */
} dyad_output_sizes;

typedef struct dyad_size_terms {
    dyad_dual f_m, m_m, f_n, m_n; /* sizes of F_m, M_Dm, F_n, M_Dn */
    dyad_dual l_m, l_n;           /* lengths (m) */
    dyad_dual inv;                /* inverse divisor: 1/|d|, RTR 1/(|D_m D_n| |d|) */
} dyad_size_terms;

/* RRR: beta = -M_Dm / l_m, alpha = (M_Dn / l_n - beta j_m.j_n) / d, R_mn from
 * both, R_mk = -(R_mn + F_m), R_np = R_mn - F_n. */
static inline dyad_output_sizes dyad_sizes_rrr(const dyad_size_terms* t)
{
    const dyad_dual beta = dyad_dual_div(t->m_m, t->l_m);
    const dyad_dual alpha =
        dyad_dual_mul(dyad_dual_add(dyad_dual_div(t->m_n, t->l_n), beta), t->inv);
    dyad_output_sizes s;
    s.force = dyad_dual_add(dyad_dual_add(alpha, beta), dyad_dual_add(t->f_m, t->f_n));
    s.moment = dyad_dual_const(0);
    s.first_form = 1;
    return s;
}

/* RRT: tau = M_Dn / l_n, gamma = -(F_m.i_k + tau j_n.i_k) / d, R_mn from both,
 * N_mk = -(F_m + R_mn).j_k, R_np = R_mn - F_n, M^R_mk = -M_Dm - l_m i_m x R_mn. */
static inline dyad_output_sizes dyad_sizes_rrt(const dyad_size_terms* t)
{
    const dyad_dual tau = dyad_dual_div(t->m_n, t->l_n);
    const dyad_dual r_mn = dyad_dual_add(dyad_dual_mul(dyad_dual_add(t->f_m, tau), t->inv), tau);
    dyad_output_sizes s;
    s.force = dyad_dual_add(r_mn, dyad_dual_add(t->f_m, t->f_n));
    s.moment = dyad_dual_add(t->m_m, dyad_dual_mul(t->l_m, r_mn));
    s.first_form = 1;
    return s;
}

/* RTR: N_mn = -(M_Dm + M_Dn) / (|D_m D_n| d), R_np = R_mn - F_n,
 * R_mk = -(R_mn + F_m); M^R_mn = -l_m N_mn - M_Dm (link m about D_m) or
 * -l_n i_n x R_np + M_Dn - l_n F_n.j_n (link n about E): the solver takes the
 * form of the smaller size. */
static inline dyad_output_sizes dyad_sizes_rtr(const dyad_size_terms* t)
{
    const dyad_dual n_mn = dyad_dual_mul(dyad_dual_add(t->m_m, t->m_n), t->inv);
    const dyad_dual via_m = dyad_dual_add(dyad_dual_mul(t->l_m, n_mn), t->m_m);
    const dyad_dual via_n = dyad_dual_add(
        dyad_dual_mul(t->l_n, dyad_dual_add(n_mn, dyad_dual_add(t->f_n, t->f_n))), t->m_n);
    dyad_output_sizes s;
    s.force = dyad_dual_add(n_mn, dyad_dual_add(t->f_m, t->f_n));
    s.first_form = via_m.v < via_n.v; /* as dyad_dual_min picks */
    s.moment = dyad_dual_min(via_m, via_n);
    return s;
}

/* TRT: N_mk, N_np = -/+(F_m + F_n).i_p,k / d, R_mn = -(R_mk + F_m) or R_np + F_n;
 * M^R_gd = l_g i_g x R_gd - (M_Dg - l_g F_g.j_g). */
static inline dyad_output_sizes dyad_sizes_trt(const dyad_size_terms* t)
{
    const dyad_dual normal = dyad_dual_mul(dyad_dual_add(t->f_m, t->f_n), t->inv);
    dyad_output_sizes s;
    s.force = dyad_dual_add(normal, dyad_dual_add(t->f_m, t->f_n));
    s.moment =
        dyad_dual_max(dyad_dual_add(dyad_dual_mul(t->l_m, dyad_dual_add(normal, t->f_m)), t->m_m),
                      dyad_dual_add(dyad_dual_mul(t->l_n, dyad_dual_add(normal, t->f_n)), t->m_n));
    s.first_form = 1;
    return s;
}

/* RTT: N_mk = -F_m.i_m / d, N_mn = F_m.i_k / d, R_np = -(R_mk + F_m + F_n) or
 * R_mn - F_n; M^R_mn = M_Dn - l_n i_n x R_mn (link n about D_n),
 * M^R_mk = -M_Dm - l_m i_m x R_mn - M^R_mn (link m about D_m). */
static inline dyad_output_sizes dyad_sizes_rtt(const dyad_size_terms* t)
{
    const dyad_dual normal = dyad_dual_mul(t->f_m, t->inv);
    const dyad_dual m_mn = dyad_dual_add(t->m_n, dyad_dual_mul(t->l_n, normal));
    dyad_output_sizes s;
    s.force = dyad_dual_add(normal, dyad_dual_add(t->f_m, t->f_n));
    s.moment = dyad_dual_add(dyad_dual_add(t->m_m, dyad_dual_mul(t->l_m, normal)), m_mn);
    s.first_form = 1;
    return s;
}

/* ---- from sizes to the amplification -------------------------------------------------------- */

/* Largest |component| of the reaction forces R_mk, R_np, R_mn, with its rate.
 * The normal forces are projections of these (|N| <= sqrt(2) x this), so the
 * factor computed against it also covers them. */
static inline dyad_dual dyad_largest_force(const dyad_result* value, const dyad_result* rate)
{
    dyad_dual a = dyad_dual_max(dyad_dual_abs(value->r_mk.x, rate->r_mk.x),
                                dyad_dual_abs(value->r_mk.y, rate->r_mk.y));
    dyad_dual b = dyad_dual_max(dyad_dual_abs(value->r_np.x, rate->r_np.x),
                                dyad_dual_abs(value->r_np.y, rate->r_np.y));
    dyad_dual c = dyad_dual_max(dyad_dual_abs(value->r_mn.x, rate->r_mn.x),
                                dyad_dual_abs(value->r_mn.y, rate->r_mn.y));
    return dyad_dual_max(dyad_dual_max(a, b), c);
}

/* Largest reactive moment of the type's sliding pairs, with its rate
 * (pair: 1 where D_m, E, D_n slides). */
static inline dyad_dual dyad_largest_moment(const dyad_result* value, const dyad_result* rate,
                                            int slides_dm, int slides_e, int slides_dn)
{
    dyad_dual largest = dyad_dual_const(0);
    if (slides_dm) {
        largest = dyad_dual_abs(value->m_mk, rate->m_mk);
    }
    if (slides_e) {
        largest = dyad_dual_max(largest, dyad_dual_abs(value->m_mn, rate->m_mn));
    }
    if (slides_dn) {
        largest = dyad_dual_max(largest, dyad_dual_abs(value->m_np, rate->m_np));
    }
    return largest;
}

/* One group's data factor: size / largest output, in [1, 1/eps]. Written so
 * that a NaN or infinite size (a sum of magnitudes that overflowed) gives
 * 1/eps, and an all-zero group with zero size gives 1. */
static inline dyad_dual dyad_data_factor(dyad_dual size, dyad_dual largest)
{
    if (!(size.v <= largest.v * (1 / DYAD_REAL_EPSILON))) {
        return dyad_dual_const(1 / DYAD_REAL_EPSILON);
    }
    return size.v > largest.v ? dyad_dual_div(size, largest) : dyad_dual_const(1);
}

/* amplification = max(data factor of the forces, of the moments) / conditioning,
 * kept finite (a conditioning near the smallest threshold could overflow it). */
static inline dyad_dual dyad_amplification_of(dyad_output_sizes sizes, dyad_dual largest_force,
                                              dyad_dual largest_moment, dyad_dual conditioning)
{
    const dyad_dual factor = dyad_dual_max(dyad_data_factor(sizes.force, largest_force),
                                           dyad_data_factor(sizes.moment, largest_moment));
    const dyad_dual a = dyad_dual_div(factor, conditioning);
    return a.v < DYAD_REAL_MAX ? a : dyad_dual_const(DYAD_REAL_MAX);
}

#endif /* DYADFMU_AMPLIFICATION_H */
