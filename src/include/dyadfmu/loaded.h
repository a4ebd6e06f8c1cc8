/* dyadfmu: the closed forms on a dyad whose loads are already reduced.
 *
 * dyad_solve_<type> validates a dyad_input, reduces each link's active load,
 * weight and inertia to a resultant, and then applies the type's closed forms.
 * The functions here are that last step alone. They serve a caller that forms
 * the resultants itself: a mechanism of several dyads, where the reactions of
 * a later dyad load the links of an earlier one, or generated code that knows
 * at compile time which terms of the resultant exist (no inertia in a static
 * scene, no weight without gravity) and so never computes the others.
 *
 * They do no input validation: the caller guarantees finite values, unit
 * directions with j = k0 x i, and lengths in the type's domain
 * (dyad_length_may_be_zero). The status is DYAD_STATUS_OK, DYAD_STATUS_SINGULAR
 * (conditioning below the threshold) or DYAD_STATUS_OUT_OF_RANGE (a reaction is
 * not finite); outputs are NaN unless ok, as with dyad_solve.
 */
#ifndef DYADFMU_LOADED_H
#define DYADFMU_LOADED_H

#include "dyadfmu/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One link of a dyad with the resultant of everything acting on it except the
 *  reactions of its own three pairs. */
typedef struct dyad_loaded_link {
    dyad_vec2 i;   /**< i_g: unit vector from D_g towards E, global frame (-) */
    dyad_vec2 j;   /**< j_g = k0 x i_g (-) */
    dyad_real l;   /**< l_g = |D_g E| (m) */
    dyad_vec2 f;   /**< resultant force F_g, global frame (N) */
    dyad_real m;   /**< resultant moment about the centre of mass S_g (N m) */
    dyad_real m_d; /**< moment of all those loads about D_g (N m) */
    /** Size of f (N): the sum of |x| + |y| over every term summed into f (a
     *  term's own error bound where it carries one, see dyad_force_size). The
     *  caller's round-off of f must be a few eps times it; it is at least
     *  |f.x| + |f.y|. It makes result.amplification cover the cancellation of
     *  the load terms; |f.x| + |f.y| claims that f has no round-off. */
    dyad_real f_size;
    /** Size of m_d (N m), likewise: the sum of the magnitudes of its terms,
     *  |r x v| counted as (|r.x| + |r.y|)(|v.x| + |v.y|). */
    dyad_real m_d_size;
} dyad_loaded_link;

/** A dyad ready for its closed forms. */
typedef struct dyad_loaded {
    dyad_loaded_link m;           /**< link m, paired with k at D_m */
    dyad_loaded_link n;           /**< link n, paired with p at D_n */
    dyad_vec2 i_k, j_k;           /**< guide at D_m and its normal (-), where D_m slides */
    dyad_vec2 i_p, j_p;           /**< guide at D_n and its normal (-), where D_n slides */
    dyad_real singular_threshold; /**< as dyad_input.singular_threshold (-) */
} dyad_loaded;

dyad_status dyad_react_rrr(const dyad_loaded* dyad, dyad_result* result);
dyad_status dyad_react_rrt(const dyad_loaded* dyad, dyad_result* result);
dyad_status dyad_react_rtr(const dyad_loaded* dyad, dyad_result* result);
dyad_status dyad_react_trt(const dyad_loaded* dyad, dyad_result* result);
dyad_status dyad_react_rtt(const dyad_loaded* dyad, dyad_result* result);

/** The reactions and their directional derivative along `seed`, exactly (no
 *  finite differences): `seed` has the layout of `dyad` and holds the rate of
 *  each field (a unit vector's rate is its derivative, of which only the part
 *  normal to it counts; the threshold is not differentiated); `derivative`
 *  receives the rate of every output of `value`, the conditioning and the
 *  amplification included. The derivative solves the same closed forms under
 *  the change of the equilibrium sums with the reactions held (see
 *  dyad_tangent.c). Status as dyad_react_<type>; outputs NaN unless ok. */
dyad_status dyad_react_tangent_rrr(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative);
dyad_status dyad_react_tangent_rrt(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative);
dyad_status dyad_react_tangent_rtr(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative);
dyad_status dyad_react_tangent_trt(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative);
dyad_status dyad_react_tangent_rtt(const dyad_loaded* dyad, const dyad_loaded* seed,
                                   dyad_result* value, dyad_result* derivative);

/** The size of a solved dyad's reaction forces as a term of another link's
 *  load (N): amplification x the largest |x| + |y| of R_mk, R_np, R_mn. It
 *  bounds each of them, and a few eps times it bounds their error; a chain
 *  adds it to the f_size of the link a reaction loads. NaN unless the status
 *  is ok. */
dyad_real dyad_force_size(const dyad_result* result);

/** The same for the reactive moments (N m): amplification x the largest
 *  |m_mk|, |m_np|, |m_mn|. */
dyad_real dyad_moment_size(const dyad_result* result);

/** The rates of dyad_force_size and dyad_moment_size (N and N m per unit of
 *  the seed) from a result and its derivative (dyad_react_tangent_<type>). */
dyad_real dyad_force_size_rate(const dyad_result* value, const dyad_result* derivative);
dyad_real dyad_moment_size_rate(const dyad_result* value, const dyad_result* derivative);

#ifdef __cplusplus
}
#endif

#endif /* DYADFMU_LOADED_H */
