/* dyadfmu: dispatch by dyad type. Kept apart from the solvers so that a
 * program using one type links only that type's solver. */
#include "dyad_internal.h"

#include <stddef.h>

dyad_status dyad_solve(dyad_type type, const dyad_input* input, dyad_result* result)
{
    if (result == NULL) {
        return DYAD_STATUS_INVALID_INPUT;
    }
    switch (type) {
    case DYAD_RRR: return dyad_solve_rrr(input, result);
    case DYAD_RRT: return dyad_solve_rrt(input, result);
    case DYAD_RTR: return dyad_solve_rtr(input, result);
    case DYAD_TRT: return dyad_solve_trt(input, result);
    case DYAD_RTT: return dyad_solve_rtt(input, result);
    case DYAD_TYPE_COUNT: break;
    }
    result->denominator = result->conditioning = result->amplification = (dyad_real)NAN;
    return dyad_reject(result, DYAD_STATUS_INVALID_INPUT, DYAD_FIELD_TYPE);
}

dyad_status dyad_solve_tangent(dyad_type type, const dyad_input* input, const dyad_input* seed,
                               dyad_result* value, dyad_result* derivative)
{
    static const dyad_tangent_type* const kinds[DYAD_TYPE_COUNT] = {
        &dyad_tangent_rrr, &dyad_tangent_rrt, &dyad_tangent_rtr, &dyad_tangent_trt,
        &dyad_tangent_rtt};
    if ((unsigned)type >= DYAD_TYPE_COUNT) {
        if (value != NULL) {
            value->denominator = value->conditioning = value->amplification = (dyad_real)NAN;
            dyad_reject(value, DYAD_STATUS_INVALID_INPUT, DYAD_FIELD_TYPE);
        }
        if (derivative != NULL && value != NULL) {
            *derivative = *value;
        }
        return DYAD_STATUS_INVALID_INPUT;
    }
    return dyad_solve_tangent_of(kinds[type], input, seed, value, derivative);
}
