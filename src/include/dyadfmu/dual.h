/* dyadfmu: dual numbers, a value and its derivative along a seed, for
 * forward-mode differentiation: the tangents of the kinematics and of the
 * reactions, and the directional derivatives of generated scene code, are the
 * same formulas evaluated on these. Every operation is the plain one on the
 * value plus its first-order rule on the rate; none allocates or branches
 * except where the plain operation does (|x| at 0 takes the rate 0).
 *
 * dyad_dual is a scalar with its rate; dyad_dual_vec2 a 2-D vector with its
 * rate. A rate has the unit of its value per unit of the seed's parameter. */
#ifndef DYADFMU_DUAL_H
#define DYADFMU_DUAL_H

#include "dyadfmu/types.h"
#include "dyadfmu/vec2.h"

#include <math.h>

#ifdef DYAD_REAL_FLOAT
#define DYAD_SQRT  sqrtf
#define DYAD_ATAN2 atan2f
#else
#define DYAD_SQRT  sqrt
#define DYAD_ATAN2 atan2
#endif

/* |x| as one instruction (x < 0 ? -x : x is a compare and a branch, since it
 * must keep the sign of -0 and NaN). */
#ifdef DYAD_REAL_FLOAT
#define DYAD_FABS fabsf
#else
#define DYAD_FABS fabs
#endif

/* A value and its rate along a seed. */
typedef struct dyad_dual {
    dyad_real v;
    dyad_real d;
} dyad_dual;

static inline dyad_dual dyad_dual_make(dyad_real v, dyad_real d)
{
    dyad_dual r;
    r.v = v;
    r.d = d;
    return r;
}

static inline dyad_dual dyad_dual_const(dyad_real v)
{
    return dyad_dual_make(v, 0);
}

static inline dyad_dual dyad_dual_add(dyad_dual a, dyad_dual b)
{
    return dyad_dual_make(a.v + b.v, a.d + b.d);
}

static inline dyad_dual dyad_dual_mul(dyad_dual a, dyad_dual b)
{
    return dyad_dual_make(a.v * b.v, a.d * b.v + a.v * b.d);
}

static inline dyad_dual dyad_dual_div(dyad_dual a, dyad_dual b)
{
    const dyad_real q = a.v / b.v;
    return dyad_dual_make(q, (a.d - q * b.d) / b.v);
}

/* |a| and its rate: the one-sided rate is taken as 0 at a = 0. */
static inline dyad_dual dyad_dual_abs(dyad_real a, dyad_real da)
{
    return dyad_dual_make(DYAD_FABS(a), a > 0 ? da : a < 0 ? -da : 0);
}

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

/* An input with its seed. */
static inline dyad_dual_vec2 dyad_kdv_in(dyad_vec2 v, dyad_vec2 s)
{
    dyad_dual_vec2 r;
    r.v = v;
    r.d = s;
    return r;
}

static inline void dyad_kd_put(dyad_dual a, dyad_real* to, dyad_real* rate)
{
    *to = a.v;
    *rate = a.d;
}

static inline void dyad_kdv_put(dyad_dual_vec2 a, dyad_vec2* to, dyad_vec2* rate)
{
    *to = a.v;
    *rate = a.d;
}

/* The complex product a (x) b (dyad_turn) and its rate. */
static inline dyad_dual_vec2 dyad_kdv_cmul(dyad_dual_vec2 a, dyad_dual_vec2 b)
{
    dyad_dual_vec2 r;
    r.v = dyad_turn(a.v, b.v);
    r.d = dyad_add(dyad_turn(a.d, b.v), dyad_turn(a.v, b.d));
    return r;
}

/* s a + t b and its rate. */
static inline dyad_dual_vec2 dyad_kdv_combine(dyad_dual s, dyad_dual_vec2 a, dyad_dual t,
                                              dyad_dual_vec2 b)
{
    return dyad_kdv_add(dyad_kdv_scale(s, a), dyad_kdv_scale(t, b));
}

/* |v.x| + |v.y| and its rate. */
static inline dyad_dual dyad_kdv_norm1(dyad_dual_vec2 v)
{
    return dyad_dual_add(dyad_dual_abs(v.v.x, v.d.x), dyad_dual_abs(v.v.y, v.d.y));
}

/* atan2(y, x) and its rate (y' x - x' y) / (x^2 + y^2); NaN rate at the origin. */
static inline dyad_dual dyad_kd_atan2(dyad_dual y, dyad_dual x)
{
    return dyad_dual_make(DYAD_ATAN2(y.v, x.v), (y.d * x.v - x.d * y.v) / (x.v * x.v + y.v * y.v));
}

#endif /* DYADFMU_DUAL_H */
