/* dyadfmu: what the per-type solvers share. Not part of the public API. */
#ifndef DYADFMU_INTERNAL_H
#define DYADFMU_INTERNAL_H

#include "dyadfmu/dyad.h"
#include "dyadfmu/vec2.h"

/* A link ready for the formulas: its frame, length, centre of mass, and the
 * resultant F_g, M_g of active load, weight and inertia at the centre of mass. */
typedef struct dyad_body {
    dyad_vec2 i;   /* i_g, normalised (-) */
    dyad_vec2 j;   /* j_g = k0 x i_g (-) */
    dyad_real l;   /* l_g (m) */
    dyad_vec2 com; /* (x_S, y_S) in the link frame (m) */
    dyad_vec2 f;   /* F_g, global frame (N) */
    dyad_real m;   /* M_g (N m) */
} dyad_body;

typedef struct dyad_prepared {
    dyad_body m;
    dyad_body n;
    dyad_vec2 i_k, j_k; /* guide at D_m, where D_m is translational */
    dyad_vec2 i_p, j_p; /* guide at D_n, where D_n is translational */
} dyad_prepared;

/* Validates the input for the type and fills prepared. On success the result's
 * outputs are zeroed (so the moments and normal forces of revolute pairs read 0)
 * and DYAD_STATUS_OK is returned; otherwise the result (if not NULL) reports the
 * invalid field with NaN outputs and DYAD_STATUS_INVALID_INPUT is returned. */
dyad_status dyad_prepare(dyad_type type, const dyad_input* input, dyad_prepared* prepared,
                         dyad_result* result);

/* Records the conditioning figure. Returns DYAD_STATUS_OK if it is at or above
 * the threshold; otherwise marks the result singular with NaN outputs and
 * returns DYAD_STATUS_SINGULAR. */
dyad_status dyad_accept_conditioning(dyad_real denominator, dyad_real conditioning,
                                     dyad_real threshold, dyad_result* result);

/* Marks the result with a failure status and field, outputs NaN; returns status. */
dyad_status dyad_reject(dyad_result* result, dyad_status status, dyad_field field);

/* Final check once a solver has written its outputs: any non-finite output
 * turns the result into DYAD_STATUS_OUT_OF_RANGE with NaN outputs. */
dyad_status dyad_finish(dyad_result* result);

/* Moment about D_g of the link's resultant load: (S_g - D_g) x F_g + M_g. */
static inline dyad_real dyad_load_moment_about_d(const dyad_body* b)
{
    return b->com.x * dyad_dot(b->f, b->j) - b->com.y * dyad_dot(b->f, b->i) + b->m;
}

/* Moment about E of the link's resultant load: (S_g - E) x F_g + M_g,
 * with S_g - E = (x_S - l_g) i_g + y_S j_g. */
static inline dyad_real dyad_load_moment_about_e(const dyad_body* b)
{
    return (b->com.x - b->l) * dyad_dot(b->f, b->j) - b->com.y * dyad_dot(b->f, b->i) + b->m;
}

static inline dyad_real dyad_abs(dyad_real a)
{
    return a < 0 ? -a : a;
}

#endif /* DYADFMU_INTERNAL_H */
