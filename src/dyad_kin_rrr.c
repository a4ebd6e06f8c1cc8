/* dyadfmu: kinematics of the RRR dyad: links m and n pinned to the external
 * links at D_m = k.point and D_n = p.point and to each other at E.
 *
 * Position. E lies on the circle of radius l_m about D_m and on that of
 * radius l_n about D_n. With d = D_n - D_m, L = |d|, u = d / L, write
 * E - D_m = a u + h k0 x u. Subtracting |E - D_n|^2 = l_n^2 from
 * |E - D_m|^2 = l_m^2 gives
 *      a = (l_m^2 - l_n^2 + L^2) / (2 L),   h = branch sqrt(l_m^2 - a^2),
 * and branch +1 puts E to the left of D_m D_n (d x (E - D_m) = h L > 0).
 * l_m^2 - a^2 cancels when E is near the line D_m D_n, exactly where h
 * decides the conditioning, so it is factored (Heron):
 *      4 L^2 h^2 = [(l_m + l_n)^2 - L^2] [L^2 - (l_m - l_n)^2]
 *                = A (l_m + l_n + L) B (L + |l_m - l_n|),
 *      A = l_m + l_n - L,   B = L - |l_m - l_n|,
 * every factor a sum or a difference of inputs. A < 0: the links do not
 * reach (TOO_FAR, gap -A = L - (l_m + l_n)); B < 0: one circle lies inside
 * the other (TOO_CLOSE, gap -B = |l_m - l_n| - L). Then
 *      i_m = (a u + h k0 x u) / l_m,   i_n = (E - D_n) / l_n = (b u + h k0 x u) / l_n,
 * with b = a - L = (l_m^2 - l_n^2 - L^2) / (2 L) formed directly.
 *
 * Velocity. E = D_m + l_m i_m = D_n + l_n i_n, with i_g' = omega_g j_g:
 *      v_Dm + omega_m l_m j_m = v_Dn + omega_n l_n j_n,
 * linear in the unknowns with the columns a = l_m j_m, b = -l_n j_n:
 *      omega_m a + omega_n b = v_Dn - v_Dm,
 * solved by Cramer's rule (cross products with b and a). Acceleration, with
 * j_g' = -omega_g i_g:
 *      a_Dm + epsilon_m l_m j_m - omega_m^2 l_m i_m = a_Dn + epsilon_n l_n j_n - omega_n^2 l_n i_n,
 * the same columns with the centripetal terms moved to the right.
 *
 * Conditioning. The determinant a x b = -l_m l_n (i_m x i_n): normalised,
 * |i_m . j_n| = |i_m x i_n|, the kinetostatic solver's figure. From the
 * position, i_m x i_n = (a h - b h) / (l_m l_n) = h L / (l_m l_n): computed
 * so, it keeps its digits as the links align (h -> 0). L = 0 with l_m = l_n
 * (the circles coincide) leaves E anywhere with the links folded on each
 * other: conditioning 0, singular.
 *
 * Round-off. A and B are differences of the inputs and of L = |d|, each
 * rounded to about eps (l_m + l_n + L); near full extension (A -> 0) or
 * folding (B -> 0) that is a large part of them. h^2 is their product, so h,
 * and with it E and both directions, is known to eps / closure of itself with
 *      closure = min(A, B) / (l_m + l_n + L)
 * (kinematics.h), while the conditioning h L / (l_m l_n) falls only like
 * sqrt(closure). The velocity equations divide by a x b, proportional to h:
 * the rates carry h's relative error, eps / closure, and the determinant's
 * own rounding, eps / conditioning. The accelerations divide by it again, with
 * omega^2 on their right-hand side: the same order. So every motion output is
 * within about eps (1 + 1 / closure + 1 / conditioning) of the largest of its unit
 * (the amplification), which scripts/tests/test_kinematics_vs_mpmath.py holds
 * against mpmath on the way to either toggle.
 *
 * The formulas below are written over a scalar of choice (dyad_kin_generic.h):
 * this file compiles them over dyad_real for dyad_kinematics_rrr, and
 * dyad_kin_rrr_tangent.c includes them over the dual numbers for the tangent.
 */
#ifndef DYAD_KIN_FORMULAS
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#include "dyad_kin_generic.h"
#include "dyad_kin_rrr.c"

dyad_status dyad_kinematics_rrr(const dyad_kin_input* input, dyad_kin_result* result)
{
    return dyad_kin_run_plain(DYAD_RRR, rrr_position_plain, rrr_motion_plain, input, input, result,
                              result);
}

#else /* the formulas, over the pass's scalar */

DYAD_KIN_STEP dyad_kin_failure DYAD_KIN(rrr_position)(const kin_in* in, kin_state* st)
{
    const dyad_kv d = kv_sub(in->p.point.pos, in->k.point.pos);
    const dyad_ks l2 = kv_dot(d, d);
    const dyad_ks len = ks_sqrt(l2);
    const dyad_ks reach = ks_add(in->l_m, in->l_n);
    const dyad_ks spread = ks_abs(ks_sub(in->l_m, in->l_n));
    const dyad_ks far = ks_sub(reach, len);                        /* A */
    const dyad_ks near = ks_sub(len, spread);                      /* B */
    const dyad_ks diff2 = ks_mul(ks_sub(in->l_m, in->l_n), reach); /* l_m^2 - l_n^2 */
    dyad_ks twice, h, a, b;
    dyad_kv u, v;
    if (ks_val(far) < 0) {
        return DYAD_KIN(dyad_kin_fail)(st, DYAD_KIN_TOO_FAR, ks_neg(far));
    }
    if (ks_val(near) < 0) {
        return DYAD_KIN(dyad_kin_fail)(st, DYAD_KIN_TOO_CLOSE, ks_neg(near));
    }
    if (ks_val(len) == 0) {
        st->conditioning = ks_c(0); /* coincident circles: folded links */
        DYAD_KIN(dyad_kin_closure)(st, near, reach);
        return DYAD_KIN_CLOSES;
    }
    twice = ks_add(len, len);
    u = kv_scale(ks_div(ks_c(1), len), d);
    v = kv_perp(u);
    h = ks_div(ks_sqrt(ks_mul(ks_mul(far, ks_add(reach, len)), ks_mul(near, ks_add(len, spread)))),
               twice);
    h = ks_mul(ks_c(in->branch), h);
    a = ks_div(ks_add(diff2, l2), twice);
    b = ks_div(ks_sub(diff2, l2), twice);
    st->i_m = kv_scale(ks_div(ks_c(1), in->l_m), DYAD_KIN(dyad_kin_combine)(a, u, h, v));
    st->i_n = kv_scale(ks_div(ks_c(1), in->l_n), DYAD_KIN(dyad_kin_combine)(b, u, h, v));
    st->conditioning = ks_abs(ks_div(ks_mul(h, len), ks_mul(in->l_m, in->l_n)));
    DYAD_KIN(dyad_kin_closure)(st, ks_val(far) < ks_val(near) ? far : near, ks_add(reach, len));
    return DYAD_KIN_CLOSES;
}

/* E from D_m along link m and from D_n along link n. */
DYAD_KIN_STEP void DYAD_KIN(rrr_sides)(const kin_in* in, const kin_state* st, kin_motion* from_m,
                                       kin_motion* from_n)
{
    *from_m = DYAD_KIN(dyad_kin_arm)(&in->k.point, st->l_m, st->i_m, st->w_m, st->e_m);
    *from_n = DYAD_KIN(dyad_kin_arm)(&in->p.point, st->l_n, st->i_n, st->w_n, st->e_n);
}

DYAD_KIN_STEP void DYAD_KIN(rrr_motion)(const kin_in* in, kin_state* st)
{
    const dyad_kv a = kv_scale(in->l_m, kv_perp(st->i_m));
    const dyad_kv b = kv_scale(ks_neg(in->l_n), kv_perp(st->i_n));
    DYAD_KIN(dyad_kin_rates)(in, st, DYAD_KIN(rrr_sides), a, b, &st->w_m, &st->e_m, &st->w_n,
                             &st->e_n);
}

#endif
