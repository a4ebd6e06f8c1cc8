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

/* 0 where `ok`, else 1, as a real: a batch's count of failed checks (dyad_lanes.h), in the
 * scalar of the values it is taken from, so that the count stays in the vector's lanes. */
#define DYAD_FAILED(ok) ((ok) ? (dyad_real)0 : (dyad_real)1)

/* A type's steps (its position, its two sides of the closure, its rates): inlined into
 * dyad_kin_run, where they are called through pointers, and into a batch's loop
 * (dyad_lanes.h), which a call would keep from vectorising. */
#define DYAD_KIN_STEP DYAD_CLOSED_FORM

/* dyad_kin_input_default's values: guides and turns along x, lengths 1, branch +1, the
 * default threshold, everything else 0. */
#define DYAD_KIN_INPUT_DEFAULTS \
    {.k = {.guide = {1, 0}},    \
     .p = {.guide = {1, 0}},    \
     .length_m = 1,             \
     .length_n = 1,             \
     .turn_m = {1, 0},          \
     .turn_n = {1, 0},          \
     .branch = 1,               \
     .singular_threshold = DYAD_DEFAULT_SINGULAR_THRESHOLD}

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

/* x - x: 0 for a finite x, NaN otherwise; a sum of them is 0 where all are finite. */
static inline dyad_real dyad_kin_residue(dyad_vec2 v)
{
    return (v.x - v.x) + (v.y - v.y);
}

static inline dyad_real dyad_kin_point_residue(const dyad_point_motion* p)
{
    return dyad_kin_residue(p->position) + dyad_kin_residue(p->velocity) +
           dyad_kin_residue(p->acceleration);
}

/* What a mount must be: its point finite; where it slides, its guide a unit and its
 * rates finite. */
static inline int dyad_kin_mount_good(const dyad_mount* g, int slides)
{
    if (!slides) {
        return dyad_kin_point_residue(&g->point) == 0;
    }
    return (dyad_kin_point_residue(&g->point) + dyad_kin_residue(g->guide) + (g->omega - g->omega) +
                (g->epsilon - g->epsilon) ==
            0) &
           dyad_is_unit(g->guide);
}

/* 1 where dyad_kin_first_bad_field finds no bad field: every check at once, without a
 * branch per field (the common case; inlined where the type is a constant, the checks
 * of the fields it does not read go). */
static inline int dyad_kin_fields_good(dyad_type type, const dyad_kin_input* in)
{
    const int slides_dm = dyad_kin_slides(type, DYAD_PAIR_DM);
    const int slides_e = dyad_kin_slides(type, DYAD_PAIR_E);
    const int slides_dn = dyad_kin_slides(type, DYAD_PAIR_DN);
    const int two_ways = type == DYAD_RRR || type == DYAD_RRT || type == DYAD_RTR;
    const dyad_real m = in->length_m, n = in->length_n, threshold = in->singular_threshold;
    const dyad_real mounted = in->mount_amplification;
    int good = dyad_kin_mount_good(&in->k, slides_dm) & dyad_kin_mount_good(&in->p, slides_dn);
    good &= dyad_kin_residue(in->com_m) + dyad_kin_residue(in->com_n) + (n - n) +
                (threshold - threshold) + (mounted - mounted) ==
            0;
    if (!slides_e) {
        good &= (m - m == 0) & (type == DYAD_RRR ? m > 0 : m >= 0);
    }
    good &= type == DYAD_RRR || type == DYAD_RRT ? n > 0 : n >= 0;
    if (slides_dm) {
        good &= dyad_is_unit(in->turn_m);
    }
    if (slides_e || slides_dn) {
        good &= dyad_is_unit(in->turn_n);
    }
    if (two_ways) {
        good &= (in->branch == 1) | (in->branch == -1);
    }
    return good & (threshold > 0) & (threshold < 1) & (mounted >= 0);
}

/* Every motion output, conditioning and amplification of `result` NaN, gap 0,
 * failure CLOSES; status and field as given. */
void dyad_kin_fill_nan(dyad_kin_result* result, dyad_status status, dyad_kin_field field);

/* Rejects the call in value and, if not NULL, derivative; returns status. */
dyad_status dyad_kin_reject(dyad_kin_result* value, dyad_kin_result* derivative, dyad_status status,
                            dyad_kin_field field);

/* The reals of a result's motion, from m to slide_p: the structs between hold nothing
 * else (no padding between reals), so they are one array. */
#define DYAD_KIN_MOTION_REALS 50
typedef char dyad_kin_motion_reals_are_contiguous[offsetof(dyad_kin_result, slide_p) +
                                                              sizeof(dyad_slide) -
                                                              offsetof(dyad_kin_result, m) ==
                                                          DYAD_KIN_MOTION_REALS * sizeof(dyad_real)
                                                      ? 1
                                                      : -1];

/* 0 where every motion output of a result is finite (dyad_residue_of). */
static inline dyad_real dyad_kin_motion_residue(const dyad_kin_result* r)
{
    return dyad_residue_of(
        (const dyad_real*)(const void*)((const char*)r + offsetof(dyad_kin_result, m)),
        DYAD_KIN_MOTION_REALS);
}

/* 1 if every motion output of result is finite. */
int dyad_kin_outputs_finite(const dyad_kin_result* result);

#endif /* DYADFMU_KIN_INTERNAL_H */
