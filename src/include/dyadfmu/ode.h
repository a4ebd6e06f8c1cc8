/* dyadfmu: an error-controlled integrator for y' = f(t, y), stable on stiff
 * problems: the Rosenbrock method RODASP of order 4 (src/dyad_ode.c derives and
 * justifies it), with its embedded error estimate, step-size control and
 * continuous output; and, for a problem that is not stiff, the explicit method
 * DOP853 of order 8 (options.method), with the same interface.
 *
 * It is what a forward-dynamics FMU integrates its equation of motion with
 * inside doStep: the caller owns everything (a dyad_ode_state holds the whole
 * integrator, plain data without pointers, so that copying it is an FMU state
 * save and copying it back a restore), nothing is allocated, no I/O is done,
 * libm is all it uses. The results depend on the calls alone: the same calls
 * from the same state give the same bits.
 *
 * One call, dyad_ode_advance(), integrates from the state's t to t_end in
 * internal steps the error control chooses; the last one is shortened to end
 * on t_end exactly (the inputs of an FMU change there), and the step size the
 * controller proposed is kept for the next call, so the steps do not follow
 * the caller's interval. Every call starts from a fresh f(t, y) and Jacobian:
 * the caller may change the right-hand side (an FMU's inputs) between calls.
 *
 * On a failure the state stays at the last accepted point (t, y): status
 * names what failed, and t_failed the time at which it did.
 */
#ifndef DYADFMU_ODE_H
#define DYADFMU_ODE_H

#include "dyadfmu/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The largest dimension of y the state has room for. */
#define DYAD_ODE_MAX_DIM 16

/** Result of dyad_ode_advance(). */
typedef enum dyad_ode_status {
    DYAD_ODE_OK = 0,
    /** The arguments are out of their domain (n, tolerances, t_end before t,
     *  a non-finite y or time); nothing was done. */
    DYAD_ODE_INVALID_ARGUMENT,
    /** f returned a failure code (kept in rhs_code): the state is at the last
     *  accepted point. */
    DYAD_ODE_RHS_FAILED,
    /** f returned a value that is not finite: the state is at the last
     *  accepted point. */
    DYAD_ODE_RHS_NONFINITE,
    /** The Jacobian callback returned a failure code (kept in rhs_code) or a
     *  Jacobian or df/dt that is not finite. */
    DYAD_ODE_JACOBIAN_FAILED,
    /** The iteration matrix I / (h gamma) - J stayed singular while the step
     *  was halved DYAD_ODE_SINGULAR_RETRIES times. */
    DYAD_ODE_SINGULAR,
    /** The error control asked for a step below 16 eps |t|: the solution is
     *  not smooth there (a discontinuity of f, a blow-up). */
    DYAD_ODE_STEP_UNDERFLOW,
    /** The call would need more than max_steps internal steps. Checked before
     *  each step: where the limits of the controller (the present step size,
     *  its growth by at most DYAD_ODE_MAX_GROWTH per step, h_max) already
     *  prove it, the state stops at the last accepted point (before the first
     *  step: nothing was done); it stops there too after max_steps steps. */
    DYAD_ODE_TOO_MANY_STEPS
} dyad_ode_status;

/** The most the step size grows from one step to the next. */
#define DYAD_ODE_MAX_GROWTH 6
/** How often a singular iteration matrix halves the step before giving up. */
#define DYAD_ODE_SINGULAR_RETRIES 5

/** The right-hand side: dydt = f(t, y), n values. Returns 0, or a non-zero
 *  code of the caller's own (e.g. the mechanism cannot assemble), which stops
 *  the integration with DYAD_ODE_RHS_FAILED. */
typedef int (*dyad_ode_rhs)(void* user, dyad_real t, const dyad_real* y, dyad_real* dydt);

/** The Jacobian: jac[i * n + j] = d f_i / d y_j at (t, y), row-major, and
 *  dfdt[i] = d f_i / d t (zeros for an autonomous system). f = f(t, y) is
 *  given for the caller's convenience. Returns 0 or a code of its own. */
typedef int (*dyad_ode_jacobian)(void* user, dyad_real t, const dyad_real* y, const dyad_real* f,
                                 dyad_real* jac, dyad_real* dfdt);

/** Lowers the magnitudes rtol applies to in a step from (t, y0) to y1: magnitude[i]
 *  holds max(|y0_i|, |y1_i|, options.magnitude[i]) on entry and may only be lowered (a
 *  larger value or NaN is ignored, a negative one counts as 0); component i's error is
 *  then held to atol + rtol magnitude[i]. For a quantity the caller computes from the
 *  states and whose error must stay within its own tolerance, such as the torque of a
 *  motor without inductance, k (V - k q') / R, which carries the speed's error times
 *  k^2 / R. Called after every attempt's stages, the last of which was evaluated at
 *  t + h. */
typedef void (*dyad_ode_error_magnitude)(void* user, const dyad_real* y0, const dyad_real* y1,
                                         dyad_real* magnitude);

/** What is integrated: not part of the state (it holds pointers). */
typedef struct dyad_ode_system {
    int n;            /**< dimension, 1..DYAD_ODE_MAX_DIM */
    dyad_ode_rhs rhs; /**< required */
    /** NULL: forward differences, n evaluations of f (one more for df/dt
     *  unless autonomous), counted in rhs_evaluations. */
    dyad_ode_jacobian jacobian;
    /** Non-zero: f does not depend on t, df/dt is zero (saves the evaluation
     *  of the difference Jacobian). */
    int autonomous;
    /** NULL: each component's error within atol + rtol max(|y0|, |y1|, magnitude). */
    dyad_ode_error_magnitude error_magnitude;
    void* user; /**< passed to the callbacks */
} dyad_ode_system;

/** The method of dyad_ode_advance(). */
typedef enum dyad_ode_method {
    /** RODASP, the Rosenbrock method of order 4: stable on stiff problems, a Jacobian and
     *  an LU factorisation per step (the default). */
    DYAD_ODE_RODASP = 0,
    /** DOP853, the explicit Runge-Kutta method of order 8: twelve evaluations of f per
     *  step and nothing else, for a problem that is not stiff. */
    DYAD_ODE_DOP853
} dyad_ode_method;

/** Settings: set by dyad_ode_init(), free to change between calls. */
typedef struct dyad_ode_options {
    /** The error of a step, per component, within atol + rtol |y| (in the
     *  root mean square over the components). rtol > 0, atol > 0. */
    dyad_real rtol;
    dyad_real atol;
    /** The largest internal step (> 0; default +inf). */
    dyad_real h_max;
    /** The first step (0: chosen from the tolerances and f, and at least 256 times
     *  the shortest step below). */
    dyad_real h_initial;
    /** The shortest step the error control may ask for (default 0) before the
     *  call gives up with DYAD_ODE_STEP_UNDERFLOW, as it does below 16 eps |t|:
     *  a caller that integrates from t = 0 states its own time's resolution. */
    dyad_real h_min;
    /** The most internal steps (accepted or not) one call may take (> 0). */
    long max_steps;
    dyad_ode_method method;
    /** The least magnitude rtol applies to, per component (default 0): the error of
     *  component i within atol + rtol max(|y0_i|, |y1_i|, magnitude[i]), so that a
     *  component passing through zero is held to its own scale, not to atol. */
    dyad_real magnitude[DYAD_ODE_MAX_DIM];
} dyad_ode_options;

/** What the integrator did, summed over the calls since dyad_ode_init(). */
typedef struct dyad_ode_counters {
    long rhs_evaluations; /**< calls of f, those of the difference Jacobian included */
    long jacobian_evaluations;
    long decompositions; /**< LU factorisations of the iteration matrix */
    long accepted_steps;
    long rejected_steps;
} dyad_ode_counters;

/** The whole integrator: plain data, copied by assignment or memcpy. */
typedef struct dyad_ode_state {
    int n;
    dyad_real t;                   /**< the last accepted time */
    dyad_real y[DYAD_ODE_MAX_DIM]; /**< the solution at t */
    dyad_ode_options options;      /**< read by every call */
    dyad_ode_counters counters;    /**< updated by every call */
    /* The step-size controller: the next step's size (0 before the first),
     * and the last accepted step's size and error for Gustafsson's
     * predictive control (0 before the first). */
    dyad_real h_next;
    dyad_real h_accepted;
    dyad_real error_accepted;
    /* The continuous output of the last accepted step [t - h_last, t]:
     * y(t - h_last + s h_last) = (1 - s) y_last + s (y + (1 - s)(d1 + s d2)). */
    dyad_real h_last;                   /**< 0: no step taken yet */
    dyad_real y_last[DYAD_ODE_MAX_DIM]; /**< y at t - h_last */
    dyad_real d1[DYAD_ODE_MAX_DIM];
    dyad_real d2[DYAD_ODE_MAX_DIM];
    /* The last failure: */
    dyad_ode_status status;
    int rhs_code;       /**< the callback's code for RHS_FAILED, JACOBIAN_FAILED */
    dyad_real t_failed; /**< where f or the step failed (t itself if before any step) */
} dyad_ode_state;

/** Defaults: rtol 1e-8, atol 1e-10, h_max +inf, h_initial 0, h_min 0, max_steps 100000,
 *  method RODASP. */
dyad_ode_options dyad_ode_options_default(void);

/** Starts the integrator at (t0, y0) of dimension n with the given options
 *  (NULL: the defaults): counters zero, no step taken. Returns
 *  DYAD_ODE_INVALID_ARGUMENT (state->status too) for a bad n, option or a
 *  non-finite t0 or y0. */
dyad_ode_status dyad_ode_init(dyad_ode_state* state, int n, dyad_real t0, const dyad_real* y0,
                              const dyad_ode_options* options);

/** Integrates from state->t to t_end (>= state->t). Returns the status, also
 *  stored in state->status; DYAD_ODE_OK means state->t == t_end. */
dyad_ode_status dyad_ode_advance(dyad_ode_state* state, const dyad_ode_system* system,
                                 dyad_real t_end);

/** The continuous output of the last accepted step at time t in
 *  [state->t - state->h_last, state->t]: the solution (y) and its derivative
 *  (dydt), of order 3; either may be NULL. Returns DYAD_ODE_INVALID_ARGUMENT
 *  for t outside that interval or before the first step, else DYAD_ODE_OK. */
dyad_ode_status dyad_ode_dense(const dyad_ode_state* state, dyad_real t, dyad_real* y,
                               dyad_real* dydt);

/** The status's name, e.g. "step size underflow" (never NULL). */
const char* dyad_ode_status_name(dyad_ode_status status);

#ifdef __cplusplus
}
#endif

#endif /* DYADFMU_ODE_H */
