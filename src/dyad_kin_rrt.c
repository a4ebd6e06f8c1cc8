/* dyadfmu: kinematics of the RRT dyad: link m slides at D_m on the guide of
 * link k (the slider of a slider-crank), pinned to link n at E; link n is
 * pinned to p at D_n = p.point.
 *
 * Position. D_m = G_k + s_k i_k on the guide through G_k = k.point, and link
 * m keeps its direction on it: i_m = turn_m (x) i_k, omega_m = omega_k,
 * epsilon_m = epsilon_k. E = G_k + s_k i_k + l_m i_m must lie at l_n from
 * D_n. With c = G_k + l_m i_m - D_n, E - D_n = c + s_k i_k, and
 * |c + s_k i_k|^2 = l_n^2 is a quadratic in s_k:
 *      s_k = -(c . i_k) + branch r,   r = sqrt(l_n^2 - (c . j_k)^2),
 * branch +1 the larger slide. The root is factored,
 * l_n^2 - (c . j_k)^2 = (l_n - |c . j_k|)(l_n + |c . j_k|); the line E runs on
 * passes farther than l_n from D_n where |c . j_k| > l_n (OFF_LINE, gap
 * |c . j_k| - l_n). Then
 *      E - D_n = (c . j_k) j_k + branch r i_k,   i_n = (E - D_n) / l_n,
 * without the difference -(c . i_k) + (c . i_k).
 *
 * Velocity. E from the slider and from D_n (i_g' = omega_g j_g):
 *      v_Gk + s_k' i_k + omega_k k0 x (s_k i_k + l_m i_m) = v_Dn + omega_n l_n j_n,
 * the unknowns s_k' (relative to the guide) and omega_n with the columns
 * a = i_k, b = -l_n j_n. Acceleration: the slide on the turning guide adds
 * the Coriolis term 2 omega_k s_k' j_k (dyad_kin_generic.h, kin_arm):
 *      a_Gk + s_k'' i_k + (2 s_k' omega_k + s_k epsilon_k) j_k - s_k omega_k^2 i_k
 *        + l_m (epsilon_k j_m - omega_k^2 i_m)
 *      = a_Dn + epsilon_n l_n j_n - omega_n^2 l_n i_n,
 * the same columns in s_k'' and epsilon_n.
 *
 * Conditioning. a x b = -l_n (i_k x j_n) = -l_n (i_n . i_k): normalised
 * |i_n . i_k|, the kinetostatic solver's figure; from the position it is
 * |r| / l_n, exact as E - D_n turns normal to the guide (r -> 0).
 *
 * Round-off. c carries the rounding of G_k + l_m i_m - D_n, about
 * eps (|G_k| + l_m + |D_n|), and l_n - |c . j_k| that of l_n and |c . j_k|:
 * as the rod turns normal to the guide (r -> 0) the root's argument is known
 * to eps / closure of itself, with
 *      closure = (l_n - |c . j_k|) / (l_n + |c . j_k| + |G_k|_1 + l_m + |D_n|_1)
 * (|v|_1 = |v.x| + |v.y|, kinematics.h), and r, s_k and i_n to half of it; the
 * conditioning |r| / l_n falls like sqrt(closure). The rates divide by
 * a x b = -r: as for RRR, they carry eps / closure and the determinant's own
 * rounding eps / conditioning, the accelerations the same order again.
 *
 * Compiled once per scalar (dyad_kin_generic.h), as dyad_kin_rrr.c.
 */
#ifndef DYAD_KIN_FORMULAS
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#include "dyad_kin_generic.h"
#include "dyad_kin_rrt.c"

dyad_status dyad_kinematics_rrt(const dyad_kin_input* input, dyad_kin_result* result)
{
    return dyad_kin_run_plain(DYAD_RRT, rrt_position_plain, rrt_motion_plain, input, input, result,
                              result);
}

#else /* the formulas, over the pass's scalar */

DYAD_KIN_STEP dyad_kin_failure DYAD_KIN(rrt_position)(const kin_in* in, kin_state* st)
{
    const dyad_kv i_k = in->k.guide;
    const dyad_kv j_k = kv_perp(i_k);
    const dyad_kv i_m = kv_cmul(in->turn_m, i_k);
    const dyad_kv c = kv_sub(kv_add(in->k.point.pos, kv_scale(in->l_m, i_m)), in->p.point.pos);
    const dyad_ks cj = kv_dot(c, j_k);
    const dyad_ks off = ks_abs(cj);
    dyad_ks r;
    if (ks_val(off) > ks_val(in->l_n)) {
        return DYAD_KIN(dyad_kin_fail)(st, DYAD_KIN_OFF_LINE, ks_sub(off, in->l_n));
    }
    r = ks_mul(ks_c(in->branch), ks_sqrt(ks_mul(ks_sub(in->l_n, off), ks_add(in->l_n, off))));
    st->s_k.q = ks_sub(r, kv_dot(c, i_k));
    st->i_m = i_m;
    st->i_n = kv_scale(ks_div(ks_c(1), in->l_n), DYAD_KIN(dyad_kin_combine)(cj, j_k, r, i_k));
    st->w_m = in->k.omega;
    st->e_m = in->k.epsilon;
    st->conditioning = ks_abs(ks_div(r, in->l_n));
    DYAD_KIN(dyad_kin_closure)(
        st, ks_sub(in->l_n, off),
        ks_add(ks_add(ks_add(in->l_n, off), ks_add(kv_norm1(in->k.point.pos), in->l_m)),
               kv_norm1(in->p.point.pos)));
    return DYAD_KIN_CLOSES;
}

/* E from the slider on guide k along link m, and from D_n along link n. */
DYAD_KIN_STEP void DYAD_KIN(rrt_sides)(const kin_in* in, const kin_state* st, kin_motion* from_m,
                                       kin_motion* from_n)
{
    const kin_motion d_m = DYAD_KIN(dyad_kin_on_guide)(&in->k, st->s_k);
    *from_m = DYAD_KIN(dyad_kin_arm)(&d_m, st->l_m, st->i_m, st->w_m, st->e_m);
    *from_n = DYAD_KIN(dyad_kin_arm)(&in->p.point, st->l_n, st->i_n, st->w_n, st->e_n);
}

DYAD_KIN_STEP void DYAD_KIN(rrt_motion)(const kin_in* in, kin_state* st)
{
    const dyad_kv b = kv_scale(ks_neg(in->l_n), kv_perp(st->i_n));
    DYAD_KIN(dyad_kin_rates)(in, st, DYAD_KIN(rrt_sides), in->k.guide, b, &st->s_k.dq, &st->s_k.ddq,
                             &st->w_n, &st->e_n);
    st->d_m = DYAD_KIN(dyad_kin_on_guide)(&in->k, st->s_k);
}

#endif
