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

#include "dyadfmu/kinematics.h"
#include "dyadfmu/vec2.h"
#include "dyad_internal.h"

#include <math.h>
#include <stddef.h>

#ifdef DYAD_REAL_FLOAT
#define DYAD_SQRT sqrtf
#else
#define DYAD_SQRT sqrt
#endif

/* ---- plain arithmetic the vec2.h set lacks ----------------------------------------------------
 */

/* The complex product a (x) b: b turned by the angle of a and scaled by |a|. */
static inline dyad_vec2 dyad_cmul(dyad_vec2 a, dyad_vec2 b)
{
    return dyad_vec2_make(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

/* ---- dual arithmetic: a value and its derivative along the seed ------------------------------ */

/* A 2-D vector and its derivative. */
typedef struct dyad_dual_vec2 {
    dyad_vec2 v;
    dyad_vec2 d;
} dyad_dual_vec2;

static inline dyad_dual dyad_kd_sub(dyad_dual a, dyad_dual b)
{
    return dyad_dual_make(a.v - b.v, a.d - b.d);
}

static inline dyad_dual dyad_kd_neg(dyad_dual a)
{
    return dyad_dual_make(-a.v, -a.d);
}

/* The rate is infinite or NaN where the value is 0: there the root has none. */
static inline dyad_dual dyad_kd_sqrt(dyad_dual a)
{
    const dyad_real r = DYAD_SQRT(a.v);
    return dyad_dual_make(r, a.d / (2 * r));
}

static inline dyad_dual dyad_kd_abs(dyad_dual a)
{
    return dyad_dual_abs(a.v, a.d);
}

static inline dyad_dual_vec2 dyad_kdv_make(dyad_dual x, dyad_dual y)
{
    dyad_dual_vec2 r;
    r.v = dyad_vec2_make(x.v, y.v);
    r.d = dyad_vec2_make(x.d, y.d);
    return r;
}

static inline dyad_dual_vec2 dyad_kdv_const(dyad_vec2 v)
{
    dyad_dual_vec2 r;
    r.v = v;
    r.d = dyad_vec2_make(0, 0);
    return r;
}

static inline dyad_dual dyad_kdv_x(dyad_dual_vec2 a)
{
    return dyad_dual_make(a.v.x, a.d.x);
}

static inline dyad_dual dyad_kdv_y(dyad_dual_vec2 a)
{
    return dyad_dual_make(a.v.y, a.d.y);
}

static inline dyad_dual_vec2 dyad_kdv_add(dyad_dual_vec2 a, dyad_dual_vec2 b)
{
    dyad_dual_vec2 r;
    r.v = dyad_add(a.v, b.v);
    r.d = dyad_add(a.d, b.d);
    return r;
}

static inline dyad_dual_vec2 dyad_kdv_sub(dyad_dual_vec2 a, dyad_dual_vec2 b)
{
    dyad_dual_vec2 r;
    r.v = dyad_sub(a.v, b.v);
    r.d = dyad_sub(a.d, b.d);
    return r;
}

static inline dyad_dual_vec2 dyad_kdv_neg(dyad_dual_vec2 a)
{
    dyad_dual_vec2 r;
    r.v = dyad_neg(a.v);
    r.d = dyad_neg(a.d);
    return r;
}

static inline dyad_dual_vec2 dyad_kdv_scale(dyad_dual s, dyad_dual_vec2 a)
{
    dyad_dual_vec2 r;
    r.v = dyad_scale(s.v, a.v);
    r.d = dyad_combine(s.d, a.v, s.v, a.d);
    return r;
}

static inline dyad_dual_vec2 dyad_kdv_perp(dyad_dual_vec2 a)
{
    dyad_dual_vec2 r;
    r.v = dyad_perp(a.v);
    r.d = dyad_perp(a.d);
    return r;
}

static inline dyad_dual dyad_kdv_dot(dyad_dual_vec2 a, dyad_dual_vec2 b)
{
    return dyad_dual_make(dyad_dot(a.v, b.v), dyad_dot(a.d, b.v) + dyad_dot(a.v, b.d));
}

static inline dyad_dual dyad_kdv_cross(dyad_dual_vec2 a, dyad_dual_vec2 b)
{
    return dyad_dual_make(dyad_cross(a.v, b.v), dyad_cross(a.d, b.v) + dyad_cross(a.v, b.d));
}

static inline dyad_dual_vec2 dyad_kdv_cmul(dyad_dual_vec2 a, dyad_dual_vec2 b)
{
    dyad_dual_vec2 r;
    r.v = dyad_cmul(a.v, b.v);
    r.d = dyad_add(dyad_cmul(a.d, b.v), dyad_cmul(a.v, b.d));
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

/* The tangent of each type, from the type's file (the dual pass). */
dyad_status dyad_kin_tangent_rrr(const dyad_kin_input* input, const dyad_kin_input* seed,
                                 dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kin_tangent_rrt(const dyad_kin_input* input, const dyad_kin_input* seed,
                                 dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kin_tangent_rtr(const dyad_kin_input* input, const dyad_kin_input* seed,
                                 dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kin_tangent_trt(const dyad_kin_input* input, const dyad_kin_input* seed,
                                 dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kin_tangent_rtt(const dyad_kin_input* input, const dyad_kin_input* seed,
                                 dyad_kin_result* value, dyad_kin_result* derivative);

#endif /* DYADFMU_KIN_INTERNAL_H */
