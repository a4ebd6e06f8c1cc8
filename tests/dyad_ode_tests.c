/* dyadfmu: tests of the integrator (dyadfmu/ode.h, src/dyad_ode.c).
 *
 * Against exact solutions (a linear system, a stiff forced decay, a limit
 * cycle), its order measured with fixed steps, against GSL's odeiv2 (rk8pd
 * and msbdf at tight tolerances: a pendulum, Van der Pol at mu = 1e3 and a
 * DC motor driving an unbalanced flywheel with viscous friction, L/R = 1e-3 s
 * and 1e-6 s), its reproducibility, and every failure it reports. GSL is the
 * reference only: without it (DYAD_ODE_TESTS_GSL undefined) those tests say
 * so and pass.
 *
 * Usage: dyad_ode_tests [test-name ...]   (no name: run them all; -v prints
 * the measured numbers)
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dyadfmu/ode.h"
#include "named_tests.h"

#ifdef DYAD_ODE_TESTS_GSL
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#endif

static int verbose = 0;

#define REPORT(...)                     \
    do {                                \
        if (verbose) {                  \
            printf("    " __VA_ARGS__); \
        }                               \
    } while (0)

/* ---- the problems ------------------------------------------------------------------------- */

/* y' = A y, A block-diagonal: a decaying oscillation (-1 +- 2i) and a fast
 * decay -1e4 coupled into it by nothing, so exp(A t) is known. */
static int linear_rhs(void* user, double t, const double* y, double* f)
{
    (void)user;
    (void)t;
    f[0] = -y[0] + 2 * y[1];
    f[1] = -2 * y[0] - y[1];
    f[2] = -1e4 * y[2];
    return 0;
}

static int linear_jacobian(void* user, double t, const double* y, const double* f, double* jac,
                           double* dfdt)
{
    static const double a[9] = {-1, 2, 0, -2, -1, 0, 0, 0, -1e4};
    (void)user, (void)t, (void)y, (void)f;
    memcpy(jac, a, sizeof a);
    dfdt[0] = dfdt[1] = dfdt[2] = 0;
    return 0;
}

static void linear_exact(double t, double* y)
{
    double e = exp(-t);
    y[0] = e * (cos(2 * t) + 0.5 * sin(2 * t));
    y[1] = e * (-sin(2 * t) + 0.5 * cos(2 * t));
    y[2] = exp(-1e4 * t);
}

/* y' = -lambda (y - cos t): y = (lambda^2 cos t + lambda sin t) / (lambda^2 + 1)
 * + (y0 - lambda^2 / (lambda^2 + 1)) exp(-lambda t). */
static int forced_rhs(void* user, double t, const double* y, double* f)
{
    f[0] = -*(const double*)user * (y[0] - cos(t));
    return 0;
}

static int forced_jacobian(void* user, double t, const double* y, const double* f, double* jac,
                           double* dfdt)
{
    double lambda = *(const double*)user;
    (void)y, (void)f;
    jac[0] = -lambda;
    dfdt[0] = -lambda * sin(t);
    return 0;
}

static double forced_exact(double lambda, double y0, double t)
{
    double l2 = lambda * lambda;
    return (l2 * cos(t) + lambda * sin(t)) / (l2 + 1) + (y0 - l2 / (l2 + 1)) * exp(-lambda * t);
}

/* The limit cycle r' = r (1 - r^2), theta' = 1 in Cartesian form, nonlinear:
 * r(t) = 1 / sqrt(1 + (1 / r0^2 - 1) exp(-2 t)). */
static int cycle_rhs(void* user, double t, const double* y, double* f)
{
    double g = 1 - y[0] * y[0] - y[1] * y[1];
    (void)user, (void)t;
    f[0] = -y[1] + y[0] * g;
    f[1] = y[0] + y[1] * g;
    return 0;
}

static int cycle_jacobian(void* user, double t, const double* y, const double* f, double* jac,
                          double* dfdt)
{
    double g = 1 - y[0] * y[0] - y[1] * y[1];
    (void)user, (void)t, (void)f;
    jac[0] = g - 2 * y[0] * y[0];
    jac[1] = -1 - 2 * y[0] * y[1];
    jac[2] = 1 - 2 * y[0] * y[1];
    jac[3] = g - 2 * y[1] * y[1];
    dfdt[0] = dfdt[1] = 0;
    return 0;
}

static void cycle_exact(double t, double* y)
{
    double r0 = 0.5, r = 1 / sqrt(1 + (1 / (r0 * r0) - 1) * exp(-2 * t));
    y[0] = r * cos(t);
    y[1] = r * sin(t);
}

/* The pendulum theta'' = -(g / l) sin theta, g / l = 9.81. */
static int pendulum_rhs(void* user, double t, const double* y, double* f)
{
    (void)user, (void)t;
    f[0] = y[1];
    f[1] = -9.81 * sin(y[0]);
    return 0;
}

/* Van der Pol: y0'' = mu (1 - y0^2) y0' - y0. */
static int vdp_rhs(void* user, double t, const double* y, double* f)
{
    double mu = *(const double*)user;
    (void)t;
    f[0] = y[1];
    f[1] = mu * (1 - y[0] * y[0]) * y[1] - y[0];
    return 0;
}

static int vdp_jacobian(void* user, double t, const double* y, const double* f, double* jac,
                        double* dfdt)
{
    double mu = *(const double*)user;
    (void)t, (void)f;
    jac[0] = 0;
    jac[1] = 1;
    jac[2] = -2 * mu * y[0] * y[1] - 1;
    jac[3] = mu * (1 - y[0] * y[0]);
    dfdt[0] = dfdt[1] = 0;
    return 0;
}

/* A DC motor driving a flywheel with an unbalance (m g r sin theta) and
 * viscous friction, the supply voltage varying; states theta, omega, i:
 *      J omega' = k i - b omega - m g r sin theta,
 *      L i' = V(t) - R i - k omega,   V(t) = 12 + 3 sin(4 pi t). */
typedef struct motor {
    double resistance, inductance, k, inertia, friction, unbalance;
} motor;

static motor motor_with(double l_over_r)
{
    motor m;
    m.resistance = 1;
    m.inductance = l_over_r;
    m.k = 0.05;
    m.inertia = 1e-4;
    m.friction = 1e-4;
    m.unbalance = 0.02;
    return m;
}

static double motor_voltage(double t)
{
    return 12 + 3 * sin(4 * 3.14159265358979323846 * t);
}

static int motor_rhs(void* user, double t, const double* y, double* f)
{
    const motor* m = (const motor*)user;
    f[0] = y[1];
    f[1] = (m->k * y[2] - m->friction * y[1] - m->unbalance * sin(y[0])) / m->inertia;
    f[2] = (motor_voltage(t) - m->resistance * y[2] - m->k * y[1]) / m->inductance;
    return 0;
}

static int motor_jacobian(void* user, double t, const double* y, const double* f, double* jac,
                          double* dfdt)
{
    const motor* m = (const motor*)user;
    (void)f;
    memset(jac, 0, 9 * sizeof *jac);
    jac[1] = 1;
    jac[3] = -m->unbalance * cos(y[0]) / m->inertia;
    jac[4] = -m->friction / m->inertia;
    jac[5] = m->k / m->inertia;
    jac[7] = -m->k / m->inductance;
    jac[8] = -m->resistance / m->inductance;
    dfdt[0] = dfdt[1] = 0;
    dfdt[2] = 3 * 4 * 3.14159265358979323846 * cos(4 * 3.14159265358979323846 * t) / m->inductance;
    return 0;
}

/* ---- helpers ------------------------------------------------------------------------------ */

static dyad_ode_system system_of(int n, dyad_ode_rhs rhs, dyad_ode_jacobian jac, void* user)
{
    dyad_ode_system s;
    s.n = n;
    s.rhs = rhs;
    s.jacobian = jac;
    s.autonomous = 0;
    s.error_magnitude = NULL;
    s.user = user;
    return s;
}

static dyad_ode_options tolerances(double rtol, double atol)
{
    dyad_ode_options o = dyad_ode_options_default();
    o.rtol = rtol;
    o.atol = atol;
    return o;
}

/* Integrates over `count` communication steps of dt from (0, y0); the states
 * at the steps' ends into out[(k + 1) * n ...] (out[0..n) = y0). */
static dyad_ode_status run_grid(dyad_ode_state* s, const dyad_ode_system* sys, const double* y0,
                                const dyad_ode_options* o, double dt, int count, double* out)
{
    int k, n = sys->n;
    dyad_ode_status status = dyad_ode_init(s, n, 0, y0, o);
    memcpy(out, y0, (size_t)n * sizeof *out);
    for (k = 1; k <= count && status == DYAD_ODE_OK; ++k) {
        status = dyad_ode_advance(s, sys, k * dt);
        memcpy(out + k * n, s->y, (size_t)n * sizeof *out);
    }
    return status;
}

/* ---- (a) exact solutions ------------------------------------------------------------------ */

/* The linear system under error control, by `method`: within the tolerance at every
 * communication point, and not suspiciously better; the continuous output halfway
 * through the last step within the tolerance too. */
static int linear_exact_by(dyad_ode_method method, const char* name)
{
    int fails = 0, r, k, i;
    static const double rtols[3] = {1e-6, 1e-8, 1e-10};
    dyad_ode_system sys = system_of(3, linear_rhs, linear_jacobian, NULL);
    sys.autonomous = 1;
    for (r = 0; r < 3; ++r) {
        double y0[3], out[51 * 3], worst = 0, exact[3], y[3], middle;
        dyad_ode_state s;
        dyad_ode_options o = tolerances(rtols[r], rtols[r] * 1e-2);
        o.method = method;
        linear_exact(0, y0);
        CHECK(run_grid(&s, &sys, y0, &o, 0.1, 50, out) == DYAD_ODE_OK, "status");
        for (k = 1; k <= 50; ++k) {
            linear_exact(0.1 * k, exact);
            for (i = 0; i < 3; ++i) {
                worst = fmax(worst, fabs(out[k * 3 + i] - exact[i]));
            }
        }
        middle = s.t - 0.5 * s.h_last;
        CHECK(dyad_ode_dense(&s, middle, y, NULL) == DYAD_ODE_OK, "dense");
        linear_exact(middle, exact);
        REPORT("%s rtol %.0e: max error %.2e, %ld steps, %ld f; dense %.1e\n", name, rtols[r],
               worst, s.counters.accepted_steps, s.counters.rhs_evaluations, fabs(y[0] - exact[0]));
        CHECK(worst < rtols[r], "rtol %g: error %g", rtols[r], worst);
        CHECK(worst > 1e-3 * rtols[r], "rtol %g: error %g suspiciously small", rtols[r], worst);
        CHECK(fabs(y[0] - exact[0]) < rtols[r], "dense error %g", fabs(y[0] - exact[0]));
    }
    return fails;
}

static int test_linear_exact(void)
{
    return linear_exact_by(DYAD_ODE_RODASP, "RODASP");
}

static int test_stiff_forced(void)
{
    int fails = 0, k, with_fd;
    double lambda = 1e6;
    for (with_fd = 0; with_fd < 2; ++with_fd) {
        dyad_ode_system sys = system_of(1, forced_rhs, with_fd ? NULL : forced_jacobian, &lambda);
        dyad_ode_options o = tolerances(1e-8, 1e-10);
        dyad_ode_state s;
        double y0 = 0, out[101], worst = 0;
        CHECK(run_grid(&s, &sys, &y0, &o, 0.1, 100, out) == DYAD_ODE_OK, "status");
        for (k = 1; k <= 100; ++k) {
            worst = fmax(worst, fabs(out[k] - forced_exact(lambda, 0, 0.1 * k)));
        }
        REPORT("lambda 1e6 (%s J): max error %.2e, %ld steps (%ld rejected), %ld f\n",
               with_fd ? "difference" : "exact", worst, s.counters.accepted_steps,
               s.counters.rejected_steps, s.counters.rhs_evaluations);
        CHECK(worst < 1e-8, "error %g", worst);
        /* Stable far beyond 1 / lambda: an explicit method would need 1e7 steps. */
        CHECK(s.counters.accepted_steps < 400, "%ld steps", s.counters.accepted_steps);
    }
    return fails;
}

/* The error at t = 2 of fixed steps h (rtol so loose every step passes). */
static double fixed_step_error(const dyad_ode_system* sys, const double* y0, const double* exact,
                               double h)
{
    int i;
    double worst = 0;
    dyad_ode_state s;
    dyad_ode_options o = tolerances(1e20, 1e20);
    o.h_initial = o.h_max = h;
    dyad_ode_init(&s, sys->n, 0, y0, &o);
    dyad_ode_advance(&s, sys, 2);
    for (i = 0; i < sys->n; ++i) {
        worst = fmax(worst, fabs(s.y[i] - exact[i]));
    }
    return worst;
}

static int test_order_four(void)
{
    int fails = 0, p;
    double lambda = 10, cycle0[2], cycle2[2], forced0 = 1, forced2 = forced_exact(10, 1, 2);
    dyad_ode_system problems[2];
    problems[0] = system_of(2, cycle_rhs, cycle_jacobian, NULL);
    problems[1] = system_of(1, forced_rhs, forced_jacobian, &lambda);
    cycle_exact(0, cycle0);
    cycle_exact(2, cycle2);
    for (p = 0; p < 2; ++p) {
        const double* y0 = p == 0 ? cycle0 : &forced0;
        const double* exact = p == 0 ? cycle2 : &forced2;
        double e1 = fixed_step_error(&problems[p], y0, exact, 0.02);
        double e2 = fixed_step_error(&problems[p], y0, exact, 0.01);
        double order = log2(e1 / e2);
        REPORT("%s: error %.3e at h 0.02, %.3e at 0.01: order %.2f\n",
               p == 0 ? "limit cycle" : "forced, lambda 10", e1, e2, order);
        CHECK(order > 3.7 && order < 4.5, "problem %d: order %g", p, order);
    }
    return fails;
}

/* The continuous output inside each step against the exact solution. */
static int test_dense_output(void)
{
    int fails = 0, k, j;
    double y0[2], exact[2], y[2], dydt[2], f[2], worst = 0, worst_rate = 0;
    dyad_ode_system sys = system_of(2, cycle_rhs, cycle_jacobian, NULL);
    dyad_ode_options o = tolerances(1e-8, 1e-10);
    dyad_ode_state s;
    cycle_exact(0, y0);
    dyad_ode_init(&s, 2, 0, y0, &o);
    CHECK(dyad_ode_dense(&s, 0, y, NULL) == DYAD_ODE_INVALID_ARGUMENT, "no step yet");
    for (k = 1; k <= 40; ++k) {
        CHECK(dyad_ode_advance(&s, &sys, 0.25 * k) == DYAD_ODE_OK, "status");
        for (j = 0; j <= 4; ++j) {
            double t = s.t - s.h_last * j / 4.0;
            CHECK(dyad_ode_dense(&s, t, y, dydt) == DYAD_ODE_OK, "dense at %g", t);
            cycle_exact(t, exact);
            cycle_rhs(NULL, t, exact, f);
            worst = fmax(worst, fmax(fabs(y[0] - exact[0]), fabs(y[1] - exact[1])));
            worst_rate = fmax(worst_rate, fmax(fabs(dydt[0] - f[0]), fabs(dydt[1] - f[1])));
        }
    }
    REPORT("dense output: error %.2e, of its derivative %.2e\n", worst, worst_rate);
    CHECK(worst < 5e-8, "dense error %g", worst);
    CHECK(worst_rate < 1e-6, "dense derivative error %g", worst_rate);
    CHECK(dyad_ode_dense(&s, s.t + 1e-9, y, NULL) == DYAD_ODE_INVALID_ARGUMENT, "after t");
    return fails;
}

/* ---- (c) the explicit method, DOP853 ----------------------------------------------------- */

/* The error at t = 2 of fixed steps h of DOP853. */
static double dop_fixed_step_error(const dyad_ode_system* sys, const double* y0,
                                   const double* exact, double h)
{
    int i;
    double worst = 0;
    dyad_ode_state s;
    dyad_ode_options o = tolerances(1e20, 1e20);
    o.h_initial = o.h_max = h;
    o.method = DYAD_ODE_DOP853;
    dyad_ode_init(&s, sys->n, 0, y0, &o);
    dyad_ode_advance(&s, sys, 2);
    for (i = 0; i < sys->n; ++i) {
        worst = fmax(worst, fabs(s.y[i] - exact[i]));
    }
    return worst;
}

/* Order 8: the error of fixed steps falls 256 times per halving (the limit cycle, where
 * round-off stays far below it at these steps). */
static int test_dop_order_eight(void)
{
    int fails = 0;
    double y0[2], exact[2], e1, e2, order;
    dyad_ode_system sys = system_of(2, cycle_rhs, NULL, NULL);
    cycle_exact(0, y0);
    cycle_exact(2, exact);
    e1 = dop_fixed_step_error(&sys, y0, exact, 0.2);
    e2 = dop_fixed_step_error(&sys, y0, exact, 0.1);
    order = log2(e1 / e2);
    REPORT("DOP853, limit cycle: error %.3e at h 0.2, %.3e at 0.1: order %.2f\n", e1, e2, order);
    CHECK(order > 7.5 && order < 8.8, "order %g", order);
    return fails;
}

/* The stiff block (-1e4) holds DOP853 to its stability limit whatever the tolerance
 * (about 7,900 steps), and its result is still within the tolerance. */
static int test_dop_linear_exact(void)
{
    return linear_exact_by(DYAD_ODE_DOP853, "DOP853");
}

/* ---- (b) against GSL ---------------------------------------------------------------------- */

#ifdef DYAD_ODE_TESTS_GSL

typedef struct gsl_bridge {
    const dyad_ode_system* sys;
} gsl_bridge;

static int gsl_function_of(double t, const double y[], double f[], void* params)
{
    const dyad_ode_system* sys = ((const gsl_bridge*)params)->sys;
    return sys->rhs(sys->user, t, y, f) == 0 ? GSL_SUCCESS : GSL_EBADFUNC;
}

static int gsl_jacobian_of(double t, const double y[], double* dfdy, double dfdt[], void* params)
{
    const dyad_ode_system* sys = ((const gsl_bridge*)params)->sys;
    double f[DYAD_ODE_MAX_DIM];
    sys->rhs(sys->user, t, y, f);
    return sys->jacobian(sys->user, t, y, f, dfdy, dfdt) == 0 ? GSL_SUCCESS : GSL_EBADFUNC;
}

/* GSL's solution on the grid k dt, k = 0..count, into out. */
static int gsl_reference(const dyad_ode_system* sys, const gsl_odeiv2_step_type* type, double tol,
                         const double* y0, double dt, int count, double* out)
{
    int k, n = sys->n, status = GSL_SUCCESS;
    double t = 0, y[DYAD_ODE_MAX_DIM];
    gsl_bridge bridge;
    gsl_odeiv2_system gsys;
    gsl_odeiv2_driver* driver;
    bridge.sys = sys;
    gsys.function = gsl_function_of;
    gsys.jacobian = gsl_jacobian_of;
    gsys.dimension = (size_t)n;
    gsys.params = &bridge;
    driver = gsl_odeiv2_driver_alloc_y_new(&gsys, type, 1e-8, tol, tol);
    gsl_odeiv2_driver_set_nmax(driver, 0);
    memcpy(y, y0, (size_t)n * sizeof *y);
    memcpy(out, y0, (size_t)n * sizeof *out);
    for (k = 1; k <= count && status == GSL_SUCCESS; ++k) {
        status = gsl_odeiv2_driver_apply(driver, &t, k * dt, y);
        memcpy(out + k * n, y, (size_t)n * sizeof *out);
    }
    gsl_odeiv2_driver_free(driver);
    return status;
}

/* The largest difference per component over the grid, each divided by
 * scale[i]. */
static double grid_error(int n, int count, const double* a, const double* b, const double* scale)
{
    int k, i;
    double worst = 0;
    for (k = 0; k <= count; ++k) {
        for (i = 0; i < n; ++i) {
            worst = fmax(worst, fabs(a[k * n + i] - b[k * n + i]) / scale[i]);
        }
    }
    return worst;
}

/* The pendulum by `method` at rtol 1e-6, 1e-8 and 1e-10 on a grid of `count` steps of dt,
 * against GSL's rk8pd at 1e-14: the error within 1e3 rtol and falling tenfold per
 * tolerance. f[k] gets each run's evaluations of f, a difference Jacobian's excepted. */
static int pendulum_against_gsl(dyad_ode_method method, double dt, int count, long* f)
{
    int fails = 0, r;
    double y0[2] = {2.5, 0}, ref[201 * 2], out[201 * 2], unit[2] = {1, 1}, last = 1;
    const char* name = method == DYAD_ODE_DOP853 ? "DOP853" : "RODASP";
    dyad_ode_system sys = system_of(2, pendulum_rhs, NULL, NULL);
    sys.autonomous = 1;
    CHECK(count <= 200, "grid of %d steps", count);
    CHECK(gsl_reference(&sys, gsl_odeiv2_step_rk8pd, 1e-14, y0, dt, count, ref) == GSL_SUCCESS,
          "rk8pd");
    for (r = 6; r <= 10; r += 2) {
        dyad_ode_state s;
        dyad_ode_options o = tolerances(pow(10, -r), pow(10, -r - 2));
        double error;
        o.method = method;
        CHECK(run_grid(&s, &sys, y0, &o, dt, count, out) == DYAD_ODE_OK, "status");
        error = grid_error(2, count, out, ref, unit);
        f[(r - 6) / 2] = s.counters.rhs_evaluations - 2 * s.counters.jacobian_evaluations;
        REPORT("%s pendulum on a grid of %g s, rtol 1e-%d: error %.2e, %ld steps (%ld "
               "rejected), %ld f\n",
               name, dt, r, error, s.counters.accepted_steps, s.counters.rejected_steps,
               s.counters.rhs_evaluations);
        CHECK(error < 1e3 * pow(10, -r), "%s rtol 1e-%d: error %g", name, r, error);
        CHECK(error < last / 10, "%s rtol 1e-%d: error %g does not fall", name, r, error);
        last = error;
    }
    return fails;
}

static int test_gsl_pendulum(void)
{
    long f[3];
    return pendulum_against_gsl(DYAD_ODE_RODASP, 0.05, 200, f);
}

/* On a grid of 1 s (on a finer one the grid, not the tolerance, would set DOP853's steps),
 * DOP853 takes fewer evaluations of f at every tolerance than RODASP's stages alone. */
static int test_dop_gsl_pendulum(void)
{
    int fails = 0, k;
    long explicit_f[3], rosenbrock_f[3];
    fails += pendulum_against_gsl(DYAD_ODE_DOP853, 1.0, 20, explicit_f);
    fails += pendulum_against_gsl(DYAD_ODE_RODASP, 1.0, 20, rosenbrock_f);
    for (k = 0; k < 3; ++k) {
        CHECK(explicit_f[k] < rosenbrock_f[k], "rtol 1e-%d: DOP853 %ld f, RODASP %ld", 6 + 2 * k,
              explicit_f[k], rosenbrock_f[k]);
    }
    return fails;
}

static int test_gsl_van_der_pol(void)
{
    int fails = 0, r;
    double mu = 1e3, y0[2] = {2, 0}, ref[31 * 2], out[31 * 2], scale[2] = {2, 2e3}, last = 1;
    dyad_ode_system sys = system_of(2, vdp_rhs, vdp_jacobian, &mu);
    sys.autonomous = 1;
    CHECK(gsl_reference(&sys, gsl_odeiv2_step_msbdf, 1e-13, y0, 100, 30, ref) == GSL_SUCCESS,
          "msbdf");
    for (r = 6; r <= 10; r += 2) {
        dyad_ode_state s;
        dyad_ode_options o = tolerances(pow(10, -r), pow(10, -r));
        double error;
        CHECK(run_grid(&s, &sys, y0, &o, 100, 30, out) == DYAD_ODE_OK, "status");
        error = grid_error(2, 30, out, ref, scale);
        REPORT("Van der Pol mu 1e3 over 3000, rtol 1e-%d: error %.2e of the amplitude, %ld "
               "steps (%ld rejected), %ld f\n",
               r, error, s.counters.accepted_steps, s.counters.rejected_steps,
               s.counters.rhs_evaluations);
        CHECK(error < 1e4 * pow(10, -r), "rtol 1e-%d: error %g", r, error);
        CHECK(error < last, "rtol 1e-%d: error %g does not fall", r, error);
        last = error;
    }
    return fails;
}

#define MOTOR_STEPS 500 /* 1 ms each: 0.5 s */

/* One motor against its reference at rtol 1e-6..1e-10: the errors relative
 * to the angle travelled, the peak speed and the peak current into errors[],
 * the f evaluations into evaluations[]. */
static int motor_accuracy(motor* m, const double* ref, double* errors, long* evaluations)
{
    int fails = 0, r, k;
    double y0[3] = {0, 0, 0}, out[(MOTOR_STEPS + 1) * 3], scale[3] = {0, 0, 0};
    dyad_ode_system sys = system_of(3, motor_rhs, motor_jacobian, m);
    for (k = 0; k <= MOTOR_STEPS; ++k) {
        scale[0] = fmax(scale[0], fabs(ref[k * 3]));
        scale[1] = fmax(scale[1], fabs(ref[k * 3 + 1]));
        scale[2] = fmax(scale[2], fabs(ref[k * 3 + 2]));
    }
    for (r = 6; r <= 10; ++r) {
        dyad_ode_state s;
        dyad_ode_options o = tolerances(pow(10, -r), pow(10, -r));
        CHECK(run_grid(&s, &sys, y0, &o, 1e-3, MOTOR_STEPS, out) == DYAD_ODE_OK, "status");
        errors[r - 6] = grid_error(3, MOTOR_STEPS, out, ref, scale);
        evaluations[r - 6] = s.counters.rhs_evaluations;
        REPORT("L/R %.0e, rtol 1e-%d: error %.2e; %ld steps (%ld rejected), %ld f, %ld J: "
               "%.1f f per ms\n",
               m->inductance / m->resistance, r, errors[r - 6], s.counters.accepted_steps,
               s.counters.rejected_steps, s.counters.rhs_evaluations,
               s.counters.jacobian_evaluations, s.counters.rhs_evaluations / 500.0);
    }
    return fails;
}

static int test_gsl_motor(void)
{
    int fails = 0, c, r;
    double errors[2][5], ref[(MOTOR_STEPS + 1) * 3], ref2[(MOTOR_STEPS + 1) * 3];
    double y0[3] = {0, 0, 0}, unit[3] = {1, 1, 1};
    long evaluations[2][5];
    for (c = 0; c < 2; ++c) {
        motor m = motor_with(c == 0 ? 1e-3 : 1e-6);
        dyad_ode_system sys = system_of(3, motor_rhs, motor_jacobian, &m);
        CHECK(gsl_reference(&sys, gsl_odeiv2_step_rk8pd, 1e-14, y0, 1e-3, MOTOR_STEPS, ref) ==
                  GSL_SUCCESS,
              "rk8pd");
        CHECK(gsl_reference(&sys, gsl_odeiv2_step_msbdf, 1e-13, y0, 1e-3, MOTOR_STEPS, ref2) ==
                  GSL_SUCCESS,
              "msbdf");
        REPORT("L/R %.0e: rk8pd and msbdf differ by %.2e (absolute)\n", m.inductance,
               grid_error(3, MOTOR_STEPS, ref, ref2, unit));
        fails += motor_accuracy(&m, ref, errors[c], evaluations[c]);
        for (r = 0; r < 5; ++r) {
            CHECK(errors[c][r] < 2 * pow(10, -6 - r), "case %d rtol 1e-%d: %g", c, r + 6,
                  errors[c][r]);
            CHECK(r == 0 || errors[c][r] < errors[c][r - 1], "case %d: no fall at 1e-%d", c, r + 6);
        }
        CHECK(errors[c][4] < 1e-2 * errors[c][0], "case %d: 1e-10 vs 1e-6: %g / %g", c,
              errors[c][4], errors[c][0]);
    }
    /* Stiffness costs nothing: L/R = 1e-6 s at most as many f as 1e-3 s. */
    CHECK(evaluations[1][2] <= evaluations[0][2], "stiff %ld f, non-stiff %ld at rtol 1e-8",
          evaluations[1][2], evaluations[0][2]);
    return fails;
}

#else

static int test_gsl_skipped(void)
{
    printf("    skipped: built without GSL (libgsl-dev)\n");
    return 0;
}

#endif

/* ---- (b') a component's own magnitude ---------------------------------------------------- */

/* The limit cycle's components pass through zero twice a turn. Held only to
 * atol + rtol |y|, each crossing forces small steps; held to rtol times the cycle's
 * radius (options.magnitude), the steps follow the motion, and the error stays within
 * that scale. */
static int magnitude_run(dyad_ode_method method, double magnitude, double* worst, long* steps)
{
    int k;
    double y0[2], out[101 * 2], exact[2];
    dyad_ode_system sys = system_of(2, cycle_rhs, cycle_jacobian, NULL);
    dyad_ode_options o = tolerances(1e-8, 1e-15);
    dyad_ode_state s;
    o.method = method;
    o.magnitude[0] = o.magnitude[1] = magnitude;
    sys.autonomous = 1;
    cycle_exact(0, y0);
    if (run_grid(&s, &sys, y0, &o, 0.2, 100, out) != DYAD_ODE_OK) {
        return 1;
    }
    *worst = 0;
    for (k = 1; k <= 100; ++k) {
        cycle_exact(0.2 * k, exact);
        *worst = fmax(*worst, fmax(fabs(out[2 * k] - exact[0]), fabs(out[2 * k + 1] - exact[1])));
    }
    *steps = s.counters.accepted_steps + s.counters.rejected_steps;
    return 0;
}

static int magnitude_by(dyad_ode_method method, const char* name)
{
    int fails = 0;
    double own_error, floor_error;
    long own_steps, floor_steps;
    CHECK(magnitude_run(method, 0, &own_error, &own_steps) == 0, "%s without magnitude", name);
    CHECK(magnitude_run(method, 1, &floor_error, &floor_steps) == 0, "%s magnitude 1", name);
    REPORT("%s: without magnitude %ld steps, error %.2e; magnitude 1: %ld steps, error %.2e\n",
           name, own_steps, own_error, floor_steps, floor_error);
    CHECK(floor_steps < own_steps, "%s: %ld steps with magnitude, %ld without", name, floor_steps,
          own_steps);
    CHECK(floor_error < 10 * 1e-8, "%s: error %g with magnitude 1", name, floor_error);
    return fails;
}

static int test_magnitude(void)
{
    int fails = 0;
    double y0 = 1;
    dyad_ode_state s;
    dyad_ode_options o = tolerances(1e-8, 1e-10);
    fails += magnitude_by(DYAD_ODE_RODASP, "RODASP");
    fails += magnitude_by(DYAD_ODE_DOP853, "DOP853");
    o.magnitude[3] = NAN;
    CHECK(dyad_ode_init(&s, 1, 0, &y0, &o) == DYAD_ODE_INVALID_ARGUMENT, "NaN magnitude");
    o.magnitude[3] = -1;
    CHECK(dyad_ode_init(&s, 1, 0, &y0, &o) == DYAD_ODE_INVALID_ARGUMENT, "negative magnitude");
    o.magnitude[3] = INFINITY;
    CHECK(dyad_ode_init(&s, 1, 0, &y0, &o) == DYAD_ODE_INVALID_ARGUMENT, "infinite magnitude");
    return fails;
}

/* ---- (b'') a quantity computed from the states, held to its own tolerance ----------------- */

/* A crank driven by a motor without inductance: M w' = c (w_free - w) - load sin W t, with a
 * damping c = k^2 / R so strong that the speed sits a hair below w_free. The motor's torque
 * c (w_free - w), which the reactions follow, carries the speed's error times c: held to
 * rtol |w| the speed leaves it far beyond rtol of the load; the system's error_magnitude holds
 * the speed to rtol of the torque's own scale over c instead. */
#define STIFF_CRANK_DT 0.005 /* s, the communication step; 200 of them */

typedef struct stiff_crank {
    double inertia, damping, free_speed, load, frequency;
    double rtol, atol;
} stiff_crank;

static int stiff_crank_rhs(void* user, dyad_real t, const dyad_real* y, dyad_real* dydt)
{
    const stiff_crank* c = (const stiff_crank*)user;
    dydt[0] = y[1];
    dydt[1] = (c->damping * (c->free_speed - y[1]) - c->load * sin(c->frequency * t)) / c->inertia;
    return 0;
}

static void stiff_crank_magnitude(void* user, const dyad_real* y0, const dyad_real* y1,
                                  dyad_real* magnitude)
{
    const stiff_crank* c = (const stiff_crank*)user;
    const double torque = fabs(c->damping * (c->free_speed - y1[1]));
    (void)y0;
    magnitude[1] = (torque + c->load) / c->damping;
}

/* The torque c (w_free - w) at t from w(0) = w_free: with u = w - w_free, a = c / M and the
 * load's frequency W, u' = -a u - (load / M) sin W t, whose solution is
 * u = B (cos W t - e^(-a t)) - (a / W) B sin W t, B = (load / M) W / (W^2 + a^2). */
static double stiff_crank_torque(const stiff_crank* c, double t)
{
    const double a = c->damping / c->inertia, w = c->frequency;
    const double b = c->load / c->inertia * w / (w * w + a * a);
    return -c->damping * (b * (cos(w * t) - exp(-a * t)) - a / w * b * sin(w * t));
}

static double stiff_crank_error(stiff_crank* c, int scaled, dyad_ode_method method, long* steps)
{
    int k;
    double y0[2] = {0, 0}, out[201 * 2], worst = 0;
    dyad_ode_system sys = system_of(2, stiff_crank_rhs, NULL, c);
    dyad_ode_options o = tolerances(c->rtol, c->atol);
    dyad_ode_state s;
    o.method = method;
    y0[1] = c->free_speed;
    sys.autonomous = 0;
    sys.error_magnitude = scaled ? stiff_crank_magnitude : NULL;
    if (run_grid(&s, &sys, y0, &o, STIFF_CRANK_DT, 200, out) != DYAD_ODE_OK) {
        return INFINITY;
    }
    for (k = 1; k <= 200; ++k) {
        const double torque = c->damping * (c->free_speed - out[2 * k + 1]);
        worst = fmax(worst, fabs(torque - stiff_crank_torque(c, STIFF_CRANK_DT * k)) / c->load);
    }
    *steps = s.counters.accepted_steps + s.counters.rejected_steps;
    return worst;
}

static int test_error_magnitude(void)
{
    int fails = 0, m;
    const dyad_ode_method methods[2] = {DYAD_ODE_RODASP, DYAD_ODE_DOP853};
    const char* names[2] = {"RODASP", "DOP853"};
    for (m = 0; m < 2; ++m) {
        stiff_crank c = {1e-2, 1e2, 1e3, 1, 300, 1e-8, 1e-12};
        long plain_steps = 0, scaled_steps = 0;
        const double plain = stiff_crank_error(&c, 0, methods[m], &plain_steps);
        const double scaled = stiff_crank_error(&c, 1, methods[m], &scaled_steps);
        REPORT("%s: torque error / load %.2e in %ld steps held to rtol |w|, %.2e in %ld steps "
               "with error_magnitude\n",
               names[m], plain, plain_steps, scaled, scaled_steps);
        CHECK(plain > 100 * c.rtol, "%s: the torque is within %g without error_magnitude: no test",
              names[m], plain);
        CHECK(scaled < 10 * c.rtol, "%s: torque error %g with error_magnitude", names[m], scaled);
    }
    return fails;
}

/* ---- (c) reproducibility ------------------------------------------------------------------ */

static int test_reproducible(void)
{
    int fails = 0;
    motor m = motor_with(1e-6);
    dyad_ode_system sys = system_of(3, motor_rhs, motor_jacobian, &m);
    dyad_ode_options o = tolerances(1e-8, 1e-8);
    double y0[3] = {0, 0, 0}, a[101 * 3], b[101 * 3], one[2 * 3];
    dyad_ode_state s1, s2, s3;
    run_grid(&s1, &sys, y0, &o, 1e-3, 100, a);
    run_grid(&s2, &sys, y0, &o, 1e-3, 100, b);
    CHECK(memcmp(a, b, sizeof a) == 0, "two runs differ");
    CHECK(memcmp(&s1.counters, &s2.counters, sizeof s1.counters) == 0, "counters differ");
    /* One call over 0.1 s against a hundred: within the tolerance. */
    CHECK(run_grid(&s3, &sys, y0, &o, 0.1, 1, one) == DYAD_ODE_OK, "one call");
    REPORT("one call vs 100: angle %.2e, speed %.2e, current %.2e apart; %ld vs %ld f\n",
           fabs(one[3] - a[300]), fabs(one[4] - a[301]), fabs(one[5] - a[302]),
           s3.counters.rhs_evaluations, s1.counters.rhs_evaluations);
    CHECK(fabs(one[3] - a[300]) < 1e-7 * fabs(a[300]), "angle %g vs %g", one[3], a[300]);
    CHECK(fabs(one[4] - a[301]) < 1e-7 * fabs(a[301]), "speed %g vs %g", one[4], a[301]);
    CHECK(fabs(one[5] - a[302]) < 1e-7 * fabs(a[302]) + 1e-7, "current %g vs %g", one[5], a[302]);
    return fails;
}

static int test_save_restore(void)
{
    int fails = 0, k;
    motor m = motor_with(1e-3);
    dyad_ode_system sys = system_of(3, motor_rhs, NULL, &m);
    dyad_ode_options o = tolerances(1e-9, 1e-9);
    double y0[3] = {0, 0, 0};
    dyad_ode_state s, saved, copy;
    dyad_ode_init(&s, 3, 0, y0, &o);
    for (k = 1; k <= 40; ++k) {
        dyad_ode_advance(&s, &sys, k * 2.5e-3);
    }
    saved = s;
    for (k = 41; k <= 80; ++k) {
        dyad_ode_advance(&s, &sys, k * 2.5e-3);
    }
    memcpy(&copy, &saved, sizeof copy); /* a serialised state, brought back */
    for (k = 41; k <= 80; ++k) {
        dyad_ode_advance(&copy, &sys, k * 2.5e-3);
    }
    CHECK(memcmp(&copy, &s, sizeof s) == 0, "restored run differs: t %.17g vs %.17g", copy.t, s.t);
    CHECK(copy.y[1] == s.y[1] && s.t == 0.2, "speed %.17g vs %.17g", copy.y[1], s.y[1]);
    return fails;
}

/* ---- (d) failures ------------------------------------------------------------------------- */

/* The forced decay that fails (code 7, "cannot assemble") or turns NaN
 * from t_bad on. */
typedef struct failing {
    double lambda, t_bad;
    int nan;
} failing;

static int failing_rhs(void* user, double t, const double* y, double* f)
{
    const failing* p = (const failing*)user;
    forced_rhs((void*)&p->lambda, t, y, f);
    if (t >= p->t_bad) {
        if (p->nan) {
            f[0] = NAN;
            return 0;
        }
        return 7;
    }
    return 0;
}

static int test_rhs_failure(void)
{
    int fails = 0, nan;
    for (nan = 0; nan < 2; ++nan) {
        failing p;
        dyad_ode_system sys = system_of(1, failing_rhs, NULL, &p);
        dyad_ode_options o = tolerances(1e-8, 1e-10);
        dyad_ode_state s, before;
        double y0 = 1;
        dyad_ode_status st, expected = nan ? DYAD_ODE_RHS_NONFINITE : DYAD_ODE_RHS_FAILED;
        p.lambda = 1;
        p.t_bad = 0.73;
        p.nan = nan;
        dyad_ode_init(&s, 1, 0, &y0, &o);
        CHECK(dyad_ode_advance(&s, &sys, 0.5) == DYAD_ODE_OK, "before the failure");
        before = s;
        st = dyad_ode_advance(&s, &sys, 1.0);
        CHECK(st == expected && s.status == st, "status %s", dyad_ode_status_name(st));
        CHECK(nan || s.rhs_code == 7, "code %d", s.rhs_code);
        CHECK(s.t < 0.73 && s.t >= 0.5 && s.t_failed >= 0.73 && s.t_failed > s.t,
              "last accepted %g, failed at %g", s.t, s.t_failed);
        CHECK(fabs(s.y[0] - forced_exact(1, 1, s.t)) < 1e-7, "y at the last accepted point");
        CHECK(s.counters.accepted_steps > before.counters.accepted_steps, "steps taken");
        REPORT("%s: stopped at t %.6f (failed at %.6f)\n", dyad_ode_status_name(st), s.t,
               s.t_failed);
    }
    return fails;
}

static int test_step_cap(void)
{
    int fails = 0;
    double lambda = 1, y0 = 1;
    dyad_ode_system sys = system_of(1, forced_rhs, forced_jacobian, &lambda);
    dyad_ode_options o = tolerances(1e-8, 1e-10);
    dyad_ode_state s, before;
    dyad_ode_status st;
    /* Refused before it starts: h_max 1e-3 cannot cover 1 s in 100 steps. */
    o.h_max = 1e-3;
    o.max_steps = 100;
    dyad_ode_init(&s, 1, 0, &y0, &o);
    before = s;
    st = dyad_ode_advance(&s, &sys, 1.0);
    CHECK(st == DYAD_ODE_TOO_MANY_STEPS, "status %s", dyad_ode_status_name(st));
    CHECK(s.counters.rhs_evaluations == 0 && s.t == 0 && s.y[0] == before.y[0], "work done");
    /* Within the cap's reach at the controller's limits, but the error
     * control needs more: stops at the last accepted point as soon as the
     * steps left cannot reach the end even growing as fast as they may, before
     * the cap itself. */
    o.h_max = INFINITY;
    o.max_steps = 60;
    o.rtol = 1e-12;
    o.atol = 1e-14;
    dyad_ode_init(&s, 1, 0, &y0, &o);
    st = dyad_ode_advance(&s, &sys, 1000.0);
    CHECK(st == DYAD_ODE_TOO_MANY_STEPS, "status %s", dyad_ode_status_name(st));
    CHECK(s.t > 0 && s.t < 1000 && s.counters.accepted_steps + s.counters.rejected_steps < 60,
          "t %g after %ld + %ld", s.t, s.counters.accepted_steps, s.counters.rejected_steps);
    printf("    step cap: stopped at t = %g s after %ld + %ld steps of 60\n", s.t,
           s.counters.accepted_steps, s.counters.rejected_steps);
    CHECK(fabs(s.y[0] - forced_exact(1, 1, s.t)) < 1e-10, "y at the last accepted point");
    return fails;
}

/* y' = 0: every step's error is 0 and each step grows by the controller's largest
 * factor. Over a span near DBL_MAX, by both methods, the span is covered and the step
 * it proposes next stays finite (a state, and a plant's solver.step output). */
static int still_rhs(void* user, double t, const double* y, double* f)
{
    (void)user, (void)t, (void)y;
    f[0] = 0;
    return 0;
}

static int still_jacobian(void* user, double t, const double* y, const double* f, double* jac,
                          double* dfdt)
{
    (void)user, (void)t, (void)y, (void)f;
    jac[0] = 0;
    dfdt[0] = 0;
    return 0;
}

static int test_growth_stays_finite(void)
{
    int fails = 0, k;
    const dyad_ode_method methods[2] = {DYAD_ODE_RODASP, DYAD_ODE_DOP853};
    const char* names[2] = {"RODASP", "DOP853"};
    dyad_ode_system sys = system_of(1, still_rhs, still_jacobian, NULL);
    for (k = 0; k < 2; ++k) {
        dyad_ode_options o = tolerances(1e-8, 1e-10);
        dyad_ode_state s;
        dyad_ode_status st;
        double y0 = 1;
        o.method = methods[k];
        o.max_steps = 20000;
        dyad_ode_init(&s, 1, 0, &y0, &o);
        st = dyad_ode_advance(&s, &sys, 1.0);
        st = st == DYAD_ODE_OK ? dyad_ode_advance(&s, &sys, 1.7976931348623157e308) : st;
        CHECK(st == DYAD_ODE_OK, "%s: status %s", names[k], dyad_ode_status_name(st));
        CHECK(isfinite(s.h_next) && s.h_next > 0 && s.y[0] == 1, "%s: h_next %g, y %g", names[k],
              s.h_next, s.y[0]);
    }
    return fails;
}

/* y' = -1 above 0, +1 below: no step across 0 meets the tolerance. */
static int switching_rhs(void* user, double t, const double* y, double* f)
{
    (void)user, (void)t;
    f[0] = y[0] > 0 ? -1 : 1;
    return 0;
}

static int test_step_underflow(void)
{
    int fails = 0;
    double y0 = 0.5;
    dyad_ode_system sys = system_of(1, switching_rhs, NULL, NULL);
    dyad_ode_options o = tolerances(1e-10, 1e-300);
    dyad_ode_state s;
    dyad_ode_status st;
    sys.autonomous = 1;
    dyad_ode_init(&s, 1, 0, &y0, &o);
    st = dyad_ode_advance(&s, &sys, 1.0);
    REPORT("%s at t %.17g after %ld steps\n", dyad_ode_status_name(st), s.t,
           s.counters.accepted_steps);
    CHECK(st == DYAD_ODE_STEP_UNDERFLOW, "status %s", dyad_ode_status_name(st));
    CHECK(fabs(s.t - 0.5) < 1e-9, "stopped at %.17g", s.t);
    /* It gives up at 16 eps |t|, not at the last bit of t. */
    CHECK(s.h_next > 1e-16 && s.h_next < 16 * 2.3e-16 * s.t, "gave up at h %g", s.h_next);
    /* or at the shortest step it is given, sooner */
    o.h_min = 1e-6;
    dyad_ode_init(&s, 1, 0, &y0, &o);
    st = dyad_ode_advance(&s, &sys, 1.0);
    CHECK(st == DYAD_ODE_STEP_UNDERFLOW && fabs(s.t - 0.5) < 1e-5 && s.h_next < 1e-6 &&
              s.h_next > 1e-8,
          "h_min 1e-6: %s at t %.17g, gave up at h %g", dyad_ode_status_name(st), s.t, s.h_next);
    return fails;
}

/* A body at rest but for a speed of a few eps, under a constant acceleration of 100. */
static int falling_rhs(void* user, double t, const double* y, double* f)
{
    (void)user, (void)t;
    f[0] = y[1];
    f[1] = 100;
    return 0;
}

/* A start a few eps from rest, as a plant's states may be given: |y| / |f| in the
 * error's norm asks for a first step of 1e-19 s, below the shortest a caller that
 * integrates a 1 ms step from 0 allows (16 eps of it). The first step starts 256 times
 * above that shortest one instead, and the motion is the exact one. Before, the call
 * stopped at once with STEP_UNDERFLOW. */
static int test_first_step_near_rest(void)
{
    const dyad_ode_method methods[2] = {DYAD_ODE_RODASP, DYAD_ODE_DOP853};
    int fails = 0, m;
    for (m = 0; m < 2; ++m) {
        double y0[2] = {0, 1e-14};
        dyad_ode_system sys = system_of(2, falling_rhs, NULL, NULL);
        dyad_ode_options o = tolerances(1e-8 / 64, 1e-8 / 64);
        dyad_ode_state s;
        dyad_ode_status st;
        o.method = methods[m];
        o.h_min = 16 * DBL_EPSILON * 1e-3;
        sys.autonomous = 1;
        dyad_ode_init(&s, 2, 0, y0, &o);
        st = dyad_ode_advance(&s, &sys, 1e-3);
        REPORT("%s: %s after %ld steps\n", dyad_ode_status_name(st), m ? "DOP853" : "RODASP",
               s.counters.accepted_steps);
        CHECK(st == DYAD_ODE_OK, "%s: %s", m ? "DOP853" : "RODASP", dyad_ode_status_name(st));
        CHECK(fabs(s.y[1] - (1e-14 + 0.1)) < 1e-15 && fabs(s.y[0] - (1e-17 + 5e-5)) < 1e-18,
              "%s: y = (%.17g, %.17g)", m ? "DOP853" : "RODASP", s.y[0], s.y[1]);
    }
    return fails;
}

/* y' = J y with J = diag(8, 16, ..., 256): I / (h gamma) - J is singular at
 * h = 1/2, 1/4, ..., 1/64 (gamma = 1/4), every halving the first step tries. */
static int singular_rhs(void* user, double t, const double* y, double* f)
{
    int i;
    (void)user, (void)t;
    for (i = 0; i < 6; ++i) {
        f[i] = 8.0 * (1 << i) * y[i];
    }
    return 0;
}

static int singular_jacobian(void* user, double t, const double* y, const double* f, double* jac,
                             double* dfdt)
{
    int i;
    (void)user, (void)t, (void)y, (void)f;
    memset(jac, 0, 36 * sizeof *jac);
    for (i = 0; i < 6; ++i) {
        jac[i * 7] = 8.0 * (1 << i);
        dfdt[i] = 0;
    }
    return 0;
}

static int test_singular(void)
{
    int fails = 0;
    double y0[6] = {1, 1, 1, 1, 1, 1};
    dyad_ode_system sys = system_of(6, singular_rhs, singular_jacobian, NULL);
    dyad_ode_options o = tolerances(1e-6, 1e-6);
    dyad_ode_state s;
    dyad_ode_status st;
    o.h_initial = 0.5;
    dyad_ode_init(&s, 6, 0, y0, &o);
    st = dyad_ode_advance(&s, &sys, 1.0);
    CHECK(st == DYAD_ODE_SINGULAR, "status %s", dyad_ode_status_name(st));
    CHECK(s.t == 0 && s.counters.decompositions == DYAD_ODE_SINGULAR_RETRIES + 1,
          "t %g, %ld decompositions", s.t, s.counters.decompositions);
    /* One halving fewer: the last one gets through. */
    o.h_initial = 0.25;
    dyad_ode_init(&s, 6, 0, y0, &o);
    st = dyad_ode_advance(&s, &sys, 1.0);
    CHECK(st == DYAD_ODE_OK, "status %s", dyad_ode_status_name(st));
    CHECK(fabs(s.y[0] / exp(8.0) - 1) < 1e-4, "y0 %g", s.y[0]);
    return fails;
}

static int test_invalid_arguments(void)
{
    int fails = 0;
    double y0 = 1, nan_y = NAN, lambda = 1;
    dyad_ode_system sys = system_of(1, forced_rhs, NULL, &lambda);
    dyad_ode_options o = tolerances(1e-8, 0);
    dyad_ode_state s;
    CHECK(dyad_ode_init(&s, 1, 0, &y0, &o) == DYAD_ODE_INVALID_ARGUMENT, "atol 0");
    CHECK(dyad_ode_init(&s, 0, 0, &y0, NULL) == DYAD_ODE_INVALID_ARGUMENT, "n 0");
    CHECK(dyad_ode_init(&s, DYAD_ODE_MAX_DIM + 1, 0, &y0, NULL) == DYAD_ODE_INVALID_ARGUMENT,
          "n too large");
    CHECK(dyad_ode_init(&s, 1, 0, &nan_y, NULL) == DYAD_ODE_INVALID_ARGUMENT, "NaN y0");
    CHECK(dyad_ode_init(&s, 1, 0, &y0, NULL) == DYAD_ODE_OK, "defaults");
    CHECK(dyad_ode_advance(&s, &sys, -1) == DYAD_ODE_INVALID_ARGUMENT, "backwards");
    CHECK(dyad_ode_advance(&s, &sys, NAN) == DYAD_ODE_INVALID_ARGUMENT, "NaN t_end");
    CHECK(dyad_ode_advance(&s, &sys, 0) == DYAD_ODE_OK && s.counters.rhs_evaluations == 0,
          "empty interval");
    sys.n = 2;
    CHECK(dyad_ode_advance(&s, &sys, 1) == DYAD_ODE_INVALID_ARGUMENT, "n differs");
    CHECK(strcmp(dyad_ode_status_name(DYAD_ODE_STEP_UNDERFLOW), "step size underflow") == 0,
          "name");
    return fails;
}

static const named_test tests[] = {
    {"linear_exact", test_linear_exact},
    {"stiff_forced", test_stiff_forced},
    {"order_four", test_order_four},
    {"dense_output", test_dense_output},
    {"dop_order_eight", test_dop_order_eight},
    {"dop_linear_exact", test_dop_linear_exact},
#ifdef DYAD_ODE_TESTS_GSL
    {"gsl_pendulum", test_gsl_pendulum},
    {"dop_gsl_pendulum", test_dop_gsl_pendulum},
    {"gsl_van_der_pol", test_gsl_van_der_pol},
    {"gsl_motor", test_gsl_motor},
#else
    {"gsl_skipped", test_gsl_skipped},
#endif
    {"magnitude", test_magnitude},
    {"error_magnitude", test_error_magnitude},
    {"reproducible", test_reproducible},
    {"save_restore", test_save_restore},
    {"rhs_failure", test_rhs_failure},
    {"step_cap", test_step_cap},
    {"growth_stays_finite", test_growth_stays_finite},
    {"step_underflow", test_step_underflow},
    {"first_step_near_rest", test_first_step_near_rest},
    {"singular", test_singular},
    {"invalid_arguments", test_invalid_arguments},
};

int main(int argc, char** argv)
{
    if (argc > 1 && strcmp(argv[1], "-v") == 0) {
        verbose = 1;
        --argc;
        ++argv;
    }
    return run_named_tests(tests, sizeof tests / sizeof tests[0], "ode", argv + 1, argc - 1) == 0
               ? 0
               : 1;
}
