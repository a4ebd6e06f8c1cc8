/* dyadfmu: the integrators of dyadfmu/ode.h, the Rosenbrock method RODASP and, further
 * down, the explicit DOP853.
 *
 * The problem. A mechanism's equation of motion M(q) q'' = effort - h(q, q')
 * is smooth and mildly stiff at most; with a DC motor in the same system the
 * armature current i obeys L i' = V - R i - k_e w, an eigenvalue near -R/L,
 * down to -1e6 1/s for L/R = 1e-6 s, while the motion it drives changes over
 * milliseconds. An explicit method must keep h |lambda| inside its stability
 * region, h < ~3e-6 s there: a thousand steps per millisecond of motion, no
 * matter the tolerance. The method must therefore be A-stable, and L-stable
 * (its amplification R(z) -> 0 as z -> -inf), so that the fast mode is
 * damped out in one step instead of ringing with |R| near 1 (the trapezoidal
 * rule, ROS3P's |R(inf)| = 0.73).
 *
 * Why a Rosenbrock method. An implicit Runge-Kutta or BDF method solves a
 * nonlinear system per step by Newton's iteration, whose convergence test,
 * Jacobian reuse and restarts make the cost irregular and the code large. A
 * Rosenbrock method builds the Newton step into the method: with
 * J = df/dy (t0, y0), f_t = df/dt (t0, y0), gamma fixed and
 *      (I / (h gamma) - J) u_i = f(t0 + c_i h, y0 + sum_{j<i} a_ij u_j)
 *                                 + sum_{j<i} (C_ij / h) u_j + h d_i f_t,
 * for i = 1..s, each stage is one linear solve with the same matrix: one LU
 * factorisation per step, s evaluations of f, no iteration, so the cost of a
 * step is fixed and its result a fixed sequence of operations (bit-for-bit
 * reproducible). The price is that the order conditions assume the exact J,
 * which the FMU has (the generated code's directional derivatives); a
 * forward-difference J is the fallback here, at n evaluations of f.
 *
 * Why RODASP. Of the Rosenbrock methods with an embedded estimate, the RODAS
 * family (E. Hairer, G. Wanner, Solving Ordinary Differential Equations II,
 * 2nd ed., Springer 1996, section IV.7, and their code rodas.f) is order 4
 * with an order-3 embedded solution, L-stable, and stiffly accurate (the last
 * stage's argument is the solution, c_5 = c_6 = 1), so it keeps its order on
 * very stiff problems and index-1 DAEs. Order 4 matters at the project's
 * tolerances (rtol 1e-8 and below): the step grows as rtol^(1/4), against
 * rtol^(1/3) for the order-3 ROS34PW2 or ROS3P, a factor rtol^(-1/12) = 4.6
 * fewer steps at 1e-8 (the constants aside) for two more stages than
 * ROS34PW2's four. Six stages, the last one the estimate:
 *      y1 = y0 + sum_{j<5} a_5j u_j + u_5 + u_6,   error = u_6,
 * the difference between the order-4 solution and the order-3 one (the
 * argument of stage 6).
 * The motor's current is the case that decides between the members: with
 * L/R small, L i' = V(t) - R i - k w(t) is a Prothero-Robinson equation,
 * i - g(t) = O(L/R) pulled onto a slowly moving g, on which Hairer's RODAS4
 * (rodas.f METH = 1) loses order for h >> L/R (its stages do not satisfy
 * the extra conditions). Measured here on the motor of dyad_ode_tests.c at
 * rtol 1e-10: RODAS4 took 32209 steps for L/R = 1e-6 s against 4315 for
 * L/R = 1e-3 s. RODASP (G. Steinebach, Order-reduction of ROW-methods for
 * DAEs and method of lines applications, Preprint 1741, TH Darmstadt 1995;
 * rodas.f METH = 2; also called Rodas4P) satisfies them: order 4 on the
 * Prothero-Robinson problem for any stiffness, and with it the two motors
 * take 3223 and 3197 steps. The coefficients below are rodas.f's (METH = 2)
 * to 16 digits. Its continuous extension (rodas.f, CONTRO) is the cubic
 *      y(t0 + s h) = (1 - s) y0 + s (y1 + (1 - s)(D1 + s D2)),
 *      D1 = sum_{j<=5} h_1j u_j,  D2 = sum_{j<=5} h_2j u_j,
 * of order 3, free: the stages are already there. The tests measure the
 * order 4 (the error of fixed steps falls 16 times per halving) and the
 * continuous output against exact solutions.
 *
 * The error control (rodas.f's): the error of a step is the root mean square
 * of u_6,i / (atol + rtol max(|y0_i|, |y1_i|)), a magnitude the system may
 * lower (error_magnitude: a quantity computed from the states, held to its
 * own tolerance, tightens its states' error); accepted at <= 1; the next
 * step is h / fac, fac = err^(1/4) / 0.9 limited to [1/6, 5], with
 * Gustafsson's predictive factor (from the last accepted step's h and error,
 * kept in the state) after an accepted step, and no growth right after a
 * rejection. A singular iteration matrix halves the step.
 *
 * Determinism. Nothing but the arguments and the state is read; the loops run
 * in fixed order; no FMA is asked for (C99 with GCC's -std=c99 contracts
 * nothing), so two runs of the same calls agree to the bit.
 */
#include "dyadfmu/ode.h"

#include <math.h>
#include <string.h>
#include <stddef.h>

#define ODE_STAGES 6
#define ODE_SAFETY ((dyad_real)0.9)
/** fac = h / h_new is kept in [1 / DYAD_ODE_MAX_GROWTH, 1 / ODE_MIN_SHRINK]. */
#define ODE_MIN_SHRINK ((dyad_real)0.2)

/* RODASP (Rodas4P), G. Steinebach 1995, as in rodas.f (METH = 2). gamma, and
 * c_5 = c_6 = 1, d_5 = d_6 = 0 (stiffly accurate). */
static const dyad_real rodas_gamma = 0.25;
static const dyad_real rodas_c[ODE_STAGES] = {0.0, 0.75, 0.21, 0.63, 1.0, 1.0};
static const dyad_real rodas_d[ODE_STAGES] = {0.25, -0.5, -0.023504, -0.0362, 0.0, 0.0};
/* a[i][j], j < i: the arguments of f; stage 6 is stage 5's plus u_5. */
static const dyad_real rodas_a[5][4] = {
    {0.0, 0.0, 0.0, 0.0},
    {3.0, 0.0, 0.0, 0.0},
    {1.831036793486759, 0.4955183967433795, 0.0, 0.0},
    {2.304376582692669, -0.05249275245743001, -1.176798761832782, 0.0},
    {-7.170454962423024, -4.741636671481785, -16.31002631330971, -1.062004044111401}};
/* C[i][j], j < i: the stages' coupling, divided by h. */
static const dyad_real rodas_cc[ODE_STAGES][5] = {
    {0.0, 0.0, 0.0, 0.0, 0.0},
    {-12.0, 0.0, 0.0, 0.0, 0.0},
    {-8.791795173947035, -2.207865586973518, 0.0, 0.0, 0.0},
    {10.81793056857153, 6.780270611428266, 19.53485944642410, 0.0, 0.0},
    {34.19095006749676, 15.49671153725963, 54.74760875964130, 14.16005392148534, 0.0},
    {34.62605830930532, 15.30084976114473, 56.99955578662667, 18.40807009793095,
     -5.714285714285717}};
/* The continuous output's D1 and D2 from u_1..u_5. */
static const dyad_real rodas_h[2][5] = {
    {25.09876703708589, 11.62013104361867, 28.49148307714626, -5.664021568594133, 0.0},
    {1.638054557396973, -0.7373619806678748, 8.477918219238990, 15.99253148779520,
     -1.882352941176471}};

/* What one point (t0, y0) needs for all attempts at a step from it, and the
 * attempts' scratch. On the stack of dyad_ode_advance(): nothing persists. */
typedef struct ode_work {
    dyad_real f0[DYAD_ODE_MAX_DIM];
    dyad_real ft[DYAD_ODE_MAX_DIM];
    dyad_real jac[DYAD_ODE_MAX_DIM * DYAD_ODE_MAX_DIM];
    dyad_real lu[DYAD_ODE_MAX_DIM * DYAD_ODE_MAX_DIM];
    int pivot[DYAD_ODE_MAX_DIM];
    dyad_real u[ODE_STAGES][DYAD_ODE_MAX_DIM];
    dyad_real arg[DYAD_ODE_MAX_DIM];  /* the argument of f at a stage */
    dyad_real ynew[DYAD_ODE_MAX_DIM]; /* the step's solution */
} ode_work;

/* ---- options and arguments ------------------------------------------------------------------ */

dyad_ode_options dyad_ode_options_default(void)
{
    dyad_ode_options o;
    o.rtol = (dyad_real)1e-8;
    o.atol = (dyad_real)1e-10;
    o.h_max = (dyad_real)INFINITY;
    o.h_initial = 0;
    o.h_min = 0;
    o.max_steps = 100000;
    o.method = DYAD_ODE_RODASP;
    memset(o.magnitude, 0, sizeof o.magnitude);
    return o;
}

static int ode_finite_vector(int n, const dyad_real* v)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (!isfinite(v[i])) {
            return 0;
        }
    }
    return 1;
}

static int ode_magnitudes_valid(const dyad_ode_options* o)
{
    int i;
    for (i = 0; i < DYAD_ODE_MAX_DIM; ++i) {
        if (!(isfinite(o->magnitude[i]) && o->magnitude[i] >= 0)) {
            return 0;
        }
    }
    return 1;
}

static int ode_options_valid(const dyad_ode_options* o)
{
    return ode_magnitudes_valid(o) && isfinite(o->rtol) && o->rtol > 0 && isfinite(o->atol) &&
           o->atol > 0 && o->h_max > 0 && isfinite(o->h_initial) && o->h_initial >= 0 &&
           isfinite(o->h_min) && o->h_min >= 0 && o->max_steps > 0 &&
           (o->method == DYAD_ODE_RODASP || o->method == DYAD_ODE_DOP853);
}

/* The magnitude rtol applies to where component i goes from y_i to y1: the larger, at
 * least the component's own (options.magnitude). */
static dyad_real ode_magnitude(const dyad_ode_state* s, int i, dyad_real y1)
{
    return fmax(fmax(fabs(s->y[i]), fabs(y1)), s->options.magnitude[i]);
}

/* The scale of component i's error where it goes from y_i to y1: atol + rtol times its
 * magnitude. */
static dyad_real ode_scale(const dyad_ode_state* s, int i, dyad_real y1)
{
    return s->options.atol + s->options.rtol * ode_magnitude(s, i, y1);
}

/* Every component's error scale for a step from s->y to y1: ode_scale(), its magnitude
 * lowered where the system's error_magnitude() says so. */
static void ode_scales(const dyad_ode_state* s, const dyad_ode_system* sys, const dyad_real* y1,
                       dyad_real* sc)
{
    int i;
    dyad_real own[DYAD_ODE_MAX_DIM], asked[DYAD_ODE_MAX_DIM];
    for (i = 0; i < s->n; ++i) {
        own[i] = asked[i] = ode_magnitude(s, i, y1[i]);
    }
    if (sys->error_magnitude != NULL) {
        sys->error_magnitude(sys->user, s->y, y1, asked);
    }
    for (i = 0; i < s->n; ++i) {
        const dyad_real kept = asked[i] < own[i] ? fmax(asked[i], 0) : own[i];
        sc[i] = s->options.atol + s->options.rtol * kept;
    }
}

dyad_ode_status dyad_ode_init(dyad_ode_state* state, int n, dyad_real t0, const dyad_real* y0,
                              const dyad_ode_options* options)
{
    int i;
    dyad_ode_state s;
    if (state == NULL) {
        return DYAD_ODE_INVALID_ARGUMENT;
    }
    for (i = 0; i < DYAD_ODE_MAX_DIM; ++i) {
        s.y[i] = s.y_last[i] = s.d1[i] = s.d2[i] = 0;
    }
    s.n = n;
    s.t = s.t_failed = t0;
    s.options = options != NULL ? *options : dyad_ode_options_default();
    s.counters.rhs_evaluations = s.counters.jacobian_evaluations = s.counters.decompositions = 0;
    s.counters.accepted_steps = s.counters.rejected_steps = 0;
    s.h_next = s.h_accepted = s.error_accepted = s.h_last = 0;
    s.rhs_code = 0;
    s.status = DYAD_ODE_OK;
    if (n < 1 || n > DYAD_ODE_MAX_DIM || y0 == NULL || !isfinite(t0) || !ode_finite_vector(n, y0) ||
        !ode_options_valid(&s.options)) {
        s.status = DYAD_ODE_INVALID_ARGUMENT;
    } else {
        for (i = 0; i < n; ++i) {
            s.y[i] = y0[i];
        }
    }
    *state = s;
    return s.status;
}

const char* dyad_ode_status_name(dyad_ode_status status)
{
    switch (status) {
    case DYAD_ODE_OK: return "ok";
    case DYAD_ODE_INVALID_ARGUMENT: return "invalid argument";
    case DYAD_ODE_RHS_FAILED: return "right-hand side failed";
    case DYAD_ODE_RHS_NONFINITE: return "right-hand side not finite";
    case DYAD_ODE_JACOBIAN_FAILED: return "Jacobian failed";
    case DYAD_ODE_SINGULAR: return "singular iteration matrix";
    case DYAD_ODE_STEP_UNDERFLOW: return "step size underflow";
    case DYAD_ODE_TOO_MANY_STEPS: return "too many steps";
    }
    return "unknown status";
}

/* ---- linear algebra: LU with partial pivoting, n x n, row-major, in place ------------------- */

/* Returns 0, or 1 where a pivot is zero or not finite (the matrix is singular
 * to working precision or overflowed). */
static int ode_lu_factor(int n, dyad_real* a, int* pivot)
{
    int i, j, k;
    for (k = 0; k < n; ++k) {
        int p = k;
        for (i = k + 1; i < n; ++i) {
            if (fabs(a[i * n + k]) > fabs(a[p * n + k])) {
                p = i;
            }
        }
        pivot[k] = p;
        if (!(a[p * n + k] != 0) || !isfinite(a[p * n + k])) {
            return 1;
        }
        if (p != k) {
            for (j = 0; j < n; ++j) {
                dyad_real swap = a[k * n + j];
                a[k * n + j] = a[p * n + j];
                a[p * n + j] = swap;
            }
        }
        for (i = k + 1; i < n; ++i) {
            dyad_real l = a[i * n + k] /= a[k * n + k];
            for (j = k + 1; j < n; ++j) {
                a[i * n + j] -= l * a[k * n + j];
            }
        }
    }
    return 0;
}

static void ode_lu_solve(int n, const dyad_real* lu, const int* pivot, dyad_real* b)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        dyad_real swap = b[pivot[i]];
        b[pivot[i]] = b[i];
        b[i] = swap;
        for (j = 0; j < i; ++j) {
            b[i] -= lu[i * n + j] * b[j];
        }
    }
    for (i = n - 1; i >= 0; --i) {
        for (j = i + 1; j < n; ++j) {
            b[i] -= lu[i * n + j] * b[j];
        }
        b[i] /= lu[i * n + i];
    }
}

/* ---- evaluations ---------------------------------------------------------------------------- */

/* f(t, y) into dydt, counted; a failure is recorded in the state with t. */
static dyad_ode_status ode_rhs(dyad_ode_state* s, const dyad_ode_system* sys, dyad_real t,
                               const dyad_real* y, dyad_real* dydt)
{
    int code = sys->rhs(sys->user, t, y, dydt);
    ++s->counters.rhs_evaluations;
    if (code != 0 || !ode_finite_vector(s->n, dydt)) {
        s->rhs_code = code;
        s->t_failed = t;
        return code != 0 ? DYAD_ODE_RHS_FAILED : DYAD_ODE_RHS_NONFINITE;
    }
    return DYAD_ODE_OK;
}

/* Forward differences (rodas.f's increments): column j of J from a step of
 * y_j by sqrt(eps max(1e-5, |y_j|)), df/dt likewise in t. */
static dyad_ode_status ode_difference_jacobian(dyad_ode_state* s, const dyad_ode_system* sys,
                                               ode_work* w)
{
    int i, j, n = s->n;
    dyad_real fj[DYAD_ODE_MAX_DIM];
    dyad_ode_status status;
    for (j = 0; j < n; ++j) {
        w->arg[j] = s->y[j];
    }
    for (j = 0; j < n; ++j) {
        dyad_real delta = sqrt(DYAD_REAL_EPSILON * fmax((dyad_real)1e-5, fabs(s->y[j])));
        w->arg[j] = s->y[j] + delta;
        delta = w->arg[j] - s->y[j]; /* the step as represented */
        status = ode_rhs(s, sys, s->t, w->arg, fj);
        w->arg[j] = s->y[j];
        if (status != DYAD_ODE_OK) {
            return status;
        }
        for (i = 0; i < n; ++i) {
            w->jac[i * n + j] = (fj[i] - w->f0[i]) / delta;
        }
    }
    for (i = 0; i < n; ++i) {
        w->ft[i] = 0;
    }
    if (!sys->autonomous) {
        dyad_real delta = sqrt(DYAD_REAL_EPSILON * fmax((dyad_real)1e-5, fabs(s->t)));
        delta = (s->t + delta) - s->t;
        status = ode_rhs(s, sys, s->t + delta, s->y, fj);
        if (status != DYAD_ODE_OK) {
            return status;
        }
        for (i = 0; i < n; ++i) {
            w->ft[i] = (fj[i] - w->f0[i]) / delta;
        }
    }
    return DYAD_ODE_OK;
}

/* f, J and df/dt at the state's (t, y), into the work. */
static dyad_ode_status ode_linearise(dyad_ode_state* s, const dyad_ode_system* sys, ode_work* w)
{
    int n = s->n, code;
    dyad_ode_status status = ode_rhs(s, sys, s->t, s->y, w->f0);
    if (status != DYAD_ODE_OK) {
        return status;
    }
    ++s->counters.jacobian_evaluations;
    if (sys->jacobian == NULL) {
        return ode_difference_jacobian(s, sys, w);
    }
    code = sys->jacobian(sys->user, s->t, s->y, w->f0, w->jac, w->ft);
    if (code != 0 || !ode_finite_vector(n * n, w->jac) || !ode_finite_vector(n, w->ft)) {
        s->rhs_code = code;
        s->t_failed = s->t;
        return DYAD_ODE_JACOBIAN_FAILED;
    }
    return DYAD_ODE_OK;
}

/* ---- one step ------------------------------------------------------------------------------- */

/* LU of I / (h gamma) - J into w->lu; 1 where singular. */
static int ode_iteration_matrix(dyad_ode_state* s, ode_work* w, dyad_real h)
{
    int i, n = s->n;
    dyad_real diagonal = 1 / (h * rodas_gamma);
    for (i = 0; i < n * n; ++i) {
        w->lu[i] = -w->jac[i];
    }
    for (i = 0; i < n; ++i) {
        w->lu[i * n + i] += diagonal;
    }
    ++s->counters.decompositions;
    return ode_lu_factor(n, w->lu, w->pivot);
}

/* Stage k (0-based): the argument y0 + sum a_kj u_j (stage 5 adds u_4 to
 * stage 4's), f there, the right-hand side and the solve, into w->u[k]. */
static dyad_ode_status ode_stage(dyad_ode_state* s, const dyad_ode_system* sys, ode_work* w,
                                 dyad_real h, int k)
{
    int i, j, n = s->n;
    dyad_ode_status status = DYAD_ODE_OK;
    if (k == 0) {
        for (i = 0; i < n; ++i) {
            w->u[0][i] = w->f0[i];
        }
    } else {
        for (i = 0; i < n; ++i) {
            dyad_real arg = s->y[i];
            for (j = 0; j < k && j < 4; ++j) {
                arg += rodas_a[k < 5 ? k : 4][j] * w->u[j][i];
            }
            w->arg[i] = k == 5 ? arg + w->u[4][i] : arg;
        }
        status = ode_rhs(s, sys, s->t + rodas_c[k] * h, w->arg, w->u[k]);
    }
    for (i = 0; i < n; ++i) {
        dyad_real coupling = 0;
        for (j = 0; j < k; ++j) {
            coupling += rodas_cc[k][j] * w->u[j][i];
        }
        w->u[k][i] += coupling / h + h * rodas_d[k] * w->ft[i];
    }
    ode_lu_solve(n, w->lu, w->pivot, w->u[k]);
    return status;
}

/* All stages of a step of size h; the solution into w->ynew and the error
 * norm into *error. */
static dyad_ode_status ode_attempt(dyad_ode_state* s, const dyad_ode_system* sys, ode_work* w,
                                   dyad_real h, dyad_real* error)
{
    int i, k, n = s->n;
    dyad_real sum = 0, scale[DYAD_ODE_MAX_DIM];
    for (k = 0; k < ODE_STAGES; ++k) {
        dyad_ode_status status = ode_stage(s, sys, w, h, k);
        if (status != DYAD_ODE_OK) {
            return status;
        }
    }
    for (i = 0; i < n; ++i) {
        w->ynew[i] = w->arg[i] + w->u[5][i];
    }
    ode_scales(s, sys, w->ynew, scale);
    for (i = 0; i < n; ++i) {
        const dyad_real ratio = w->u[5][i] / scale[i];
        sum += ratio * ratio;
    }
    *error = sqrt(sum / n);
    return DYAD_ODE_OK;
}

/* x^(1/4) by two square roots, which IEEE 754 rounds correctly on every platform (pow is
 * the C library's own, and differs between them in its last bit): the same steps, so the
 * same bits, under Windows and Linux. */
static dyad_real ode_fourth_root(dyad_real x)
{
    return (dyad_real)sqrt(sqrt((double)x));
}

/* h / h_new from the error: err^(1/4) / safety, limited. */
static dyad_real ode_shrink(dyad_real error)
{
    dyad_real fac = isfinite(error) ? ode_fourth_root(error) / ODE_SAFETY : 1 / ODE_MIN_SHRINK;
    return fmax(1 / (dyad_real)DYAD_ODE_MAX_GROWTH, fmin(1 / ODE_MIN_SHRINK, fac));
}

/* The accepted step's next size, with Gustafsson's predictive factor. */
static dyad_real ode_next_step(dyad_ode_state* s, dyad_real h, dyad_real error)
{
    dyad_real fac = ode_shrink(error);
    if (s->h_accepted > 0) {
        dyad_real gus =
            (s->h_accepted / h) * ode_fourth_root(error * error / s->error_accepted) / ODE_SAFETY;
        gus = fmax(1 / (dyad_real)DYAD_ODE_MAX_GROWTH, fmin(1 / ODE_MIN_SHRINK, gus));
        fac = fmax(fac, gus);
    }
    s->h_accepted = h;
    s->error_accepted = fmax((dyad_real)1e-2, error);
    return fmin(h / fac, s->options.h_max);
}

/* Moves the state to the accepted step's end t_new and keeps its dense output. */
static void ode_accept(dyad_ode_state* s, const ode_work* w, dyad_real h, dyad_real t_new)
{
    int i, j, n = s->n;
    for (i = 0; i < n; ++i) {
        dyad_real d1 = 0, d2 = 0;
        for (j = 0; j < 5; ++j) {
            d1 += rodas_h[0][j] * w->u[j][i];
            d2 += rodas_h[1][j] * w->u[j][i];
        }
        s->d1[i] = d1;
        s->d2[i] = d2;
        s->y_last[i] = s->y[i];
        s->y[i] = w->ynew[i];
    }
    s->h_last = h;
    s->t = t_new;
    ++s->counters.accepted_steps;
}

/* ---- the call ------------------------------------------------------------------------------- */

/* The shortest step the error control may ask for at the state's time: the caller's
 * h_min and the resolution of the time. */
static dyad_real ode_shortest_step(const dyad_ode_state* s)
{
    return fmax(s->options.h_min, 16 * DYAD_REAL_EPSILON * fabs(s->t));
}

/* A first step from the sizes of y and f (Hairer, Norsett, Wanner I, II.4):
 * 1e-2 |y| / |f| in the error's norm, 1e-6 where either is too small; at least 256
 * times the shortest step, since a y barely above its tolerance (a start a few eps
 * from rest) makes |y| / |f| no guess at all: the error control shrinks a step too
 * long, down to the shortest, where it must. */
static dyad_real ode_first_step(const dyad_ode_state* s, const dyad_real* f0)
{
    int i;
    dyad_real ny = 0, nf = 0;
    if (s->options.h_initial > 0) {
        return s->options.h_initial;
    }
    for (i = 0; i < s->n; ++i) {
        dyad_real scale = ode_scale(s, i, s->y[i]);
        ny += (s->y[i] / scale) * (s->y[i] / scale);
        nf += (f0[i] / scale) * (f0[i] / scale);
    }
    ny = sqrt(ny / s->n);
    nf = sqrt(nf / s->n);
    return fmax(ny < 1e-5 || nf < 1e-5 ? (dyad_real)1e-6 : (dyad_real)1e-2 * ny / nf,
                256 * ode_shortest_step(s));
}

/* The fewest steps the controller could cover `span` in from step size h
 * (growth at most DYAD_ODE_MAX_GROWTH per step, at most h_max), counted up to
 * `limit` + 1: the growing steps one by one (a few dozen at most), those at
 * h_max at once. */
static long ode_fewest_steps(dyad_real h, dyad_real h_max, dyad_real span, long limit)
{
    long count = 0;
    dyad_real covered = 0;
    while (covered < span && count <= limit && h < h_max) {
        covered += h;
        h *= DYAD_ODE_MAX_GROWTH;
        ++count;
    }
    if (covered < span && count <= limit) {
        const double rest = ceil((double)((span - covered) / h_max));
        count = rest > (double)(limit - count) ? limit + 1 : count + (long)rest;
    }
    return count;
}

/* The step the next call starts with, +inf before the first if not set. */
static dyad_real ode_planned_step(const dyad_ode_state* s)
{
    if (s->h_next > 0) {
        return s->h_next;
    }
    return s->options.h_initial > 0 ? s->options.h_initial : (dyad_real)INFINITY;
}

static int ode_step_too_small(const dyad_ode_state* s, dyad_real h)
{
    return !(h >= ode_shortest_step(s)) || !(s->t + h != s->t);
}

/* One accepted step from the state's point toward t_end, with the attempts
 * it takes; *h is the step to try and becomes the next one's. *attempts
 * counts against max_steps. */
/* The size of the next attempt toward t_end from the proposed h: cut to end on t_end
 * (*last set) or refused, with t_failed, where the attempts are used up or the step is
 * below the time's resolution; counts the attempt. */
static dyad_ode_status ode_attempt_size(dyad_ode_state* s, dyad_real t_end, dyad_real h,
                                        long* attempts, dyad_real* try_h, int* last)
{
    const dyad_real left = t_end - s->t;
    *last = h >= left;
    *try_h = *last ? left : h;
    if (*attempts >= s->options.max_steps) {
        s->t_failed = s->t;
        return DYAD_ODE_TOO_MANY_STEPS;
    }
    if (!*last && ode_step_too_small(s, h)) {
        s->t_failed = s->t;
        return DYAD_ODE_STEP_UNDERFLOW;
    }
    ++*attempts;
    return DYAD_ODE_OK;
}

static dyad_ode_status ode_step(dyad_ode_state* s, const dyad_ode_system* sys, ode_work* w,
                                dyad_real t_end, dyad_real* h, long* attempts)
{
    int singular = 0, rejected = 0;
    for (;;) {
        dyad_real error, try_h;
        int last;
        dyad_ode_status status = ode_attempt_size(s, t_end, *h, attempts, &try_h, &last);
        if (status != DYAD_ODE_OK) {
            return status;
        }
        if (ode_iteration_matrix(s, w, try_h)) {
            if (++singular > DYAD_ODE_SINGULAR_RETRIES) {
                s->t_failed = s->t;
                return DYAD_ODE_SINGULAR;
            }
            *h = try_h / 2;
            continue;
        }
        status = ode_attempt(s, sys, w, try_h, &error);
        if (status != DYAD_ODE_OK) {
            return status;
        }
        if (error <= 1) {
            dyad_real next = ode_next_step(s, try_h, error);
            next = rejected ? fmin(next, try_h) : next;
            /* A step shortened to end on t_end keeps the size proposed before. */
            *h = last && try_h < *h ? fmax(*h, next) : next;
            ode_accept(s, w, try_h, last ? t_end : s->t + try_h);
            return DYAD_ODE_OK;
        }
        ++s->counters.rejected_steps;
        rejected = 1;
        *h = s->counters.accepted_steps == 0 ? try_h / 10 : try_h / ode_shrink(error);
    }
}

/* The step the next attempts start from: the one proposed, or a first one from f0, at most
 * h_max; TOO_MANY_STEPS (with t_failed) where the controller's limits already prove that
 * the attempts left cannot reach t_end. */
static dyad_ode_status ode_planned_next(dyad_ode_state* s, const dyad_real* f0, dyad_real t_end,
                                        long attempts, dyad_real* h)
{
    const long left = s->options.max_steps - attempts;
    *h = fmin(s->h_next > 0 ? s->h_next : ode_first_step(s, f0), s->options.h_max);
    if (ode_fewest_steps(*h, s->options.h_max, t_end - s->t, left) > left) {
        s->t_failed = s->t;
        return DYAD_ODE_TOO_MANY_STEPS;
    }
    return DYAD_ODE_OK;
}

/* ---- the explicit method: DOP853 -------------------------------------------------------------
 *
 * Where the problem is not stiff (a mechanism driven by an effort, a motor whose L / R is
 * not far below the motion's time scale) a Rosenbrock step's linear algebra and Jacobian
 * buy nothing, and order 4 makes its steps short at tight tolerances: the step grows as
 * rtol^(1/4). DOP853 (Dormand and Prince's explicit Runge-Kutta method of order 8, E.
 * Hairer, S. P. Norsett, G. Wanner, Solving Ordinary Differential Equations I, 2nd ed.,
 * Springer 1993, section II.10, and their code dop853.f) grows as rtol^(1/8): twelve
 * evaluations of f per step (the last, at the step's end, is the next step's first) and
 * no Jacobian. Its error estimate combines embedded solutions of order 5 and 3,
 *      err = |h| |e5|^2 / sqrt(|e5|^2 + 0.01 |e3|^2)
 * in the root mean square norm of atol + rtol max(|y0|, |y1|) (dop853.f's), accepted
 * at <= 1; the next step is h / fac, fac = err^(1/8) / 0.9 limited to [1/2, 3] (no
 * growth right after a rejection); err^(1/8) is three square roots, which every platform
 * rounds alike. The step at most doubles (dop853.f allows 6): the estimate can vanish by
 * chance where e5 passes through zero, and a step grown sixfold on such a chance may
 * leave the range where the estimate holds at all (on the slider-crank at 300 rad/s, a
 * 4.6 ms step estimated at 0.3 of its tolerance was 7,000 times over it). Its continuous
 * output is the cubic Hermite interpolant of y and f at the step's ends, of order 3, in the
 * form dyad_ode_dense() evaluates. The coefficients are dop853.f's, as the tests check (the
 * order 8 measured on exact solutions). */
#define DOP_STAGES     12
#define DOP_MIN_SHRINK ((dyad_real)(1.0 / 3.0))
#define DOP_MAX_GROWTH ((dyad_real)2)

static const dyad_real dop_c[DOP_STAGES] = {0.0,
                                            0.05260015195876773,
                                            0.0789002279381516,
                                            0.1183503419072274,
                                            0.2816496580927726,
                                            0.3333333333333333,
                                            0.25,
                                            0.3076923076923077,
                                            0.6512820512820513,
                                            0.6,
                                            0.8571428571428571,
                                            1.0};
/* a_ij, row i the stage, j < i (the rest 0) */
static const dyad_real dop_a[DOP_STAGES][DOP_STAGES - 1] = {
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.05260015195876773, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.0197250569845379, 0.0591751709536137, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.02958758547680685, 0.0, 0.08876275643042054, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
     0.0},
    {0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242, 0.0, 0.0, 0.0, 0.0,
     0.0, 0.0},
    {0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125, 0.0, 0.0, 0.0,
     0.0, 0.0},
    {0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402,
     0.008273789163814023, 0.0, 0.0, 0.0, 0.0},
    {0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726, 27.59209969944671,
     20.154067550477894, -43.48988418106996, 0.0, 0.0, 0.0},
    {0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843, 21.230051448181193,
     15.279233632882423, -33.28821096898486, -0.020331201708508627, 0.0, 0.0},
    {-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295, -8.149787010746927,
     -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196, 0.0},
    {2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625, -17.9589318631188,
     27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303,
     0.6433927460157636},
};
static const dyad_real dop_b[DOP_STAGES] = {0.054293734116568765,
                                            0.0,
                                            0.0,
                                            0.0,
                                            0.0,
                                            4.450312892752409,
                                            1.8915178993145003,
                                            -5.801203960010585,
                                            0.3111643669578199,
                                            -0.1521609496625161,
                                            0.20136540080403034,
                                            0.04471061572777259};
/* the error estimates of order 5 and 3: differences of the order-8 solution from them */
static const dyad_real dop_e5[DOP_STAGES] = {0.01312004499419488,
                                             0.0,
                                             0.0,
                                             0.0,
                                             0.0,
                                             -1.2251564463762044,
                                             -0.4957589496572502,
                                             1.6643771824549864,
                                             -0.35032884874997366,
                                             0.3341791187130175,
                                             0.08192320648511571,
                                             -0.022355307863886294};
static const dyad_real dop_e3[DOP_STAGES] = {-0.18980075407240762,
                                             0.0,
                                             0.0,
                                             0.0,
                                             0.0,
                                             4.450312892752409,
                                             1.8915178993145003,
                                             -5.801203960010585,
                                             -0.4226823213237919,
                                             -0.1521609496625161,
                                             0.20136540080403034,
                                             0.02265179219836082};

/* The stages of a step, k[0] = f(t, y) given; k[DOP_STAGES] is f at the step's end, for
 * the next step and the continuous output. */
typedef struct dop_work {
    dyad_real k[DOP_STAGES + 1][DYAD_ODE_MAX_DIM];
    dyad_real arg[DYAD_ODE_MAX_DIM];
    dyad_real ynew[DYAD_ODE_MAX_DIM];
    dyad_real e5[DYAD_ODE_MAX_DIM]; /* the embedded errors of orders 5 and 3 */
    dyad_real e3[DYAD_ODE_MAX_DIM];
} dop_work;

/* One attempt from (t, y) with step h: the solution in w->ynew and its error. */
static dyad_ode_status dop_attempt(dyad_ode_state* s, const dyad_ode_system* sys, dop_work* w,
                                   dyad_real h, dyad_real* error)
{
    int i, j, k, n = s->n;
    dyad_real e5 = 0, e3 = 0, scale[DYAD_ODE_MAX_DIM];
    for (k = 1; k < DOP_STAGES; ++k) {
        for (i = 0; i < n; ++i) {
            dyad_real sum = 0;
            for (j = 0; j < k; ++j) {
                sum += dop_a[k][j] * w->k[j][i];
            }
            w->arg[i] = s->y[i] + h * sum;
        }
        const dyad_ode_status status = ode_rhs(s, sys, s->t + dop_c[k] * h, w->arg, w->k[k]);
        if (status != DYAD_ODE_OK) {
            return status;
        }
    }
    for (i = 0; i < n; ++i) {
        dyad_real sum = 0, d5 = 0, d3 = 0;
        for (j = 0; j < DOP_STAGES; ++j) {
            sum += dop_b[j] * w->k[j][i];
            d5 += dop_e5[j] * w->k[j][i];
            d3 += dop_e3[j] * w->k[j][i];
        }
        w->ynew[i] = s->y[i] + h * sum;
        w->e5[i] = d5;
        w->e3[i] = d3;
    }
    ode_scales(s, sys, w->ynew, scale);
    for (i = 0; i < n; ++i) {
        e5 += (w->e5[i] / scale[i]) * (w->e5[i] / scale[i]);
        e3 += (w->e3[i] / scale[i]) * (w->e3[i] / scale[i]);
    }
    /* not finite where the stages overflow: rejected, the step shrinks */
    *error = e5 > 0 ? fabs(h) * e5 / sqrt((e5 + (dyad_real)0.01 * e3) * n) : 0;
    return DYAD_ODE_OK;
}

/* h / h_new from the error: err^(1/8) / safety, limited. */
static dyad_real dop_shrink(dyad_real error)
{
    dyad_real fac = isfinite(error) ? (dyad_real)sqrt(sqrt(sqrt((double)error))) / ODE_SAFETY
                                    : 1 / DOP_MIN_SHRINK;
    return fmax(1 / DOP_MAX_GROWTH, fmin(1 / DOP_MIN_SHRINK, fac));
}

/* Moves the state to the accepted step's end: f there (the next step's first stage), the
 * continuous output's differences from it. */
static dyad_ode_status dop_accept(dyad_ode_state* s, const dyad_ode_system* sys, dop_work* w,
                                  dyad_real h, dyad_real t_new)
{
    int i, n = s->n;
    dyad_ode_status status = ode_rhs(s, sys, t_new, w->ynew, w->k[DOP_STAGES]);
    if (status != DYAD_ODE_OK) {
        return status;
    }
    for (i = 0; i < n; ++i) {
        const dyad_real rise = w->ynew[i] - s->y[i];
        s->d1[i] = h * w->k[0][i] - rise;
        s->d2[i] = 2 * rise - h * (w->k[0][i] + w->k[DOP_STAGES][i]);
        s->y_last[i] = s->y[i];
        s->y[i] = w->ynew[i];
        w->k[0][i] = w->k[DOP_STAGES][i];
    }
    s->h_last = h;
    s->t = t_new;
    ++s->counters.accepted_steps;
    return DYAD_ODE_OK;
}

/* One accepted step toward t_end, with the attempts it takes; *h the step proposed. */
static dyad_ode_status dop_step(dyad_ode_state* s, const dyad_ode_system* sys, dop_work* w,
                                dyad_real t_end, dyad_real* h, long* attempts)
{
    int rejected = 0;
    for (;;) {
        dyad_real error, try_h;
        int last;
        dyad_ode_status status = ode_attempt_size(s, t_end, *h, attempts, &try_h, &last);
        if (status != DYAD_ODE_OK) {
            return status;
        }
        status = dop_attempt(s, sys, w, try_h, &error);
        if (status != DYAD_ODE_OK) {
            return status;
        }
        if (error <= 1) {
            dyad_real next = fmin(try_h / dop_shrink(error), s->options.h_max);
            next = rejected ? fmin(next, try_h) : next;
            *h = last && try_h < *h ? fmax(*h, next) : next;
            return dop_accept(s, sys, w, try_h, last ? t_end : s->t + try_h);
        }
        ++s->counters.rejected_steps;
        rejected = 1;
        *h = try_h / dop_shrink(error);
    }
}

/* The step proposed next, finite: where every error is 0 (a state at rest) each step grows
 * by the controller's largest factor, which over a span near the largest number would
 * carry it to infinity. */
static dyad_real ode_finite_step(dyad_real h)
{
    return fmin(h, DYAD_REAL_MAX);
}

/* dyad_ode_advance() with DOP853, its arguments checked. */
static dyad_ode_status dop_advance(dyad_ode_state* state, const dyad_ode_system* system,
                                   dyad_real t_end)
{
    dop_work w;
    long attempts = 0;
    dyad_ode_status status = ode_rhs(state, system, state->t, state->y, w.k[0]);
    while (status == DYAD_ODE_OK && state->t < t_end) {
        dyad_real h;
        status = ode_planned_next(state, w.k[0], t_end, attempts, &h);
        if (status == DYAD_ODE_OK) {
            status = dop_step(state, system, &w, t_end, &h, &attempts);
            state->h_next = ode_finite_step(h);
        }
    }
    return status;
}

static dyad_ode_status ode_finish(dyad_ode_state* s, dyad_ode_status status)
{
    s->status = status;
    return status;
}

dyad_ode_status dyad_ode_advance(dyad_ode_state* state, const dyad_ode_system* system,
                                 dyad_real t_end)
{
    ode_work w;
    long attempts = 0;
    dyad_ode_status status = DYAD_ODE_OK;
    if (state == NULL) {
        return DYAD_ODE_INVALID_ARGUMENT;
    }
    if (system == NULL || system->rhs == NULL || system->n != state->n || state->n < 1 ||
        state->n > DYAD_ODE_MAX_DIM || !ode_options_valid(&state->options) ||
        !(t_end >= state->t) || !isfinite(t_end)) {
        return ode_finish(state, DYAD_ODE_INVALID_ARGUMENT);
    }
    if (ode_fewest_steps(ode_planned_step(state), state->options.h_max, t_end - state->t,
                         state->options.max_steps) > state->options.max_steps) {
        state->t_failed = state->t;
        return ode_finish(state, DYAD_ODE_TOO_MANY_STEPS);
    }
    if (state->options.method == DYAD_ODE_DOP853) {
        return ode_finish(state, state->t < t_end ? dop_advance(state, system, t_end) : status);
    }
    while (status == DYAD_ODE_OK && state->t < t_end) {
        dyad_real h;
        status = ode_linearise(state, system, &w);
        if (status == DYAD_ODE_OK) {
            status = ode_planned_next(state, w.f0, t_end, attempts, &h);
        }
        if (status == DYAD_ODE_OK) {
            status = ode_step(state, system, &w, t_end, &h, &attempts);
            state->h_next = ode_finite_step(h);
        }
    }
    return ode_finish(state, status);
}

dyad_ode_status dyad_ode_dense(const dyad_ode_state* state, dyad_real t, dyad_real* y,
                               dyad_real* dydt)
{
    int i;
    dyad_real t0, s;
    if (state == NULL || !(state->h_last > 0)) {
        return DYAD_ODE_INVALID_ARGUMENT;
    }
    t0 = state->t - state->h_last;
    if (!(t >= t0 && t <= state->t)) {
        return DYAD_ODE_INVALID_ARGUMENT;
    }
    s = (t - t0) / state->h_last;
    for (i = 0; i < state->n; ++i) {
        dyad_real y0 = state->y_last[i], y1 = state->y[i], d1 = state->d1[i], d2 = state->d2[i];
        if (y != NULL) {
            y[i] = (1 - s) * y0 + s * (y1 + (1 - s) * (d1 + s * d2));
        }
        if (dydt != NULL) {
            dydt[i] = (y1 - y0 + (1 - 2 * s) * d1 + s * (2 - 3 * s) * d2) / state->h_last;
        }
    }
    return DYAD_ODE_OK;
}
