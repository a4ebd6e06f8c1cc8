/* dyadfmu: kinematics of the TRT dyad: link m slides at D_m on the guide of
 * link k, link n at D_n on the guide of link p, and the two are pinned at E
 * (a cross slide). Each keeps its direction on its guide: i_m = turn_m (x) i_k,
 * omega_m = omega_k; i_n = turn_n (x) i_p, omega_n = omega_p.
 *
 * Position. D_m = G_k + s_k i_k, D_n = G_p + s_p i_p (G the mounts' points),
 * and E = D_m + l_m i_m = D_n + l_n i_n:
 *      s_k i_k - s_p i_p = G_p + l_n i_n - G_k - l_m i_m = r,
 * two linear equations in the slides, the columns i_k and -i_p, solved by
 * Cramer's rule: s_k = (r x i_p) / (i_k x i_p), s_p = (r x i_k) / (i_k x i_p).
 * They always close, once.
 *
 * Velocity. E from either slider:
 *      v_Gk + s_k' i_k + omega_k k0 x (s_k i_k + l_m i_m)
 *      = v_Gp + s_p' i_p + omega_p k0 x (s_p i_p + l_n i_n),
 * the same columns in s_k', s_p' (each relative to its guide). Acceleration,
 * with each slide's Coriolis term 2 omega s' k0 x i on its turning guide
 * (dyad_kin_generic.h, kin_arm):
 *      a_Gk + s_k'' i_k + (2 s_k' omega_k + s_k epsilon_k) j_k - s_k omega_k^2 i_k
 *        + l_m (epsilon_k j_m - omega_k^2 i_m)
 *      = the same on p's side,
 * the same columns in s_k'', s_p''.
 *
 * Conditioning. The determinant i_k x (-i_p) = -(j_k . i_p): the kinetostatic
 * solver's |j_k . i_p|, which vanishes as the guides turn parallel (and with
 * it the position: a singular TRT is reported before it is placed).
 *
 * Round-off. No root: the slides are a 2 x 2 solve whose determinant is the
 * conditioning, so the positions carry eps / conditioning of the size of their
 * terms, |G_k|_1 + |G_p|_1 + l_m + l_n (|v|_1 = |v.x| + |v.y|), and the rates,
 * solved with the same columns, the same order; the closure is 1
 * (kinematics.h).
 *
 * Compiled once per scalar (dyad_kin_generic.h), as dyad_kin_rrr.c.
 */
#ifndef DYAD_KIN_FORMULAS
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#include "dyad_kin_generic.h"
#include "dyad_kin_trt.c"

dyad_status dyad_kinematics_trt(const dyad_kin_input* input, dyad_kin_result* result)
{
    return dyad_kin_run_plain(DYAD_TRT, trt_position_plain, trt_motion_plain, input, input, result,
                              result);
}

#else /* the formulas, over the pass's scalar */

DYAD_KIN_STEP dyad_kin_failure DYAD_KIN(trt_position)(const kin_in* in, kin_state* st)
{
    const dyad_kv i_k = in->k.guide;
    const dyad_kv i_p = in->p.guide;
    const dyad_kv i_m = kv_cmul(in->turn_m, i_k);
    const dyad_kv i_n = kv_cmul(in->turn_n, i_p);
    const dyad_kv r = kv_sub(kv_add(in->p.point.pos, kv_scale(in->l_n, i_n)),
                             kv_add(in->k.point.pos, kv_scale(in->l_m, i_m)));
    st->i_m = i_m;
    st->i_n = i_n;
    st->w_m = in->k.omega;
    st->e_m = in->k.epsilon;
    st->w_n = in->p.omega;
    st->e_n = in->p.epsilon;
    st->conditioning = ks_abs(kv_cross(i_k, i_p));
    st->size = ks_add(ks_add(kv_norm1(in->k.point.pos), kv_norm1(in->p.point.pos)),
                      ks_add(in->l_m, in->l_n));
    DYAD_KIN(dyad_kin_solve2)(i_k, kv_neg(i_p), r, &st->s_k.q, &st->s_p.q);
    return DYAD_KIN_CLOSES;
}

/* E from the slider on guide k along m, and from the slider on guide p along n. */
DYAD_KIN_STEP void DYAD_KIN(trt_sides)(const kin_in* in, const kin_state* st, kin_motion* from_m,
                                       kin_motion* from_n)
{
    const kin_motion d_m = DYAD_KIN(dyad_kin_on_guide)(&in->k, st->s_k);
    const kin_motion d_n = DYAD_KIN(dyad_kin_on_guide)(&in->p, st->s_p);
    *from_m = DYAD_KIN(dyad_kin_arm)(&d_m, st->l_m, st->i_m, st->w_m, st->e_m);
    *from_n = DYAD_KIN(dyad_kin_arm)(&d_n, st->l_n, st->i_n, st->w_n, st->e_n);
}

DYAD_KIN_STEP void DYAD_KIN(trt_motion)(const kin_in* in, kin_state* st)
{
    DYAD_KIN(dyad_kin_rates)(in, st, DYAD_KIN(trt_sides), in->k.guide, kv_neg(in->p.guide),
                             &st->s_k.dq, &st->s_k.ddq, &st->s_p.dq, &st->s_p.ddq);
    st->d_m = DYAD_KIN(dyad_kin_on_guide)(&in->k, st->s_k);
    st->d_n = DYAD_KIN(dyad_kin_on_guide)(&in->p, st->s_p);
}

#endif
