/* dyadfmu: kinematics of planar Assur dyads, closed form.
 *
 * Given the motion of the two external links where they meet the dyad, each
 * function finds how the dyad assembles and moves: the directions, angular
 * velocities and accelerations of links m and n, the lengths that slide with
 * their rates, and the position, velocity and acceleration of its pair points
 * and centres of mass. A mechanism is then analysed from its driver outwards,
 * one dyad at a time, and its reactions from the last dyad back (dyad.h).
 *
 * Conventions are those of types.h: i_g points from D_g towards E, j_g = k0 x
 * i_g, E = D_m + l_m i_m = D_n + l_n i_n, angles counter-clockwise.
 *
 * Where an outer pair slides (D_m of RRT, TRT, RTT; D_n of TRT) its external
 * link carries a guide: a line through the point `point` of that link with the
 * unit direction `guide`. The pair sits at D = point + s guide; s is the slide
 * (an output). The sliding link keeps its direction on the guide: i_m =
 * turn_m (x) i_k, the guide's direction turned by the fixed unit vector
 * turn_m = (cos delta_m, sin delta_m). Where E slides (RTR, RTT) link n keeps
 * its direction on link m: i_n = turn_n (x) i_m, and l_m = |D_m E| is an
 * output. (x) is the complex product: (a (x) b) = (a.x b.x - a.y b.y,
 * a.x b.y + a.y b.x).
 *
 * Round-off. Where a dyad closes in two ways (RRR, RRT, RTR) its position
 * is the root of a quadratic, whose argument is a small difference near a
 * toggle or branch point: the positions lose digits like eps / closure and,
 * since the rates divide by the conditioning (which the root gives), the
 * velocities and accelerations do too. `amplification` bounds all of it and
 * what the mounts' motion brings in: every motion output is within
 * c eps amplification of the largest output of its unit (c about 1; each
 * type's file derives its figures). The status is singular where
 * 1 / amplification falls below singular_threshold: with the default
 * threshold, before the outputs lose half their digits.
 *
 * The functions allocate nothing, keep no state and do no I/O. Each returns
 * the status it also stores in result->status; unless it is
 * DYAD_STATUS_OK every motion output is NaN.
 */
#ifndef DYADFMU_KINEMATICS_H
#define DYADFMU_KINEMATICS_H

#include "dyadfmu/dual.h"
#include "dyadfmu/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Position, velocity and acceleration of a material point, global frame. */
typedef struct dyad_point_motion {
    dyad_vec2 position;     /**< (m) */
    dyad_vec2 velocity;     /**< (m/s) */
    dyad_vec2 acceleration; /**< (m/s^2) */
} dyad_point_motion;

/** The external link k (or p) where it meets the dyad. */
typedef struct dyad_mount {
    /** Where the outer pair is revolute: the pin, the material point of the
     *  external link at D. Where it slides: a material point of the external
     *  link on the guide line, from which the slide is measured. */
    dyad_point_motion point;
    /** Where the outer pair slides: the guide's unit direction, global frame
     *  (-), unit within DYAD_UNIT_TOLERANCE. Read only where the pair slides. */
    dyad_vec2 guide;
    /** Angular velocity (rad/s) and acceleration (rad/s^2) of the external
     *  link, and so of its guide. Read only where the pair slides. */
    dyad_real omega;
    dyad_real epsilon;
} dyad_mount;

/** Everything the kinematics of a dyad needs. Start from dyad_kin_input_default(). */
typedef struct dyad_kin_input {
    dyad_mount k; /**< external link k, at D_m */
    dyad_mount p; /**< external link p, at D_n */
    /** l_m = |D_m E| (m). Read where it is constant: RRR (> 0), RRT and TRT
     *  (>= 0). Where E slides on m (RTR, RTT) it is an output. */
    dyad_real length_m;
    /** l_n = |D_n E| (m): > 0 for RRR and RRT, >= 0 for RTR, TRT and RTT. */
    dyad_real length_n;
    /** turn_m (-): i_m = turn_m (x) i_k, where D_m slides (RRT, TRT, RTT). Unit. */
    dyad_vec2 turn_m;
    /** turn_n (-): i_n = turn_n (x) i_p where D_n slides (TRT), i_n = turn_n (x) i_m
     *  where E slides (RTR, RTT). Unit. */
    dyad_vec2 turn_n;
    /** Centres of mass in the link frames {D_g; i_g, j_g} (m). */
    dyad_vec2 com_m;
    dyad_vec2 com_n;
    /** Assembly branch, +1 or -1, where the dyad closes in two ways (RRR,
     *  RRT, RTR); see each function. TRT and RTT close in one way. */
    int branch;
    /** The result is DYAD_STATUS_SINGULAR where 1 / amplification is below it
     *  (-), in (0, 1). Default DYAD_DEFAULT_SINGULAR_THRESHOLD. */
    dyad_real singular_threshold;
    /** The amplification the mounts' motion carries in (-), >= 0: their
     *  round-off relative to the largest value of its unit, in eps, as the
     *  result's `amplification` of the dyads that move them gives it (the sum
     *  where two do). 0 (the default) for mounts known to the last bit: the
     *  frame, a driver's given motion. */
    dyad_real mount_amplification;
} dyad_kin_input;

/** Input fields, to name the one that made a call invalid. */
typedef enum dyad_kin_field {
    DYAD_KIN_FIELD_NONE = 0,
    DYAD_KIN_FIELD_INPUT, /**< the input or result pointer itself is NULL */
    DYAD_KIN_FIELD_TYPE,  /**< the dyad type is not one of dyad_type */
    DYAD_KIN_FIELD_K_POSITION,
    DYAD_KIN_FIELD_K_VELOCITY,
    DYAD_KIN_FIELD_K_ACCELERATION,
    DYAD_KIN_FIELD_K_GUIDE,
    DYAD_KIN_FIELD_K_OMEGA,
    DYAD_KIN_FIELD_K_EPSILON,
    DYAD_KIN_FIELD_P_POSITION,
    DYAD_KIN_FIELD_P_VELOCITY,
    DYAD_KIN_FIELD_P_ACCELERATION,
    DYAD_KIN_FIELD_P_GUIDE,
    DYAD_KIN_FIELD_P_OMEGA,
    DYAD_KIN_FIELD_P_EPSILON,
    DYAD_KIN_FIELD_LENGTH_M,
    DYAD_KIN_FIELD_LENGTH_N,
    DYAD_KIN_FIELD_TURN_M,
    DYAD_KIN_FIELD_TURN_N,
    DYAD_KIN_FIELD_COM_M,
    DYAD_KIN_FIELD_COM_N,
    DYAD_KIN_FIELD_BRANCH,
    DYAD_KIN_FIELD_SINGULAR_THRESHOLD,
    DYAD_KIN_FIELD_MOUNT_AMPLIFICATION,
    DYAD_KIN_FIELD_COUNT
} dyad_kin_field;

/** Why a dyad cannot close, with DYAD_STATUS_CANNOT_ASSEMBLE. */
typedef enum dyad_kin_failure {
    DYAD_KIN_CLOSES = 0,
    /** RRR: |D_m D_n| > l_m + l_n, the links do not reach. */
    DYAD_KIN_TOO_FAR,
    /** RRR: |D_m D_n| < |l_m - l_n|, one circle lies inside the other. */
    DYAD_KIN_TOO_CLOSE,
    /** RRT: the distance of D_n from the line that E runs on exceeds l_n. */
    DYAD_KIN_OFF_LINE,
    /** RTR: |D_m D_n| < l_n |sin delta_n|, the slider cannot reach the slot's line. */
    DYAD_KIN_OFF_SLOT,
    /** RTR: the branch puts E behind D_m (l_m <= 0). */
    DYAD_KIN_BEHIND_PIVOT,
    DYAD_KIN_FAILURE_COUNT
} dyad_kin_failure;

/** Motion of one link of the dyad. */
typedef struct dyad_kin_link {
    dyad_vec2 dir;          /**< i_g, unit (-) */
    dyad_real omega;        /**< angular velocity (rad/s) */
    dyad_real epsilon;      /**< angular acceleration (rad/s^2) */
    dyad_real length;       /**< l_g = |D_g E| (m), an output where E slides on m */
    dyad_real length_rate;  /**< dl_g/dt (m/s); 0 where constant */
    dyad_real length_accel; /**< d2l_g/dt2 (m/s^2); 0 where constant */
    /** D_g as a material point of link g: for a sliding D_m the slider's point
     *  on the guide, not the guide's. */
    dyad_point_motion d;
    /** Centre of mass S_g = D_g + com.x i_g + com.y j_g. */
    dyad_point_motion com;
} dyad_kin_link;

/** Where a sliding outer pair sits on its guide: D = point + s guide. */
typedef struct dyad_slide {
    dyad_real s;     /**< (m); 0 where the pair is revolute */
    dyad_real rate;  /**< ds/dt (m/s), relative to the guide */
    dyad_real accel; /**< d2s/dt2 (m/s^2), relative to the guide */
} dyad_slide;

/** Kinematics of a dyad. */
typedef struct dyad_kin_result {
    dyad_status status;
    /** The offending field when status is DYAD_STATUS_INVALID_INPUT, else NONE. */
    dyad_kin_field field;
    /** With DYAD_STATUS_CANNOT_ASSEMBLE: which figure failed, else CLOSES. */
    dyad_kin_failure failure;
    /** With DYAD_STATUS_CANNOT_ASSEMBLE: by how much it failed (m), > 0, e.g.
     *  |D_m D_n| - (l_m + l_n) for DYAD_KIN_TOO_FAR (0 only for
     *  DYAD_KIN_BEHIND_PIVOT with l_m = 0 exactly). Else 0. With the tangent,
     *  the derivative's gap is the gap's rate. */
    dyad_real gap;

    dyad_kin_link m; /**< link m */
    dyad_kin_link n; /**< link n */
    /** E as a material point of link n (of both links where E is revolute). */
    dyad_point_motion e;
    dyad_slide slide_k; /**< D_m on guide k (RRT, TRT, RTT) */
    dyad_slide slide_p; /**< D_n on guide p (TRT) */

    /** The velocity equations' normalised determinant (-), the same figure as
     *  the kinetostatic solvers' conditioning: RRR |i_m . j_n|, RRT |i_n . i_k|,
     *  RTR min(|i_beta . i_m|, |D_m D_n| / (l_m + l_n)), TRT |j_k . i_p|, RTT
     *  |j_k . i_m|. Filled whenever the dyad closes. */
    dyad_real conditioning;
    /** The closure's own conditioning (-), in [0, 1]: where the position is a
     *  root, the root's argument (the distance from the toggle or branch
     *  point) over the size of the terms it is the difference of: RRR
     *  min(l_m + l_n - |D_m D_n|, |D_m D_n| - |l_m - l_n|) / (l_m + l_n +
     *  |D_m D_n|), RRT and RTR alike (their files). It falls like
     *  conditioning^2. 1 where the dyad closes in one way (TRT, RTT). Filled
     *  whenever the dyad closes. */
    dyad_real closure;
    /** The bound of the motion's round-off (-), >= 1: every motion output is
     *  within c eps amplification of the largest output of its unit, the
     *  mounts' own round-off (mount_amplification) included:
     *      amplification = (1 + 1 / closure + 1 / conditioning)
     *                      (1 + mount_amplification (1 + |mounts| / size)),
     *  with |mounts| the distance of the mounts' points from the origin and
     *  size the closure's (each type's file). The status is singular where
     *  1 / amplification < singular_threshold. Filled whenever the dyad closes. */
    dyad_real amplification;
} dyad_kin_result;

/** Inputs with every field zero except guides, turns = (1, 0), lengths 1 m,
 *  branch +1 and the singular threshold DYAD_DEFAULT_SINGULAR_THRESHOLD;
 *  mount_amplification 0. */
dyad_kin_input dyad_kin_input_default(void);

/** Kinematics of the dyad of the given type. */
dyad_status dyad_kinematics(dyad_type type, const dyad_kin_input* input, dyad_kin_result* result);

/** RRR: E at distance l_m from D_m and l_n from D_n; branch +1 puts E to the
 *  left of the line from D_m to D_n (k0 . (D_n - D_m) x (E - D_m) > 0).
 *  D_m = D_n with l_m = l_n (E anywhere, the links folded) is singular with
 *  conditioning 0; so is a dyad exactly at full extension or folding (closure 0). */
dyad_status dyad_kinematics_rrr(const dyad_kin_input* input, dyad_kin_result* result);
/** RRT: D_m slides on guide k; branch +1 takes the larger slide s_k. */
dyad_status dyad_kinematics_rrt(const dyad_kin_input* input, dyad_kin_result* result);
/** RTR: E slides along link m; branch +1 takes the larger l_m. */
dyad_status dyad_kinematics_rtr(const dyad_kin_input* input, dyad_kin_result* result);
/** TRT: D_m slides on guide k and D_n on guide p; one assembly. */
dyad_status dyad_kinematics_trt(const dyad_kin_input* input, dyad_kin_result* result);
/** RTT: D_m slides on guide k and E along link m; one assembly. l_m is the
 *  signed coordinate of E along i_m: negative puts E behind D_m, not a failure. */
dyad_status dyad_kinematics_rtt(const dyad_kin_input* input, dyad_kin_result* result);

/** The kinematics and their directional derivative along `seed`, exactly (no
 *  finite differences). `seed` has the layout of the input and holds the rate
 *  of each field; a unit vector's rate is its derivative, of which only the
 *  part normal to it counts; branch is not differentiated. `derivative`
 *  receives the rate of every output of `value` in the same fields (a
 *  direction's rate is the derivative of its unit vector). Status as
 *  dyad_kinematics; outputs NaN unless ok. */
dyad_status dyad_kinematics_tangent(dyad_type type, const dyad_kin_input* input,
                                    const dyad_kin_input* seed, dyad_kin_result* value,
                                    dyad_kin_result* derivative);

/** dyad_kinematics_tangent for one type, so that a program using one type
 *  links only its kinematics. */
dyad_status dyad_kinematics_tangent_rrr(const dyad_kin_input* input, const dyad_kin_input* seed,
                                        dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kinematics_tangent_rrt(const dyad_kin_input* input, const dyad_kin_input* seed,
                                        dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kinematics_tangent_rtr(const dyad_kin_input* input, const dyad_kin_input* seed,
                                        dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kinematics_tangent_trt(const dyad_kin_input* input, const dyad_kin_input* seed,
                                        dyad_kin_result* value, dyad_kin_result* derivative);
dyad_status dyad_kinematics_tangent_rtt(const dyad_kin_input* input, const dyad_kin_input* seed,
                                        dyad_kin_result* value, dyad_kin_result* derivative);

/** Dotted input field name, e.g. "k.guide", "length_m"; "" for NONE. */
const char* dyad_kin_field_name(dyad_kin_field field);

/** The failed figure, e.g. "|D_m D_n| > l_m + l_n"; "" for CLOSES. */
const char* dyad_kin_failure_name(dyad_kin_failure failure);

/** The motion of a point fixed at `at` (m) in the frame {origin; dir, k0 x dir}
 *  of a link turning at omega (rad/s) and epsilon (rad/s^2), whose material
 *  point at `origin` moves as given: how the chain passes a pair point or a
 *  guide's point from a solved link to the next dyad. */
dyad_point_motion dyad_point_on_link(const dyad_point_motion* origin, dyad_vec2 dir,
                                     dyad_real omega, dyad_real epsilon, dyad_vec2 at);

/** A point's motion with its rate along a seed (dyadfmu/dual.h): v the motion,
 *  d the rate of each of its vectors. */
typedef struct dyad_dual_point_motion {
    dyad_point_motion v;
    dyad_point_motion d;
} dyad_dual_point_motion;

/** dyad_point_on_link on dual numbers: the motion of the point and its rate
 *  along the seed that every argument carries. */
dyad_dual_point_motion dyad_point_on_link_dual(dyad_dual_point_motion origin, dyad_dual_vec2 dir,
                                               dyad_dual omega, dyad_dual epsilon,
                                               dyad_dual_vec2 at);

#ifdef __cplusplus
}
#endif

#endif /* DYADFMU_KINEMATICS_H */
