/* dyadfmu: the tangent of the cylinder, dyad_cylinder_tangent: the formulas of
 * dyad_cylinder.c on dual numbers (dyad_kin_generic.h). Apart from
 * dyad_cylinder.c so that a program that only evaluates links none of the
 * derivative. */
#include "dyadfmu/cylinder.h"
#include "dyad_kin_internal.h"
#define DYAD_KIN_FORMULAS
#define DYAD_KIN_DUAL
#include "dyad_kin_generic.h"
#include "dyad_cylinder.c"

dyad_status dyad_cylinder_tangent(const dyad_cylinder_input* input, const dyad_cylinder_input* seed,
                                  dyad_cylinder_result* value, dyad_cylinder_result* derivative)
{
    return cyl_run_dual(input, seed, value, derivative);
}
