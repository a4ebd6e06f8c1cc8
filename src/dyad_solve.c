/* dyadfmu: dispatch by dyad type, of the solvers and of the kinematics. Kept
 * apart from them so that a program using one type (a mechanism FMU, say) links
 * only that type's solver and kinematics. */
#include "dyad_internal.h"
#include "dyad_kin_internal.h"

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

dyad_status dyad_kinematics(dyad_type type, const dyad_kin_input* input, dyad_kin_result* result)
{
    switch (type) {
    case DYAD_RRR: return dyad_kinematics_rrr(input, result);
    case DYAD_RRT: return dyad_kinematics_rrt(input, result);
    case DYAD_RTR: return dyad_kinematics_rtr(input, result);
    case DYAD_TRT: return dyad_kinematics_trt(input, result);
    case DYAD_RTT: return dyad_kinematics_rtt(input, result);
    case DYAD_TYPE_COUNT: break;
    }
    return dyad_kin_reject(result, NULL, DYAD_STATUS_INVALID_INPUT,
                           result == NULL ? DYAD_KIN_FIELD_INPUT : DYAD_KIN_FIELD_TYPE);
}

dyad_status dyad_kinematics_tangent(dyad_type type, const dyad_kin_input* input,
                                    const dyad_kin_input* seed, dyad_kin_result* value,
                                    dyad_kin_result* derivative)
{
    switch (type) {
    case DYAD_RRR: return dyad_kinematics_tangent_rrr(input, seed, value, derivative);
    case DYAD_RRT: return dyad_kinematics_tangent_rrt(input, seed, value, derivative);
    case DYAD_RTR: return dyad_kinematics_tangent_rtr(input, seed, value, derivative);
    case DYAD_TRT: return dyad_kinematics_tangent_trt(input, seed, value, derivative);
    case DYAD_RTT: return dyad_kinematics_tangent_rtt(input, seed, value, derivative);
    case DYAD_TYPE_COUNT: break;
    }
    return dyad_kin_reject(value, derivative, DYAD_STATUS_INVALID_INPUT,
                           value == NULL || derivative == NULL ? DYAD_KIN_FIELD_INPUT
                                                               : DYAD_KIN_FIELD_TYPE);
}
