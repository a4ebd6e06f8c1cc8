/* dyadfmu: what the directional derivative (dyad_tangent.c) asks of the RTT dyad:
 * its conditioning's rate, its entry dyad_tangent_rtt and the tangent of its closed
 * forms on reduced loads, dyad_react_tangent_rtt. Apart from dyad_rtt.c so that a
 * program that only evaluates the reactions links none of the derivative. */
#include "dyad_tangent.h"

/* The rate of the conditioning d = j_k . i_m as the directions turn. */
static dyad_dual rtt_conditioning_rate(const dyad_input* input, const dyad_input* seed,
                                       const dyad_turning* t, const dyad_result* value,
                                       dyad_result* derivative)
{
    const dyad_real dc = -t->dth_k * dyad_dot(t->i_k, t->i_m) +
                         t->dth_m * dyad_dot(dyad_perp(t->i_k), dyad_perp(t->i_m));
    (void)input;
    (void)seed;
    return dyad_denominator_rate(value, dc, derivative);
}

const dyad_tangent_type dyad_tangent_rtt = {DYAD_RTT, dyad_solve_rtt, dyad_react_rtt,
                                            dyad_sizes_rtt, rtt_conditioning_rate};

dyad_status dyad_react_tangent_rtt(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative)
{
    return dyad_react_tangent_of(&dyad_tangent_rtt, dyad, seed, value, derivative);
}
