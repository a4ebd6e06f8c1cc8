/* dyadfmu: a hydraulic cylinder between two pins driving a link about its pivot.
 *
 * The barrel is pinned at A to a body whose motion is known (the frame or a
 * solved link), the rod slides in the barrel and is pinned at B to a link that
 * turns about the pivot O (O's motion known likewise). The cylinder's length
 * s = |AB|, its rate and acceleration are the inputs: in Assur's terms the
 * cylinder and the link close like an RRR dyad whose side AB has a prescribed
 * variable length (triangle O, A, B with |OB| fixed and |AB| = s). The
 * function finds the motion of the link and of the cylinder, the cylinder's
 * axial force, the pin reactions at A, B and O and the barrel-rod reaction
 * (src/dyad_cylinder.c derives it all).
 *
 * Frames. The cylinder's axis u is the unit vector from A to B, j = k0 x u.
 * The link's frame is {O; i_l, j_l}, i_l at the link's angle, j_l = k0 x i_l;
 * B and the link's centre of mass are given in it. Angles are
 * counter-clockwise from the x axis, in (-pi, pi].
 *
 * Sign of the axial force: positive pushes the pins apart (the cylinder
 * extends against its load: compression in the rod); the barrel pushes the rod
 * with axial_force u, the rod the barrel with -axial_force u.
 *
 * The function allocates nothing, keeps no state and does no I/O. It returns
 * the status it also stores in result->status; unless it is DYAD_STATUS_OK
 * every motion and reaction output is NaN.
 */
#ifndef DYADFMU_CYLINDER_H
#define DYADFMU_CYLINDER_H

#include "dyadfmu/kinematics.h"
#include "dyadfmu/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The barrel or the rod: a body on the cylinder's axis. */
typedef struct dyad_cylinder_part {
    dyad_real mass; /**< (kg), >= 0 */
    /** Centre of mass on the axis (m): the barrel's at A + com u (from A towards
     *  B), the rod's at B - com u (from B towards A). Any finite value. */
    dyad_real com;
    dyad_real inertia; /**< about the centre of mass (kg m^2), >= 0 */
} dyad_cylinder_part;

/** The driven link: mass properties and its active load. */
typedef struct dyad_cylinder_link {
    dyad_real mass;    /**< (kg), >= 0 */
    dyad_vec2 com;     /**< centre of mass in the link's frame {O; i_l, j_l} (m) */
    dyad_real inertia; /**< about the centre of mass (kg m^2), >= 0 */
    dyad_vec2 force;   /**< active force at the centre of mass, global frame (N) */
    dyad_real moment;  /**< active moment (N m), counter-clockwise positive */
} dyad_cylinder_link;

/** Everything the cylinder needs. Start from dyad_cylinder_input_default(). */
typedef struct dyad_cylinder_input {
    /** Pin A of the barrel, a material point of the body carrying it. */
    dyad_point_motion a;
    /** Pivot O of the link, a material point of the body carrying it. */
    dyad_point_motion o;
    /** Pin B in the link's frame (m); |pin_b| > 0 is the fixed |OB|. */
    dyad_vec2 pin_b;
    dyad_real length; /**< s = |AB| (m), > 0 */
    dyad_real rate;   /**< ds/dt (m/s) */
    dyad_real accel;  /**< d2s/dt2 (m/s^2) */
    /** +1 puts B to the left of the line from O to A
     *  ((A - O) x (B - O) > 0), -1 to its right. */
    int branch;
    dyad_cylinder_part barrel; /**< pinned at A */
    dyad_cylinder_part rod;    /**< pinned at B */
    dyad_cylinder_link link;   /**< turns about O, pinned to the rod at B */
    dyad_vec2 gravity;         /**< gravitational acceleration, global frame (m/s^2) */
    /** The result is DYAD_STATUS_SINGULAR where 1 / kin_amplification falls
     *  below it (-), in (0, 1). Default DYAD_DEFAULT_SINGULAR_THRESHOLD. */
    dyad_real singular_threshold;
    /** The amplification the mounts' motion carries in (-), >= 0, as
     *  dyad_kin_input.mount_amplification: 0 (the default) for A and O known to
     *  the last bit (the frame, a driver's given motion); where they are points
     *  of solved links, the kin amplification of what moved them. */
    dyad_real mount_amplification;
} dyad_cylinder_input;

/** Input fields, to name the one that made a call invalid. */
typedef enum dyad_cylinder_field {
    DYAD_CYL_FIELD_NONE = 0,
    DYAD_CYL_FIELD_INPUT, /**< the input or result pointer itself is NULL */
    DYAD_CYL_FIELD_A_POSITION,
    DYAD_CYL_FIELD_A_VELOCITY,
    DYAD_CYL_FIELD_A_ACCELERATION,
    DYAD_CYL_FIELD_O_POSITION,
    DYAD_CYL_FIELD_O_VELOCITY,
    DYAD_CYL_FIELD_O_ACCELERATION,
    DYAD_CYL_FIELD_PIN_B,
    DYAD_CYL_FIELD_LENGTH,
    DYAD_CYL_FIELD_RATE,
    DYAD_CYL_FIELD_ACCEL,
    DYAD_CYL_FIELD_BRANCH,
    DYAD_CYL_FIELD_BARREL_MASS,
    DYAD_CYL_FIELD_BARREL_COM,
    DYAD_CYL_FIELD_BARREL_INERTIA,
    DYAD_CYL_FIELD_ROD_MASS,
    DYAD_CYL_FIELD_ROD_COM,
    DYAD_CYL_FIELD_ROD_INERTIA,
    DYAD_CYL_FIELD_LINK_MASS,
    DYAD_CYL_FIELD_LINK_COM,
    DYAD_CYL_FIELD_LINK_INERTIA,
    DYAD_CYL_FIELD_LINK_FORCE,
    DYAD_CYL_FIELD_LINK_MOMENT,
    DYAD_CYL_FIELD_GRAVITY,
    DYAD_CYL_FIELD_SINGULAR_THRESHOLD,
    DYAD_CYL_FIELD_MOUNT_AMPLIFICATION,
    DYAD_CYL_FIELD_COUNT
} dyad_cylinder_field;

/** The motion, the axial force and the reactions. Forces in the global frame. */
typedef struct dyad_cylinder_result {
    dyad_status status;
    /** The offending field when status is DYAD_STATUS_INVALID_INPUT, else NONE. */
    dyad_cylinder_field field;
    /** With DYAD_STATUS_CANNOT_ASSEMBLE: DYAD_KIN_TOO_FAR (|OA| > |OB| + s, the
     *  cylinder too short to reach) or DYAD_KIN_TOO_CLOSE (|OA| < ||OB| - s|,
     *  too long, or too short the other way); else DYAD_KIN_CLOSES. */
    dyad_kin_failure failure;
    /** With DYAD_STATUS_CANNOT_ASSEMBLE: by how much the triangle fails (m), > 0:
     *  |OA| - (|OB| + s) or ||OB| - s| - |OA|. Else 0. */
    dyad_real gap;

    dyad_vec2 link_dir;                              /**< i_l (-) */
    dyad_real link_angle;                            /**< angle of i_l (rad) */
    dyad_real link_omega;                            /**< (rad/s) */
    dyad_real link_epsilon;                          /**< (rad/s^2) */
    dyad_vec2 axis;                                  /**< u, the unit vector from A to B (-) */
    dyad_real cylinder_angle;                        /**< angle of u (rad) */
    dyad_real cylinder_omega;                        /**< of the barrel and the rod (rad/s) */
    dyad_real cylinder_epsilon;                      /**< (rad/s^2) */
    dyad_point_motion b;                             /**< pin B */
    dyad_point_motion barrel_com, rod_com, link_com; /**< the centres of mass */

    /** The actuator force along u (N): positive pushes the pins apart. */
    dyad_real axial_force;
    dyad_vec2 r_a; /**< force on the barrel from the body at A, at A (N) */
    dyad_vec2 r_b; /**< force on the link from the rod, at B (N); the rod receives -r_b */
    dyad_vec2 r_o; /**< force on the link from the body at O, at O (N) */
    /** The sliding pair: the barrel pushes the rod with axial_force u + n_rod j
     *  at B and the moment m_rod about B; the rod the barrel with the opposites. */
    dyad_real n_rod; /**< (N) */
    dyad_real m_rod; /**< (N m) */

    /** |sin| of the angle between OB and AB (-): the velocity equations'
     *  normalised determinant; 0 at the toggle (O, A, B in line). */
    dyad_real conditioning;
    /** The triangle's distance from failing over its size (-), in [0, 1]:
     *  min(|OB| + s - |OA|, |OA| - ||OB| - s|) / (|OB| + s + |OA|). */
    dyad_real closure;
    /** The motion's round-off bound (-), as the dyads' (kinematics.h):
     *      (1 + 1 / closure + 1 / conditioning)
     *      (1 + mount_amplification (1 + (|A|_1 + |O|_1) / (|OB| + s + |OA|))),
     *  every motion output within c eps kin_amplification of the largest of its
     *  unit. The status is singular where 1 / kin_amplification is below the
     *  threshold. Filled whenever the triangle closes. */
    dyad_real kin_amplification;
    /** The forces' round-off bound (-): with status ok every force (and the
     *  moment m_rod) is within c eps amplification of the largest of its unit;
     *  the load terms' cancellation (data factor) times kin_amplification. */
    dyad_real amplification;
} dyad_cylinder_result;

/** Every field zero except pin_b (1, 0), length 1 m, branch +1 and the
 *  default singular threshold. */
dyad_cylinder_input dyad_cylinder_input_default(void);

/** The cylinder's motion, axial force and reactions. */
dyad_status dyad_cylinder(const dyad_cylinder_input* input, dyad_cylinder_result* result);

/** The same and its exact directional derivative along `seed` (the layout of
 *  the input, each field's rate; branch and threshold are not differentiated):
 *  `derivative` receives the rate of every output of `value`, the gap, the
 *  conditioning, the closure and both amplifications included. */
dyad_status dyad_cylinder_tangent(const dyad_cylinder_input* input, const dyad_cylinder_input* seed,
                                  dyad_cylinder_result* value, dyad_cylinder_result* derivative);

/** Dotted input field name, e.g. "barrel.mass", "pin_b"; "" for NONE. */
const char* dyad_cylinder_field_name(dyad_cylinder_field field);

#ifdef __cplusplus
}
#endif

#endif /* DYADFMU_CYLINDER_H */
