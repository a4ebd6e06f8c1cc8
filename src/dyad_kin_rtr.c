/* dyadfmu: kinematics of the RTR dyad: link m pinned to k at D_m = k.point,
 * link n pinned to p at D_n = p.point, and E sliding along link m (the block n
 * in the slotted lever m of a quick-return mechanism). Link n keeps its
 * direction on m: i_n = turn_n (x) i_m, omega_n = omega_m; l_m = |D_m E| is
 * an output.
 *
 * Position. With turn_n = (cos delta, sin delta) and d = D_n - D_m,
 *      d = l_m i_m - l_n i_n = (l_m - l_n turn_n) (x) i_m = w (x) i_m,
 *      w = (l_m - l_n cos delta, -l_n sin delta),
 * so |d| = |w|: l_m^2 - 2 l_m l_n cos delta + l_n^2 - |d|^2 = 0,
 *      l_m = l_n cos delta + branch r,   r = sqrt(|d|^2 - l_n^2 sin^2 delta),
 * branch +1 the larger root. r^2 = (|d| - l_n |sin delta|)(|d| + l_n |sin delta|);
 * the slot's line passes farther than |d| from D_m where |d| < l_n |sin delta|
 * (OFF_SLOT, gap l_n |sin delta| - |d|). Of the two roots, the one whose
 * terms share a sign is formed directly and the other from their product
 * l_n^2 - |d|^2 = (l_n - |d|)(l_n + |d|), so neither cancels. A root l_m <= 0
 * puts E on or behind D_m (BEHIND_PIVOT, gap -l_m). Since w.x = l_m - l_n cos
 * delta = branch r exactly, i_m turns d back by the angle of w:
 *      i_m = d (x) conj(w) / |d|^2,   conj(w) = (branch r, l_n sin delta).
 *
 * Velocity. E along m from D_m and along n from D_n:
 *      v_Dm + l_m' i_m + omega l_m j_m = v_Dn + omega l_n j_n,
 * the unknowns l_m' and omega = omega_m = omega_n with the columns a = i_m,
 * b = l_m j_m - l_n j_n = k0 x d. Acceleration, with the Coriolis term of E
 * sliding on the turning link m:
 *      a_Dm + l_m'' i_m + (2 l_m' omega + l_m epsilon) j_m - l_m omega^2 i_m
 *      = a_Dn + epsilon l_n j_n - omega^2 l_n i_n,
 * the same columns in l_m'' and epsilon.
 *
 * Conditioning. a x b = i_m . d = |d| (i_beta . i_m), i_beta = d / |d|; as the
 * kinetostatic solver's, the smaller of |i_beta . i_m| and |d| / (l_m + l_n)
 * (which vanishes as D_m and D_n meet). Since d . i_m = w.x = branch r,
 * |i_beta . i_m| = r / |d|, exact as the slot stands normal to D_m D_n.
 *
 * Round-off. |d| is rounded to about eps |d| and the slot's reach
 * l_n |sin delta| to eps of itself, so as the slot stands normal to D_m D_n
 * (r -> 0) the root's argument |d| - l_n |sin delta| is known to eps / closure
 * of itself, with
 *      closure = (|d| - l_n |sin delta|) / (|d| + l_n |sin delta|)
 * (kinematics.h), and r, l_m and i_m to half of it; |i_beta . i_m| = r / |d|
 * falls like sqrt(closure). The rates divide by d . i_m = branch r: they carry
 * eps / closure and eps / conditioning, the accelerations the same order again.
 *
 * Compiled once per scalar (dyad_kin_generic.h), as dyad_kin_rrr.c.
 */
#ifndef DYAD_KIN_FORMULAS
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#include "dyad_kin_generic.h"
#include "dyad_kin_rtr.c"

dyad_status dyad_kinematics_rtr(const dyad_kin_input* input, dyad_kin_result* result)
{
    return dyad_kin_run_plain(DYAD_RTR, rtr_position_plain, rtr_motion_plain, input, input, result,
                              result);
}

#else /* the formulas, over the pass's scalar */

/* l_m, the root of l^2 - 2 l c + (l_n^2 - |d|^2) = 0 the branch takes, given
 * c = l_n cos delta and r; neither root cancels. */
DYAD_KIN_STEP dyad_ks DYAD_KIN(rtr_length)(const kin_in* in, dyad_ks c, dyad_ks r, dyad_ks dist)
{
    const dyad_ks outer = ks_val(c) >= 0 ? ks_add(c, r) : ks_sub(c, r);
    const dyad_ks product = ks_mul(ks_sub(in->l_n, dist), ks_add(in->l_n, dist));
    const dyad_ks inner = ks_val(outer) != 0 ? ks_div(product, outer) : ks_c(0);
    /* outer is the larger root where c >= 0, the smaller where c < 0. */
    return (in->branch > 0) == (ks_val(c) >= 0) ? outer : inner;
}

DYAD_KIN_STEP dyad_kin_failure DYAD_KIN(rtr_position)(const kin_in* in, kin_state* st)
{
    const dyad_kv d = kv_sub(in->p.point.pos, in->k.point.pos);
    const dyad_ks d2 = kv_dot(d, d);
    const dyad_ks dist = ks_sqrt(d2);
    const dyad_ks c = ks_mul(in->l_n, kv_x(in->turn_n));
    const dyad_ks ls = ks_mul(in->l_n, kv_y(in->turn_n));
    const dyad_ks reach = ks_abs(ls);
    dyad_ks r, l_m, slant, spread;
    if (ks_val(dist) < ks_val(reach)) {
        return DYAD_KIN(dyad_kin_fail)(st, DYAD_KIN_OFF_SLOT, ks_sub(reach, dist));
    }
    r = ks_sqrt(ks_mul(ks_sub(dist, reach), ks_add(dist, reach)));
    l_m = DYAD_KIN(rtr_length)(in, c, r, dist);
    if (!(ks_val(l_m) > 0)) {
        return DYAD_KIN(dyad_kin_fail)(st, DYAD_KIN_BEHIND_PIVOT, ks_neg(l_m));
    }
    st->l_m.q = l_m;
    st->i_m = kv_scale(ks_div(ks_c(1), d2), kv_cmul(d, kv_make(ks_mul(ks_c(in->branch), r), ls)));
    st->i_n = kv_cmul(in->turn_n, st->i_m);
    slant = ks_div(r, dist);
    spread = ks_div(dist, ks_add(l_m, in->l_n));
    st->conditioning = ks_val(slant) < ks_val(spread) ? slant : spread;
    DYAD_KIN(dyad_kin_closure)(st, ks_sub(dist, reach), ks_add(dist, reach));
    return DYAD_KIN_CLOSES;
}

/* E along m from D_m, and along n from D_n; n turns with m. */
DYAD_KIN_STEP void DYAD_KIN(rtr_sides)(const kin_in* in, const kin_state* st, kin_motion* from_m,
                                       kin_motion* from_n)
{
    *from_m = DYAD_KIN(dyad_kin_arm)(&in->k.point, st->l_m, st->i_m, st->w_m, st->e_m);
    *from_n = DYAD_KIN(dyad_kin_arm)(&in->p.point, st->l_n, st->i_n, st->w_m, st->e_m);
}

DYAD_KIN_STEP void DYAD_KIN(rtr_motion)(const kin_in* in, kin_state* st)
{
    const dyad_kv b = kv_perp(kv_sub(in->p.point.pos, in->k.point.pos));
    DYAD_KIN(dyad_kin_rates)(in, st, DYAD_KIN(rtr_sides), st->i_m, b, &st->l_m.dq, &st->l_m.ddq,
                             &st->w_m, &st->e_m);
    st->w_n = st->w_m;
    st->e_n = st->e_m;
}

#endif
