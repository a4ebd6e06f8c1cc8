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

/* 0 where a mount's reals are finite: its point, and where it slides its guide and rates. */
static inline dyad_real dyad_kin_mount_residue(const dyad_mount* g, int slides)
{
    const dyad_real point = dyad_kin_point_residue(&g->point);
    return slides ? point + dyad_kin_residue(g->guide) + (g->omega - g->omega) +
                        (g->epsilon - g->epsilon)
                  : point;
}

/* Each check dyad_kin_first_bad_field makes, all at once, without a branch per field
 * (inlined where the type is a constant, the checks of the fields it does not read go):
 * CHECK(condition) for each. What a mount must be: its reals finite, and where it slides
 * its guide a unit. */
#define DYAD_KIN_FIELD_CHECKS(type, in, CHECK)                                                  \
    do {                                                                                        \
        const int slides_dm = dyad_kin_slides(type, DYAD_PAIR_DM);                              \
        const int slides_e = dyad_kin_slides(type, DYAD_PAIR_E);                                \
        const int slides_dn = dyad_kin_slides(type, DYAD_PAIR_DN);                              \
        const dyad_real m = (in)->length_m, n = (in)->length_n;                                 \
        const dyad_real threshold = (in)->singular_threshold;                                   \
        const dyad_real mounted = (in)->mount_amplification;                                    \
        CHECK(dyad_kin_mount_residue(&(in)->k, slides_dm) +                                     \
                  dyad_kin_mount_residue(&(in)->p, slides_dn) + dyad_kin_residue((in)->com_m) + \
                  dyad_kin_residue((in)->com_n) + (n - n) + (threshold - threshold) +           \
                  (mounted - mounted) ==                                                        \
              0);                                                                               \
        if (slides_dm) {                                                                        \
            CHECK(dyad_is_unit((in)->k.guide));                                                 \
            CHECK(dyad_is_unit((in)->turn_m));                                                  \
        }                                                                                       \
        if (slides_dn) {                                                                        \
            CHECK(dyad_is_unit((in)->p.guide));                                                 \
        }                                                                                       \
        if (!slides_e) {                                                                        \
            CHECK(m - m == 0);                                                                  \
            CHECK((type) == DYAD_RRR ? m > 0 : m >= 0);                                         \
        }                                                                                       \
        CHECK((type) == DYAD_RRR || (type) == DYAD_RRT ? n > 0 : n >= 0);                       \
        if (slides_e || slides_dn) {                                                            \
            CHECK(dyad_is_unit((in)->turn_n));                                                  \
        }                                                                                       \
        if ((type) == DYAD_RRR || (type) == DYAD_RRT || (type) == DYAD_RTR) {                   \
            CHECK(((in)->branch == 1) | ((in)->branch == -1));                                  \
        }                                                                                       \
        CHECK(threshold > 0);                                                                   \
        CHECK(threshold < 1);                                                                   \
        CHECK(mounted >= 0);                                                                    \
    } while (0)

/* 1 where dyad_kin_first_bad_field finds no bad field. */
static inline int dyad_kin_fields_good(dyad_type type, const dyad_kin_input* in)
{
    int good = 1;
#define DYAD_KIN_GOOD_IF(condition) good &= (condition)
    DYAD_KIN_FIELD_CHECKS(type, in, DYAD_KIN_GOOD_IF);
#undef DYAD_KIN_GOOD_IF
    return good;
}

/* The same as the count of the checks that fail, in reals alone: a batch's loop over
 * samples (dyad_kin_lane) vectorises where its masks are all of one width. */
static inline dyad_real dyad_kin_fields_failed(dyad_type type, const dyad_kin_input* in)
{
    dyad_real bad = 0;
#define DYAD_KIN_COUNT_UNLESS(condition) bad += DYAD_FAILED(condition)
    DYAD_KIN_FIELD_CHECKS(type, in, DYAD_KIN_COUNT_UNLESS);
#undef DYAD_KIN_COUNT_UNLESS
    return bad;
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
