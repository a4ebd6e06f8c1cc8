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
    dyad_real m_d; /* moment of F_g and M_g about D_g (N m), see link_resultant */
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
    return b->m_d;
}

/* Moment about E of the link's resultant load: (S_g - E) x F_g + M_g
 * = [(S_g - D_g) x F_g + M_g] - l_g i_g x F_g, since E - D_g = l_g i_g. */
static inline dyad_real dyad_load_moment_about_e(const dyad_body* b)
{
    return b->m_d - b->l * dyad_dot(b->f, b->j);
}

static inline dyad_real dyad_abs(dyad_real a)
{
    return a < 0 ? -a : a;
}

static inline dyad_real dyad_norm1(dyad_vec2 a)
{
    return dyad_abs(a.x) + dyad_abs(a.y);
}

/* Size of the terms summed in dyad_load_moment_about_d / _about_e: the round-off
 * of those sums is a few eps times this. */
static inline dyad_real dyad_load_moment_size(const dyad_body* b, dyad_real lever_x)
{
    return (dyad_abs(lever_x) + dyad_abs(b->com.y)) * dyad_norm1(b->f) + dyad_abs(b->m);
}

/* Where two sums are equal in exact arithmetic (a force or moment closing one
 * link's balance or the other's), the one built from smaller terms loses
 * fewer digits to cancellation: a stiff dyad, one link's inertia dwarfing the
 * other's, then keeps the light link's reactions to full relative accuracy. */
static inline dyad_vec2 dyad_smaller_sum(dyad_vec2 a, dyad_real a_terms, dyad_vec2 b,
                                         dyad_real b_terms)
{
    return a_terms <= b_terms ? a : b;
}

#endif /* DYADFMU_INTERNAL_H */
