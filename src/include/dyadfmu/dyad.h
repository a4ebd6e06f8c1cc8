/* dyadfmu: public API of the kinetostatic solvers.
 *
 * Every solver takes the kinematics, mass properties and loads of the two links
 * of one Assur dyad and returns the reactions in its three pairs. The solvers
 * allocate nothing, keep no state and do no I/O: they are reentrant and may run
 * from any number of threads at once.
 *
 * Each solver returns the status it also stores in result->status. Unless the
 * status is DYAD_STATUS_OK, every reaction output is NaN; conditioning and
 * amplification are filled whenever the inputs were valid.
 */
#ifndef DYADFMU_DYAD_H
#define DYADFMU_DYAD_H

#include "dyadfmu/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A solver of one dyad type (dyad_solve_rrr, ...). */
typedef dyad_status (*dyad_solver)(const dyad_input* input, dyad_result* result);

/** Inputs with every field zero, except: directions i_m, i_n, i_k, i_p = (1, 0),
 *  lengths 1 m, singular threshold DYAD_DEFAULT_SINGULAR_THRESHOLD. */
dyad_input dyad_input_default(void);

/** Solve the dyad of the given type. */
dyad_status dyad_solve(dyad_type type, const dyad_input* input, dyad_result* result);

/** The per-type solvers; dyad_solve dispatches to them. */
dyad_status dyad_solve_rrr(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_rrt(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_rtr(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_trt(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_rtt(const dyad_input* input, dyad_result* result);

/** The first field of `input` that is out of its domain for the type (the one
 *  dyad_solve would refuse with DYAD_STATUS_INVALID_INPUT), DYAD_FIELD_TYPE for
 *  an unknown type, DYAD_FIELD_INPUT for NULL; DYAD_FIELD_NONE if it is valid. */
dyad_field dyad_check_input(dyad_type type, const dyad_input* input);

/** The per-type solvers for an input the caller knows to be valid, as a caller
 *  does that checks each value where it is set (the FMUs check every value
 *  against the bounds of its variable, which are the fields' domains): they
 *  skip the check on the way in. The input must be one for which
 *  dyad_check_input returns DYAD_FIELD_NONE; for any other the results mean
 *  nothing. The status is DYAD_STATUS_OK, DYAD_STATUS_SINGULAR or
 *  DYAD_STATUS_OUT_OF_RANGE, never DYAD_STATUS_INVALID_INPUT; for a valid input
 *  every output equals dyad_solve_<type>'s, bit for bit. */
dyad_status dyad_solve_valid_rrr(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_valid_rrt(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_valid_rtr(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_valid_trt(const dyad_input* input, dyad_result* result);
dyad_status dyad_solve_valid_rtt(const dyad_input* input, dyad_result* result);

/** The reactions and their directional derivative along `seed`, exactly (one
 *  more solve of the closed forms, no finite differences). `seed` has the layout
 *  of the input and holds the rate of each field; a direction's rate is the
 *  derivative of its unit vector, of which only the part normal to it counts
 *  (for an angle rate w: w * (-dir.y, dir.x)). `value` gets the reactions as
 *  dyad_solve gives them; `derivative` their rates in the same fields (N/s if
 *  the seed is per second, and so on), including conditioning and
 *  amplification. Status as dyad_solve's; outputs NaN unless ok. */
dyad_status dyad_solve_tangent(dyad_type type, const dyad_input* input, const dyad_input* seed,
                               dyad_result* value, dyad_result* derivative);

/** What the directional derivative needs of one dyad type (its solver, the
 *  sizes of its outputs, the rate of its conditioning), defined in the type's
 *  own source file (dyad_<type>_tangent.c): passing dyad_tangent_rrt to
 *  dyad_solve_tangent_of links only the RRT solver. */
typedef struct dyad_tangent_type dyad_tangent_type;
extern const dyad_tangent_type dyad_tangent_rrr;
extern const dyad_tangent_type dyad_tangent_rrt;
extern const dyad_tangent_type dyad_tangent_rtr;
extern const dyad_tangent_type dyad_tangent_trt;
extern const dyad_tangent_type dyad_tangent_rtt;

/** dyad_solve_tangent for the type `kind` (&dyad_tangent_rrr, ...). */
dyad_status dyad_solve_tangent_of(const dyad_tangent_type* kind, const dyad_input* input,
                                  const dyad_input* seed, dyad_result* value,
                                  dyad_result* derivative);

/** Resultant of link g's active load, weight and inertia (d'Alembert) at its
 *  centre of mass: force (N, global frame) and moment (N m). This is F_g, M_g
 *  of the paper. Inputs are not validated here. */
void dyad_link_resultant(const dyad_link* link, dyad_vec2 gravity, dyad_vec2* force,
                         dyad_real* moment);

/** cos(angle) and sin(angle) (-) of `angle` (rad) as the FMUs convert a link
 *  angle to its direction (dyadfmu/angle.h): within about 1.1e-16 of the true
 *  values, in double whatever the library's scalar. */
void dyad_angle_cos_sin(double angle, double* cos_out, double* sin_out);

/** Kind of a pair in a type: revolute or translational. */
dyad_pair_kind dyad_pair_kind_of(dyad_type type, dyad_pair pair);

/** 1 if the type allows link's length to be 0 (a slider whose pin lies on its
 *  guide), 0 if it must be positive. */
int dyad_length_may_be_zero(dyad_type type, dyad_link_id link);

/** "RRR", "RRT", ...; "?" for an unknown type. */
const char* dyad_type_name(dyad_type type);

/** "ok", "singular", "invalid input", "out of range", "cannot assemble". */
const char* dyad_status_name(dyad_status status);

/** Dotted field name, e.g. "link_m.length", "guide_k"; "" for NONE. */
const char* dyad_field_name(dyad_field field);

#ifdef __cplusplus
}
#endif

#endif /* DYADFMU_DYAD_H */
