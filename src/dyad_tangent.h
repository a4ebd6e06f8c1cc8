/* dyadfmu: what the directional derivative (dyad_tangent.c) asks of each dyad
 * type. The derivation is shared; three things differ by type: its solver, the
 * sizes of its outputs (the amplification's formulas) and the rate of its
 * conditioning, gathered in the dyad_tangent_<type> of the type's
 * dyad_<type>_tangent.c. Its reactions on reduced loads (react) serve the
 * tangent of dyad_react_<type>. Not part of the public API. */
#ifndef DYADFMU_TANGENT_H
#define DYADFMU_TANGENT_H

#include "dyad_internal.h"

/* How the dyad's frames turn along the seed: the unit directions and their
 * angle rates (rad per unit of the seed's parameter). */
typedef struct dyad_turning {
    dyad_vec2 i_m, i_n, i_k, i_p;
    dyad_real dth_m, dth_n, dth_k, dth_p;
} dyad_turning;

/* The rate of a type's conditioning: sets derivative->denominator and
 * derivative->conditioning, and returns the type's divisor |d| (RTR:
 * |D_m D_n| |d|) with its rate, for the amplification's rate. */
typedef dyad_dual (*dyad_conditioning_rate)(const dyad_input* input, const dyad_input* seed,
                                            const dyad_turning* turning, const dyad_result* value,
                                            dyad_result* derivative);

/* One dyad type as the tangent sees it (declared in dyadfmu/dyad.h). */
struct dyad_tangent_type {
    dyad_type type;
    dyad_solver solve;
    dyad_status (*react)(const dyad_loaded* dyad, dyad_result* result);
    dyad_output_sizes (*sizes)(const dyad_size_terms* terms);
    dyad_conditioning_rate conditioning_rate;
};

/* The conditioning rate of the types whose conditioning is a signed
 * denominator d (all but RTR): dc, the rate of d. */
static inline dyad_dual dyad_denominator_rate(const dyad_result* value, dyad_real dc,
                                              dyad_result* derivative)
{
    derivative->denominator = dc;
    derivative->conditioning = value->denominator < 0 ? -dc : dc;
    return dyad_dual_abs(value->denominator, dc);
}

/* dyad_react_tangent_<type>: the tangent of the closed forms on reduced loads. */
dyad_status dyad_react_tangent_of(const dyad_tangent_type* kind, const dyad_loaded* dyad,
                                  const dyad_loaded* seed, dyad_result* value,
                                  dyad_result* derivative);

#endif /* DYADFMU_TANGENT_H */
