/* dyadfmu: what the kinematics of the dyad types share, defined once. Not part
 * of the public API.
 *
 * The formulas themselves are written once over a scalar of choice
 * (dyad_kin_generic.h) and compiled twice: over dyad_real for
 * dyad_kinematics(), and over the dual number dyad_dual (a value and its
 * derivative along a seed: forward-mode differentiation) for
 * dyad_kinematics_tangent(). This header holds what is not generic: the dual
 * vector and the dual arithmetic the second pass needs, the validation of
 * the inputs and the rejection of a call.
 */
#ifndef DYADFMU_KIN_INTERNAL_H
#define DYADFMU_KIN_INTERNAL_H

#include "dyadfmu/dual.h"
#include "dyadfmu/kinematics.h"
#include "dyadfmu/vec2.h"
#include "dyad_internal.h"

#include <math.h>
#include <stddef.h>

/* ---- plain arithmetic the vec2.h set lacks ----------------------------------------------------
 */

/* The complex product a (x) b: b turned by the angle of a and scaled by |a|. */
static inline dyad_vec2 dyad_cmul(dyad_vec2 a, dyad_vec2 b)
{
    return dyad_vec2_make(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

/* An input unit vector with its seed: only the seed's part normal to it counts
 * (the angle rate u x s, as in dyad_tangent.c). */
static inline dyad_dual_vec2 dyad_kdv_in_unit(dyad_vec2 v, dyad_vec2 s)
{
    dyad_dual_vec2 r;
    r.v = dyad_unit_of(v);
    r.d = dyad_scale(dyad_cross(r.v, s), dyad_perp(r.v));
    return r;
}

/* ---- validation and rejection (dyad_kinematics.c) ---------------------------------------------
 */

/* The pairs that slide, by type: D_m (guide k), E (along m), D_n (guide p). */
static inline int dyad_kin_slides(dyad_type type, dyad_pair pair)
{
    return dyad_pair_table[type][pair] == DYAD_PAIR_TRANSLATIONAL;
}

/* The first input field out of its domain, in the order of dyad_kin_field,
 * among the fields the type reads; DYAD_KIN_FIELD_NONE if all are good. */
dyad_kin_field dyad_kin_first_bad_field(dyad_type type, const dyad_kin_input* input);

/* Every motion output, conditioning and amplification of `result` NaN, gap 0,
 * failure CLOSES; status and field as given. */
void dyad_kin_fill_nan(dyad_kin_result* result, dyad_status status, dyad_kin_field field);

/* Rejects the call in value and, if not NULL, derivative; returns status. */
dyad_status dyad_kin_reject(dyad_kin_result* value, dyad_kin_result* derivative, dyad_status status,
                            dyad_kin_field field);

/* 1 if every motion output of result is finite. */
int dyad_kin_outputs_finite(const dyad_kin_result* result);

#endif /* DYADFMU_KIN_INTERNAL_H */
