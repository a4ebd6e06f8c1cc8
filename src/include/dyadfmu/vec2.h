/* dyadfmu: inline 2-D vector algebra on dyad_vec2. */
#ifndef DYADFMU_VEC2_H
#define DYADFMU_VEC2_H

#include <math.h>

#include "dyadfmu/types.h"

static inline dyad_vec2 dyad_vec2_make(dyad_real x, dyad_real y)
{
    dyad_vec2 v;
    v.x = x;
    v.y = y;
    return v;
}

static inline dyad_vec2 dyad_add(dyad_vec2 a, dyad_vec2 b)
{
    return dyad_vec2_make(a.x + b.x, a.y + b.y);
}

static inline dyad_vec2 dyad_sub(dyad_vec2 a, dyad_vec2 b)
{
    return dyad_vec2_make(a.x - b.x, a.y - b.y);
}

static inline dyad_vec2 dyad_neg(dyad_vec2 a)
{
    return dyad_vec2_make(-a.x, -a.y);
}

static inline dyad_vec2 dyad_scale(dyad_real s, dyad_vec2 a)
{
    return dyad_vec2_make(s * a.x, s * a.y);
}

/** s * a + t * b */
static inline dyad_vec2 dyad_combine(dyad_real s, dyad_vec2 a, dyad_real t, dyad_vec2 b)
{
    return dyad_vec2_make(s * a.x + t * b.x, s * a.y + t * b.y);
}

static inline dyad_real dyad_dot(dyad_vec2 a, dyad_vec2 b)
{
    return a.x * b.x + a.y * b.y;
}

/** z component of a x b. */
static inline dyad_real dyad_cross(dyad_vec2 a, dyad_vec2 b)
{
    return a.x * b.y - a.y * b.x;
}

/** |a.x| + |a.y|: how the sizes behind the amplification measure a vector
 *  term (dyadfmu/loaded.h). */
static inline dyad_real dyad_norm1(dyad_vec2 a)
{
#ifdef DYAD_REAL_FLOAT
    return fabsf(a.x) + fabsf(a.y);
#else
    return fabs(a.x) + fabs(a.y);
#endif
}

/** k0 x a: a turned by +90 degrees. */
static inline dyad_vec2 dyad_perp(dyad_vec2 a)
{
    return dyad_vec2_make(-a.y, a.x);
}

/** The direction a turned by the unit vector t = (cos d, sin d): a turned by d,
 *  the complex product a t. */
static inline dyad_vec2 dyad_turn(dyad_vec2 a, dyad_vec2 t)
{
    return dyad_vec2_make(a.x * t.x - a.y * t.y, a.x * t.y + a.y * t.x);
}

static inline dyad_real dyad_length(dyad_vec2 a)
{
#ifdef DYAD_REAL_FLOAT
    return sqrtf(dyad_dot(a, a));
#else
    return sqrt(dyad_dot(a, a));
#endif
}

/** Unit vector at angle a (rad) from the x axis. */
static inline dyad_vec2 dyad_dir_from_angle(dyad_real angle)
{
#ifdef DYAD_REAL_FLOAT
    return dyad_vec2_make(cosf(angle), sinf(angle));
#else
    return dyad_vec2_make(cos(angle), sin(angle));
#endif
}

/** fabs in the scalar's precision. */
static inline dyad_real dyad_fabs(dyad_real a)
{
#ifdef DYAD_REAL_FLOAT
    return fabsf(a);
#else
    return fabs(a);
#endif
}

/** The angle of the vector (x, y) from the x axis (rad), in the scalar's precision. */
static inline dyad_real dyad_atan2(dyad_real y, dyad_real x)
{
#ifdef DYAD_REAL_FLOAT
    return atan2f(y, x);
#else
    return atan2(y, x);
#endif
}

static inline int dyad_is_valid_real(dyad_real a)
{
    return isfinite(a) != 0;
}

static inline int dyad_is_valid_vec2(dyad_vec2 a)
{
    return dyad_is_valid_real(a.x) && dyad_is_valid_real(a.y);
}

#endif /* DYADFMU_VEC2_H */
