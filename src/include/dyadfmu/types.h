/* dyadfmu: kinetostatics of planar Assur dyads.
 * Types shared by the solvers: the scalar, 2-D vectors, inputs, results, status.
 *
 * Conventions (all vectors in the global frame unless a field says otherwise):
 * - x, y span the plane, z points out of it; moments and angular quantities are
 *   z components, counter-clockwise positive.
 * - The dyad has links m and n and three pairs: D_m (link m with the external
 *   link k), E (m with n) and D_n (n with the external link p).
 * - i_g is the unit vector of link g from D_g to E and j_g = k0 x i_g, so
 *   E = D_m + l_m i_m = D_n + l_n i_n.
 */
#ifndef DYADFMU_TYPES_H
#define DYADFMU_TYPES_H

#include <float.h>

/* The scalar. double unless the library is built with DYAD_REAL_FLOAT
 * (CMake option DYADFMU_FLOAT). */
#ifdef DYAD_REAL_FLOAT
typedef float dyad_real;
#define DYAD_REAL_EPSILON FLT_EPSILON
#define DYAD_REAL_MAX     FLT_MAX
#define DYAD_REAL_MIN     FLT_MIN
#define DYAD_REAL_NAME    "float" /* in messages: what a value overflowed */
/** Default singular threshold: sqrt(FLT_EPSILON) = 2^-11.5. */
#define DYAD_DEFAULT_SINGULAR_THRESHOLD 3.4526698e-4f
#else
typedef double dyad_real;
#define DYAD_REAL_EPSILON               DBL_EPSILON
#define DYAD_REAL_MAX                   DBL_MAX
#define DYAD_REAL_MIN                   DBL_MIN
#define DYAD_REAL_NAME                  "double"
/** Default singular threshold: sqrt(DBL_EPSILON) = 2^-26. At this conditioning
 *  the round-off bound eps * amplification is sqrt(eps): half the digits survive. */
#define DYAD_DEFAULT_SINGULAR_THRESHOLD 1.4901161193847656e-8
#endif

/* A constant in the scalar's precision: generated code writes its numbers so, because a
 * double constant would make a float build compute the whole expression in double (in
 * software on an FPU of single precision). In a double build it is the number itself. */
#define DYAD_R(x) ((dyad_real)(x))

/** A direction vector passes as unit when | |v|^2 - 1 | is at most this (-).
 *  It is then normalised exactly before use. */
#define DYAD_UNIT_TOLERANCE ((dyad_real)1e-6)

/** 2-D vector. */
typedef struct dyad_vec2 {
    dyad_real x;
    dyad_real y;
} dyad_vec2;

/** The five dyad types, named by their pairs at D_m, E, D_n
 *  (R revolute, T translational). */
typedef enum dyad_type {
    DYAD_RRR = 0, /**< R at D_m, R at E, R at D_n */
    DYAD_RRT,     /**< T at D_m (guide i_k), R at E, R at D_n */
    DYAD_RTR,     /**< R at D_m, T at E (guide i_m), R at D_n */
    DYAD_TRT,     /**< T at D_m (guide i_k), R at E, T at D_n (guide i_p) */
    DYAD_RTT,     /**< T at D_m (guide i_k), T at E (guide i_m), R at D_n */
    DYAD_TYPE_COUNT
} dyad_type;

/** Kind of a kinematic pair. */
typedef enum dyad_pair_kind {
    DYAD_PAIR_REVOLUTE = 0,     /**< carries a force in any direction, no moment */
    DYAD_PAIR_TRANSLATIONAL = 1 /**< carries a force normal to its guide and a moment */
} dyad_pair_kind;

/** The links of a dyad. */
typedef enum dyad_link_id {
    DYAD_LINK_M = 0, /**< link m, from D_m to E */
    DYAD_LINK_N = 1  /**< link n, from D_n to E */
} dyad_link_id;

/** The pairs of a dyad. */
typedef enum dyad_pair {
    DYAD_PAIR_DM = 0, /**< D_m: link m with external link k */
    DYAD_PAIR_E = 1,  /**< E: link m with link n */
    DYAD_PAIR_DN = 2  /**< D_n: link n with external link p */
} dyad_pair;

/** Result of a solve. */
typedef enum dyad_status {
    DYAD_STATUS_OK = 0,
    /** The type's denominator (its conditioning) is below the singular threshold:
     *  the dyad cannot carry its load with finite reactions. Outputs are NaN. */
    DYAD_STATUS_SINGULAR,
    /** An input field is out of its domain; dyad_result.field names it.
     *  Outputs are NaN. */
    DYAD_STATUS_INVALID_INPUT,
    /** Inputs were valid and conditioned, but a load or reaction overflows the
     *  scalar type. Outputs are NaN. */
    DYAD_STATUS_OUT_OF_RANGE,
    /** Kinematics only (kinematics.h): the dyad cannot close at this motion of
     *  its external links; dyad_kin_result.failure names the figure and .gap
     *  says by how much (m). Outputs are NaN. */
    DYAD_STATUS_CANNOT_ASSEMBLE
} dyad_status;

/** Input fields, to name the one that made a call invalid. */
typedef enum dyad_field {
    DYAD_FIELD_NONE = 0,
    DYAD_FIELD_INPUT, /**< the input or result pointer itself is NULL */
    DYAD_FIELD_TYPE,  /**< the dyad type is not one of dyad_type */
    DYAD_FIELD_M_DIR,
    DYAD_FIELD_M_LENGTH,
    DYAD_FIELD_M_OMEGA,
    DYAD_FIELD_M_EPSILON,
    DYAD_FIELD_M_ACCEL_D,
    DYAD_FIELD_M_COM,
    DYAD_FIELD_M_MASS,
    DYAD_FIELD_M_INERTIA,
    DYAD_FIELD_M_FORCE,
    DYAD_FIELD_M_MOMENT,
    DYAD_FIELD_N_DIR,
    DYAD_FIELD_N_LENGTH,
    DYAD_FIELD_N_OMEGA,
    DYAD_FIELD_N_EPSILON,
    DYAD_FIELD_N_ACCEL_D,
    DYAD_FIELD_N_COM,
    DYAD_FIELD_N_MASS,
    DYAD_FIELD_N_INERTIA,
    DYAD_FIELD_N_FORCE,
    DYAD_FIELD_N_MOMENT,
    DYAD_FIELD_GUIDE_K,
    DYAD_FIELD_GUIDE_P,
    DYAD_FIELD_GRAVITY,
    DYAD_FIELD_SINGULAR_THRESHOLD,
    DYAD_FIELD_COUNT
} dyad_field;

/** One link of the dyad: geometry, kinematics, mass properties, active load. */
typedef struct dyad_link {
    /** i_g: unit vector from D_g to E, global frame (-). Must be unit within
     *  DYAD_UNIT_TOLERANCE. Where l_g is 0 it still fixes the link frame of com. */
    dyad_vec2 dir;
    /** l_g = |D_g E| (m): the constant length, or the current one of a link
     *  whose pair slides. Positive or non-negative as the type requires
     *  (see dyad_length_may_be_zero()). */
    dyad_real length;
    /** Absolute angular velocity (rad/s). */
    dyad_real omega;
    /** Absolute angular acceleration (rad/s^2). */
    dyad_real epsilon;
    /** Absolute acceleration of point D_g, global frame (m/s^2). */
    dyad_vec2 accel_d;
    /** Centre of mass (x_S, y_S) in the link frame {D_g; i_g, j_g} (m). */
    dyad_vec2 com;
    /** Mass (kg), >= 0. */
    dyad_real mass;
    /** Moment of inertia about the centre of mass, normal to the plane (kg m^2), >= 0. */
    dyad_real inertia;
    /** Active load force at the centre of mass, global frame (N). */
    dyad_vec2 force;
    /** Active load moment (N m), counter-clockwise positive. */
    dyad_real moment;
} dyad_link;

/** Everything a solver needs. Start from dyad_input_default(). */
typedef struct dyad_input {
    dyad_link m; /**< link m, paired with k at D_m */
    dyad_link n; /**< link n, paired with p at D_n */
    /** i_k: unit direction of the guide on link k at D_m, global frame (-).
     *  Read only where D_m is translational (RRT, TRT, RTT). */
    dyad_vec2 guide_k;
    /** i_p: unit direction of the guide on link p at D_n, global frame (-).
     *  Read only where D_n is translational (TRT). */
    dyad_vec2 guide_p;
    /** Gravitational acceleration, global frame (m/s^2); default zero. */
    dyad_vec2 gravity;
    /** Conditioning below which the solve reports DYAD_STATUS_SINGULAR (-),
     *  in (0, 1). Default DYAD_DEFAULT_SINGULAR_THRESHOLD. */
    dyad_real singular_threshold;
} dyad_input;

/** Reactions of a dyad. Every force acts at the pair it names, in the global
 *  frame; forces on the other link of a pair are the opposites. */
typedef struct dyad_result {
    dyad_status status;
    /** The offending field when status is DYAD_STATUS_INVALID_INPUT, else NONE. */
    dyad_field field;

    /** R_mk: force on link m from link k, acting at D_m, global frame (N). */
    dyad_vec2 r_mk;
    /** R_np: force on link n from link p, acting at D_n, global frame (N). */
    dyad_vec2 r_np;
    /** R_mn: force on link m from link n, acting at E, global frame (N);
     *  link n receives -R_mn. */
    dyad_vec2 r_mn;

    /** Normal force of a translational D_m: R_mk . j_k (N). 0 where D_m is revolute. */
    dyad_real n_mk;
    /** Normal force of a translational D_n: R_np . j_p (N). 0 where D_n is revolute. */
    dyad_real n_np;
    /** Normal force of a translational E: R_mn . j_m (N). 0 where E is revolute. */
    dyad_real n_mn;

    /** M^R_mk: reactive moment on link m from link k about D_m (N m).
     *  0 where D_m is revolute (a revolute pair carries no moment). */
    dyad_real m_mk;
    /** M^R_np: reactive moment on link n from link p about D_n (N m). 0 where revolute. */
    dyad_real m_np;
    /** M^R_mn: reactive moment on link m from link n about E (N m); link n
     *  receives -M^R_mn. 0 where E is revolute. */
    dyad_real m_mn;

    /** The type's signed denominator (-): RRR i_m.j_n, RRT i_n.i_k,
     *  RTR i_beta.i_m, TRT j_k.i_p, RTT j_k.i_m. */
    dyad_real denominator;
    /** Conditioning in [0, 1] (-): |denominator|; for RTR the smaller of
     *  |i_beta.i_m| and |D_m D_n| / (l_m + l_n). Compared with the threshold. */
    dyad_real conditioning;
    /** The bound of the round-off (-): with status ok, every output is within
     *  c eps amplification of the largest output of its unit (forces in N,
     *  moments in N m); the cancellation of the load terms (the data factor)
     *  over the conditioning (dyad_amplification.h). Otherwise 1 / conditioning,
     *  +inf exactly at a singular position, NaN for an invalid input. */
    dyad_real amplification;
} dyad_result;

/* The widest instruction set a batch (dyad_solve_batch_at_most, a scene's
 * <id>_lanes_at_most) may take: it takes the widest the CPU runs up to it. Without a
 * cap, the widest. */
typedef enum dyad_lanes_isa {
    DYAD_LANES_BASELINE = 0, /* the platform's baseline (x86-64: SSE2) */
    DYAD_LANES_AVX2 = 1,
    DYAD_LANES_AVX512 = 2
} dyad_lanes_isa;

#endif /* DYADFMU_TYPES_H */
