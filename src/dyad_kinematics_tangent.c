/* dyadfmu: dyad_point_on_link on dual numbers (dyadfmu/kinematics.h), what the
 * directional derivative of a mechanism's generated code calls. Apart from
 * dyad_kinematics.c so that a program that only evaluates links none of it. */
#include "dyad_kin_internal.h"
#define DYAD_KIN_DUAL
#include "dyad_kin_generic.h"

dyad_dual_point_motion dyad_point_on_link_dual(dyad_dual_point_motion origin, dyad_dual_vec2 dir,
                                               dyad_dual omega, dyad_dual epsilon,
                                               dyad_dual_vec2 at)
{
    dyad_kin_motion_dual o, p;
    dyad_dual_point_motion r;
    o.pos = dyad_kdv_in(origin.v.position, origin.d.position);
    o.vel = dyad_kdv_in(origin.v.velocity, origin.d.velocity);
    o.acc = dyad_kdv_in(origin.v.acceleration, origin.d.acceleration);
    p = dyad_kin_on_link_dual(&o, dir, omega, epsilon, at);
    r.v.position = p.pos.v;
    r.d.position = p.pos.d;
    r.v.velocity = p.vel.v;
    r.d.velocity = p.vel.d;
    r.v.acceleration = p.acc.v;
    r.d.acceleration = p.acc.d;
    return r;
}
