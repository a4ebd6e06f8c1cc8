/* dyadfmu: what the directional derivative (dyad_tangent.c) asks of the RTR dyad:
 * its conditioning's rate, its entry dyad_tangent_rtr and the tangent of its closed
 * forms on reduced loads, dyad_react_tangent_rtr. Apart from dyad_rtr.c so that a
 * program that only evaluates the reactions links none of the derivative. */
#include "dyad_tangent.h"

/* The rate of the conditioning, the smaller of |i_beta . i_m| and
 * |D_m D_n| / (l_m + l_n), as the links turn and change length; the divisor is
 * |D_m D_n| |i_beta . i_m|. */
static dyad_dual rtr_conditioning_rate(const dyad_input* input, const dyad_input* seed,
                                       const dyad_turning* t, const dyad_result* value,
                                       dyad_result* derivative)
{
    const dyad_real reach = input->m.length + input->n.length;
    const dyad_vec2 v = dyad_combine(input->m.length, t->i_m, -input->n.length, t->i_n);
    const dyad_vec2 dv = dyad_add(
        dyad_combine(seed->m.length, t->i_m, input->m.length * t->dth_m, dyad_perp(t->i_m)),
        dyad_combine(-seed->n.length, t->i_n, -input->n.length * t->dth_n, dyad_perp(t->i_n)));
    const dyad_real dist = dyad_length(v);
    const dyad_real ddist = dyad_dot(v, dv) / dist;
    const dyad_real spread = dist / reach;
    const dyad_real slant = dyad_dot(v, t->i_m) / dist;
    const dyad_real dslant =
        (dyad_dot(dv, t->i_m) + t->dth_m * dyad_dot(v, dyad_perp(t->i_m))) / dist -
        slant * ddist / dist;
    (void)value;
    derivative->denominator = dslant;
    derivative->conditioning = dyad_abs(slant) > spread
                                   ? (ddist - spread * (seed->m.length + seed->n.length)) / reach
                                   : (slant < 0 ? -dslant : dslant);
    return dyad_dual_mul(dyad_dual_make(dist, ddist), dyad_dual_abs(slant, dslant));
}

const dyad_tangent_type dyad_tangent_rtr = {DYAD_RTR, dyad_solve_rtr, dyad_react_rtr,
                                            dyad_sizes_rtr, rtr_conditioning_rate};

dyad_status dyad_react_tangent_rtr(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative)
{
    return dyad_react_tangent_of(&dyad_tangent_rtr, dyad, seed, value, derivative);
}
