/* dyadfmu: what the directional derivative (dyad_tangent.c) asks of the TRT dyad:
 * its conditioning's rate, its entry dyad_tangent_trt and the tangent of its closed
 * forms on reduced loads, dyad_react_tangent_trt. Apart from dyad_trt.c so that a
 * program that only evaluates the reactions links none of the derivative. */
#include "dyad_tangent.h"

/* The rate of the conditioning d = j_k . i_p as the directions turn. */
static dyad_dual trt_conditioning_rate(const dyad_input* input, const dyad_input* seed,
                                       const dyad_turning* t, const dyad_result* value,
                                       dyad_result* derivative)
{
    const dyad_real dc = -t->dth_k * dyad_dot(t->i_k, t->i_p) +
                         t->dth_p * dyad_dot(dyad_perp(t->i_k), dyad_perp(t->i_p));
    (void)input;
    (void)seed;
    return dyad_denominator_rate(value, dc, derivative);
}

const dyad_tangent_type dyad_tangent_trt = {DYAD_TRT, dyad_solve_trt, dyad_react_trt,
                                            dyad_sizes_trt, trt_conditioning_rate};

dyad_status dyad_react_tangent_trt(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative)
{
    return dyad_react_tangent_of(&dyad_tangent_trt, dyad, seed, value, derivative);
}
