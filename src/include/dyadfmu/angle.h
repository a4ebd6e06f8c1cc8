/* dyadfmu: the unit vector (cos, sin) of an angle, for a caller that holds link
 * angles (the FMUs do) and converts one on every step.
 *
 * Why not libm: cos and sin of one angle cost about 120 instructions in glibc,
 * as much as a third of a dyad's solve. Here the angle is reduced to
 * r in [-pi/4, pi/4] by a multiple k of pi/2 split in three parts (Cody and
 * Waite): k p1 and k p2 are exact for |k| < 2^20 (p1 and p2 have 33 bits), the
 * third part's error is below 1e-36 rad. Each of sin r and cos r is then its
 * Taylor series to the first term below 1e-18 (r^17 and r^16), summed so that
 * the leading term (r, 1 - r^2/2) is added last; the quadrant of k places
 * them. The result is within about one unit in the last place of 1 of the true
 * cos and sin (2.2e-16; the tests bound it against mpmath), where glibc's is
 * within half a unit: a direction error far below what any reaction can
 * resolve. Beyond |angle| = 1e6 rad, and for a non-finite angle, libm does it.
 */
#ifndef DYADFMU_ANGLE_H
#define DYADFMU_ANGLE_H

#include <math.h>

/** Largest |angle| (rad) reduced here; libm reduces a larger one. */
#define DYAD_ANGLE_FAST_LIMIT 1e6

/** cos(angle) and sin(angle) (-) of `angle` (rad), to about 2.2e-16. */
static inline void dyad_cos_sin(double angle, double* cos_out, double* sin_out)
{
    /* pi/2 = P1 + P2 + P3 (P1, P2 of 33 significant bits) */
    const double two_over_pi = 0.6366197723675814;
    const double p1 = 1.5707963267341256;
    const double p2 = 6.077100506303966e-11;
    const double p3 = 2.0222662487959506e-21;
    double k, r, z, s, c, w;
    long quadrant;
    if (!(fabs(angle) <= DYAD_ANGLE_FAST_LIMIT)) {
        *cos_out = cos(angle);
        *sin_out = sin(angle);
        return;
    }
    quadrant = (long)(angle * two_over_pi + copysign(0.5, angle));
    k = (double)quadrant;
    r = ((angle - k * p1) - k * p2) - k * p3;
    z = r * r;
    s = z * (2.8114572543455206e-15 * z - 7.647163731819816e-13) + 1.6059043836821613e-10;
    s = z * (z * s - 2.505210838544172e-08) + 2.7557319223985893e-06;
    s = z * (z * s - 0.0001984126984126984) + 0.008333333333333333;
    s = r + r * z * (z * s - 0.16666666666666666);
    c = z * (4.779477332387385e-14 * z - 1.1470745597729725e-11) + 2.08767569878681e-09;
    c = z * (z * c - 2.755731922398589e-07) + 2.48015873015873e-05;
    c = z * (z * c - 0.001388888888888889) + 0.041666666666666664;
    /* 1 - z/2 rounded, its rounding error added back with the rest */
    w = 1.0 - 0.5 * z;
    c = w + (((1.0 - w) - 0.5 * z) + z * z * c);
    switch ((unsigned long)quadrant & 3u) {
    case 0:
        *cos_out = c;
        *sin_out = s;
        break;
    case 1:
        *cos_out = -s;
        *sin_out = c;
        break;
    case 2:
        *cos_out = -c;
        *sin_out = -s;
        break;
    default:
        *cos_out = s;
        *sin_out = -c;
        break;
    }
}

#endif
