/* dyadfmu: what the directional derivative (dyad_tangent.c) asks of the RRR dyad:
 * its conditioning's rate, its entry dyad_tangent_rrr and the tangent of its closed
 * forms on reduced loads, dyad_react_tangent_rrr. Apart from dyad_rrr.c so that a
 * program that only evaluates the reactions links none of the derivative. */
#include "dyad_tangent.h"

/* The rate of the conditioning d = i_m . j_n as the directions turn. */
static dyad_dual rrr_conditioning_rate(const dyad_input* input, const dyad_input* seed,
                                       const dyad_turning* t, const dyad_result* value,
                                       dyad_result* derivative)
{
    const dyad_real dc = t->dth_m * dyad_dot(dyad_perp(t->i_m), dyad_perp(t->i_n)) -
                         t->dth_n * dyad_dot(t->i_m, t->i_n);
    (void)input;
    (void)seed;
    return dyad_denominator_rate(value, dc, derivative);
}

const dyad_tangent_type dyad_tangent_rrr = {DYAD_RRR, dyad_solve_rrr, dyad_react_rrr,
                                            dyad_sizes_rrr, rrr_conditioning_rate};

dyad_status dyad_react_tangent_rrr(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative)
{
    return dyad_react_tangent_of(&dyad_tangent_rrr, dyad, seed, value, derivative);
}
