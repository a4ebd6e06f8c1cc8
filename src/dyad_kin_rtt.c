/* dyadfmu: kinematics of the RTT dyad: link m slides at D_m on the guide of
 * link k and carries a slot along i_m in which E, the block n, slides; n is
 * pinned to p at D_n = p.point (the Scotch yoke). Directions are locked:
 * i_m = turn_m (x) i_k, i_n = turn_n (x) i_m, so omega_m = omega_n = omega_k
 * and epsilon likewise; l_m = |D_m E| is an output (a signed coordinate along
 * the slot: one assembly, whatever its sign).
 *
 * Position. E = D_n + l_n i_n is known at once, and E = G_k + s_k i_k + l_m i_m
 * (G_k = k.point):
 *      s_k i_k + l_m i_m = E - G_k,
 * two linear equations in s_k and l_m, the columns i_k and i_m, by Cramer's
 * rule: s_k = ((E - G_k) x i_m) / (i_k x i_m), l_m = (i_k x (E - G_k)) / (i_k x i_m).
 *
 * Velocity. E from the slider along the slot, and from D_n along n:
 *      v_Gk + s_k' i_k + l_m' i_m + omega_k k0 x (s_k i_k + l_m i_m)
 *      = v_Dn + omega_k l_n j_n,
 * the same columns in s_k' and l_m'. Acceleration, with the Coriolis terms of
 * both slides on turning guides (dyad_kin_generic.h, kin_arm):
 *      a_Gk + s_k'' i_k + (2 s_k' omega_k + s_k epsilon_k) j_k - s_k omega_k^2 i_k
 *        + l_m'' i_m + (2 l_m' omega_k + l_m epsilon_k) j_m - l_m omega_k^2 i_m
 *      = a_Dn + epsilon_k l_n j_n - omega_k^2 l_n i_n,
 * the same columns in s_k'' and l_m''.
 *
 * Conditioning. The determinant i_k x i_m = j_k . i_m, the kinetostatic
 * solver's |j_k . i_m| (= |sin delta_m|): it vanishes with the slot parallel
 * to the guide, where the position too is undefined.
 *
 * Round-off. No root: s_k and l_m are a 2 x 2 solve whose determinant is the
 * conditioning, so the positions carry eps / conditioning of the size of their
 * terms, |G_k|_1 + |D_n|_1 + l_n (|v|_1 = |v.x| + |v.y|), and the rates, solved
 * with the same columns, the same order; the closure is 1 (kinematics.h).
 *
 * Compiled once per scalar (dyad_kin_generic.h), as dyad_kin_rrr.c.
 */
#ifndef DYAD_KIN_FORMULAS
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#include "dyad_kin_generic.h"
#include "dyad_kin_rtt.c"

dyad_status dyad_kinematics_rtt(const dyad_kin_input* input, dyad_kin_result* result)
{
    return dyad_kin_run_plain(DYAD_RTT, rtt_position_plain, rtt_motion_plain, input, input, result,
                              result);
}

#else /* the formulas, over the pass's scalar */

DYAD_KIN_STEP dyad_kin_failure DYAD_KIN(rtt_position)(const kin_in* in, kin_state* st)
{
    const dyad_kv i_k = in->k.guide;
    const dyad_kv i_m = kv_cmul(in->turn_m, i_k);
    const dyad_kv i_n = kv_cmul(in->turn_n, i_m);
    const dyad_kv e = kv_add(in->p.point.pos, kv_scale(in->l_n, i_n));
    st->i_m = i_m;
    st->i_n = i_n;
    st->w_m = st->w_n = in->k.omega;
    st->e_m = st->e_n = in->k.epsilon;
    st->conditioning = ks_abs(kv_cross(i_k, i_m));
    st->size = ks_add(ks_add(kv_norm1(in->k.point.pos), kv_norm1(in->p.point.pos)), in->l_n);
    DYAD_KIN(dyad_kin_solve2)(i_k, i_m, kv_sub(e, in->k.point.pos), &st->s_k.q, &st->l_m.q);
    return DYAD_KIN_CLOSES;
}

/* E from the slider on guide k along the slot, and from D_n along n. */
DYAD_KIN_STEP void DYAD_KIN(rtt_sides)(const kin_in* in, const kin_state* st, kin_motion* from_m,
                                       kin_motion* from_n)
{
    const kin_motion d_m = DYAD_KIN(dyad_kin_on_guide)(&in->k, st->s_k);
    *from_m = DYAD_KIN(dyad_kin_arm)(&d_m, st->l_m, st->i_m, st->w_m, st->e_m);
    *from_n = DYAD_KIN(dyad_kin_arm)(&in->p.point, st->l_n, st->i_n, st->w_n, st->e_n);
}

DYAD_KIN_STEP void DYAD_KIN(rtt_motion)(const kin_in* in, kin_state* st)
{
    DYAD_KIN(dyad_kin_rates)(in, st, DYAD_KIN(rtt_sides), in->k.guide, st->i_m, &st->s_k.dq,
                             &st->s_k.ddq, &st->l_m.dq, &st->l_m.ddq);
    st->d_m = DYAD_KIN(dyad_kin_on_guide)(&in->k, st->s_k);
}

#endif
