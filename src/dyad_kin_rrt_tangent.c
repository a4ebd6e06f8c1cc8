/* dyadfmu: the tangent of the RRT kinematics, dyad_kinematics_tangent_rrt: the
 * formulas of dyad_kin_rrt.c on dual numbers (dyad_kin_generic.h). Apart from
 * dyad_kin_rrt.c so that a program that only evaluates the motion links none of
 * the derivative. */
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#define DYAD_KIN_DUAL
#include "dyad_kin_generic.h"
#include "dyad_kin_rrt.c"

dyad_status dyad_kinematics_tangent_rrt(const dyad_kin_input* input, const dyad_kin_input* seed,
                                        dyad_kin_result* value, dyad_kin_result* derivative)
{
    return dyad_kin_run_dual(DYAD_RRT, rrt_position_dual, rrt_motion_dual, input, seed, value,
                             derivative);
}
