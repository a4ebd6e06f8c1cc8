/* dyadfmu: what the directional derivative (dyad_tangent.c) asks of the RRT dyad:
 * its conditioning's rate, its entry dyad_tangent_rrt and the tangent of its closed
 * forms on reduced loads, dyad_react_tangent_rrt. Apart from dyad_rrt.c so that a
 * program that only evaluates the reactions links none of the derivative. */
#include "dyad_tangent.h"

/* The rate of the conditioning d = i_n . i_k as the directions turn. */
static dyad_dual rrt_conditioning_rate(const dyad_input* input, const dyad_input* seed,
                                       const dyad_turning* t, const dyad_result* value,
                                       dyad_result* derivative)
{
    const dyad_real dc = t->dth_n * dyad_dot(dyad_perp(t->i_n), t->i_k) +
                         t->dth_k * dyad_dot(t->i_n, dyad_perp(t->i_k));
    (void)input;
    (void)seed;
    return dyad_denominator_rate(value, dc, derivative);
}

const dyad_tangent_type dyad_tangent_rrt = {DYAD_RRT, dyad_solve_rrt, dyad_react_rrt,
                                            dyad_sizes_rrt, rrt_conditioning_rate};

dyad_status dyad_react_tangent_rrt(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative)
{
    return dyad_react_tangent_of(&dyad_tangent_rrt, dyad, seed, value, derivative);
}
