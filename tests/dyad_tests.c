/* dyadfmu: tests of the kinetostatic core.
 *
 * Built twice, against the double and the float core. Every check of a
 * reaction is made by means independent of the solver's formulas: the
 * equilibrium of each link is summed here from the inputs and the outputs,
 * with the acceleration of the centre of mass computed with complex numbers
 * and the moments taken about an arbitrary point, in double precision.
 *
 * Usage: dyad_tests_<real> [test-name ...]   (no name: run them all)
 */
#include <complex.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "dyadfmu/angle.h"
#include "dyadfmu/batch.h"
#include "dyadfmu/dyad.h"
#include "dyadfmu/kinematics.h"
#include "dyadfmu/loaded.h"
#include "dyadfmu/vec2.h"
#define DYAD_LANES_RRR
#define DYAD_LANES_RRT
#define DYAD_LANES_RTR
#define DYAD_LANES_TRT
#define DYAD_LANES_RTT
#define DYAD_LANES_CYLINDER
#include "dyad_lanes.h"
#include "named_tests.h"

#ifdef DYAD_REAL_FLOAT
#define REAL_NAME "float"
/* float carries 24 bits; with amplification up to 10 in the random set a few
 * units of 6e-8 per term are expected. */
#define RESIDUAL_LIMIT 1e-5
#define HAND_LIMIT     1e-5
#define HUGE_REAL      1e30f
/* The test reduces the loads in double, the float core in float: the two
 * roundings of terms up to 1e3 times the reactions differ by that much. */
#define REACT_LIMIT 1e-4
#else
#define REAL_NAME      "double"
#define RESIDUAL_LIMIT 1e-12
#define HAND_LIMIT     1e-12
#define HUGE_REAL      1e300
#define REACT_LIMIT    1e-12
#endif

#define RANDOM_CONFIGURATIONS 10000
#define WELL_CONDITIONED      0.1
#define PI                    3.14159265358979323846

static const dyad_type all_types[DYAD_TYPE_COUNT] = {DYAD_RRR, DYAD_RRT, DYAD_RTR, DYAD_TRT,
                                                     DYAD_RTT};

/* ---- random numbers: splitmix64 ------------------------------------------------------------- */

typedef struct rng {
    uint64_t state;
} rng;

static double uniform(rng* r, double lo, double hi)
{
    uint64_t z = (r->state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return lo + (hi - lo) * ((double)(z >> 11) / 9007199254740992.0);
}

static double log_uniform(rng* r, double lo, double hi)
{
    return exp(uniform(r, log(lo), log(hi)));
}

static double signed_log_uniform(rng* r, double lo, double hi)
{
    return (uniform(r, 0, 1) < 0.5 ? -1 : 1) * log_uniform(r, lo, hi);
}

static dyad_vec2 vec(double x, double y)
{
    return dyad_vec2_make((dyad_real)x, (dyad_real)y);
}

static dyad_vec2 polar(double magnitude, double angle)
{
    return vec(magnitude * cos(angle), magnitude * sin(angle));
}

/* ---- equilibrium, summed independently of the solver ---------------------------------------- */

typedef struct balance {
    double fx, fy, mz; /* sums of forces (N) and of moments about P (N m) */
    double f_scale;    /* largest force term (N) */
    double m_scale;    /* largest moment term (N m) */
} balance;

static void add_force(balance* b, double complex at, double complex force, double complex p)
{
    const double complex lever = at - p;
    const double moment = creal(lever) * cimag(force) - cimag(lever) * creal(force);
    b->fx += creal(force);
    b->fy += cimag(force);
    b->mz += moment;
    if (cabs(force) > b->f_scale) {
        b->f_scale = cabs(force);
    }
    if (cabs(lever) * cabs(force) > b->m_scale) {
        b->m_scale = cabs(lever) * cabs(force);
    }
}

static void add_moment(balance* b, double moment)
{
    b->mz += moment;
    if (fabs(moment) > b->m_scale) {
        b->m_scale = fabs(moment);
    }
}

/* Worst of |sum of forces| / largest force and |sum of moments| / largest moment. */
static double relative_imbalance(const balance* b)
{
    const double f = b->f_scale > 0 ? hypot(b->fx, b->fy) / b->f_scale : hypot(b->fx, b->fy);
    const double m = b->m_scale > 0 ? fabs(b->mz) / b->m_scale : fabs(b->mz);
    return f > m ? f : m;
}

static double complex cvec(dyad_vec2 v)
{
    return (double)v.x + I * (double)v.y;
}

/* Direction of a link as the solver reads it: normalised. */
static double complex unit(dyad_vec2 v)
{
    const double complex c = cvec(v);
    return c / cabs(c);
}

/* Adds a link's active load, weight and d'Alembert inertia. The acceleration
 * of S is a_D + r (i epsilon - omega^2), r = S - D as a complex number. */
static void add_link_loads(balance* b, const dyad_link* link, double complex d, dyad_vec2 gravity,
                           double complex p)
{
    const double complex i = unit(link->dir);
    const double complex r = i * ((double)link->com.x + I * (double)link->com.y);
    const double complex accel_s =
        cvec(link->accel_d) + r * (I * (double)link->epsilon - (double)link->omega * link->omega);
    const double mass = link->mass;
    add_force(b, d + r, cvec(link->force), p);
    add_force(b, d + r, mass * cvec(gravity), p);
    add_force(b, d + r, -mass * accel_s, p);
    add_moment(b, link->moment);
    add_moment(b, -(double)link->inertia * link->epsilon);
}

/* Equilibrium residuals of a solved dyad. */
typedef struct imbalance {
    /* Worst link, relative to the largest force or moment term acting on the
     * whole dyad (loads, weights, inertia, reactions): the backward error. */
    double dyad;
    /* Worst link, relative to the largest term acting on that link alone:
     * stricter where one link's loads dwarf the other's. */
    double link;
} imbalance;

/* The equilibrium of both links; D_m is placed at d_m, moments are taken about p. */
static imbalance dyad_imbalance(const dyad_input* in, const dyad_result* out, double complex d_m,
                                double complex p)
{
    const double complex e = d_m + (double)in->m.length * unit(in->m.dir);
    const double complex d_n = e - (double)in->n.length * unit(in->n.dir);
    balance link_m = {0, 0, 0, 0, 0};
    balance link_n = {0, 0, 0, 0, 0};
    balance scale;
    imbalance result;
    double worst_m, worst_n;

    add_link_loads(&link_m, &in->m, d_m, in->gravity, p);
    add_force(&link_m, d_m, cvec(out->r_mk), p);
    add_force(&link_m, e, cvec(out->r_mn), p);
    add_moment(&link_m, out->m_mk);
    add_moment(&link_m, out->m_mn);

    add_link_loads(&link_n, &in->n, d_n, in->gravity, p);
    add_force(&link_n, d_n, cvec(out->r_np), p);
    add_force(&link_n, e, -cvec(out->r_mn), p);
    add_moment(&link_n, out->m_np);
    add_moment(&link_n, -(double)out->m_mn);

    worst_m = relative_imbalance(&link_m);
    worst_n = relative_imbalance(&link_n);
    result.link = worst_m > worst_n ? worst_m : worst_n;

    scale.f_scale = link_m.f_scale > link_n.f_scale ? link_m.f_scale : link_n.f_scale;
    scale.m_scale = link_m.m_scale > link_n.m_scale ? link_m.m_scale : link_n.m_scale;
    scale.fx = link_m.fx, scale.fy = link_m.fy, scale.mz = link_m.mz;
    worst_m = relative_imbalance(&scale);
    scale.fx = link_n.fx, scale.fy = link_n.fy, scale.mz = link_n.mz;
    worst_n = relative_imbalance(&scale);
    result.dyad = worst_m > worst_n ? worst_m : worst_n;
    return result;
}

/* What each pair may carry: a translational pair only a force normal to its
 * guide (reported as the normal force), a revolute pair no moment. Returns the
 * worst relative violation; revolute moments and normals must be exactly 0. */
static double pair_violation(dyad_type type, const dyad_input* in, const dyad_result* out)
{
    const dyad_vec2 guides[3] = {in->guide_k, in->m.dir, in->guide_p};
    const dyad_vec2 forces[3] = {out->r_mk, out->r_mn, out->r_np};
    const double normals[3] = {out->n_mk, out->n_mn, out->n_np};
    const double moments[3] = {out->m_mk, out->m_mn, out->m_np};
    const dyad_pair pairs[3] = {DYAD_PAIR_DM, DYAD_PAIR_E, DYAD_PAIR_DN};
    double worst = 0;
    int k;
    for (k = 0; k < 3; ++k) {
        if (dyad_pair_kind_of(type, pairs[k]) == DYAD_PAIR_TRANSLATIONAL) {
            const double complex g = unit(guides[k]);
            const double complex f = cvec(forces[k]);
            const double size = cabs(f) > 0 ? cabs(f) : 1;
            const double along = creal(f * conj(g));
            const double normal = cimag(f * conj(g));
            const double v1 = fabs(along) / size;
            const double v2 = fabs(normal - normals[k]) / size;
            worst = v1 > worst ? v1 : worst;
            worst = v2 > worst ? v2 : worst;
        } else if (normals[k] != 0 || moments[k] != 0) {
            return INFINITY;
        }
    }
    return worst;
}

static int all_outputs_nan(const dyad_result* r)
{
    const dyad_real v[15] = {r->r_mk.x, r->r_mk.y, r->r_np.x, r->r_np.y, r->r_mn.x,
                             r->r_mn.y, r->n_mk,   r->n_np,   r->n_mn,   r->m_mk,
                             r->m_np,   r->m_mn,   0,         0,         0};
    int k;
    for (k = 0; k < 12; ++k) {
        if (!isnan(v[k])) {
            return 0;
        }
    }
    return 1;
}

/* ---- random configurations ------------------------------------------------------------------ */

/* Conditioning of a configuration from its angles, not from the solver. */
static double independent_conditioning(dyad_type type, const dyad_input* in)
{
    const double complex i_m = unit(in->m.dir);
    const double complex i_n = unit(in->n.dir);
    const double complex i_k = unit(in->guide_k);
    const double complex i_p = unit(in->guide_p);
    switch (type) {
    case DYAD_RRR: return fabs(sin(carg(i_n / i_m)));
    case DYAD_RRT: return fabs(cos(carg(i_n / i_k)));
    case DYAD_TRT: return fabs(sin(carg(i_p / i_k)));
    case DYAD_RTT: return fabs(sin(carg(i_m / i_k)));
    case DYAD_RTR: {
        const double complex dm_dn = (double)in->m.length * i_m - (double)in->n.length * i_n;
        const double spread = cabs(dm_dn) / ((double)in->m.length + in->n.length);
        const double slant = cabs(dm_dn) > 0 ? fabs(cos(carg(dm_dn / i_m))) : 0;
        return spread < slant ? spread : slant;
    }
    case DYAD_TYPE_COUNT: break;
    }
    return 0;
}

static void random_link(rng* r, dyad_link* link, int may_be_zero)
{
    const double length = (may_be_zero && uniform(r, 0, 1) < 0.1) ? 0 : log_uniform(r, 1e-3, 1e3);
    const double size = length > 0 ? length : log_uniform(r, 1e-3, 1);
    const double mass = uniform(r, 0, 1) < 0.05 ? 0 : log_uniform(r, 1e-3, 1e3);
    const double radius = size * uniform(r, 0.05, 0.6);
    link->dir = polar(1, uniform(r, 0, 2 * PI));
    link->length = (dyad_real)length;
    link->omega = (dyad_real)signed_log_uniform(r, 1e-2, 1e2);
    link->epsilon = (dyad_real)signed_log_uniform(r, 1e-2, 1e3);
    link->accel_d = polar(log_uniform(r, 1e-2, 1e3), uniform(r, 0, 2 * PI));
    link->com = vec(size * uniform(r, -0.5, 1.5), size * uniform(r, -0.5, 0.5));
    link->mass = (dyad_real)mass;
    link->inertia = (dyad_real)(uniform(r, 0, 1) < 0.05 ? 0 : mass * radius * radius);
    link->force = polar(log_uniform(r, 1e-2, 1e4), uniform(r, 0, 2 * PI));
    link->moment = (dyad_real)(signed_log_uniform(r, 1e-2, 1e4) * size);
}

static dyad_input random_input(rng* r, dyad_type type)
{
    dyad_input in = dyad_input_default();
    random_link(r, &in.m, dyad_length_may_be_zero(type, DYAD_LINK_M));
    random_link(r, &in.n, dyad_length_may_be_zero(type, DYAD_LINK_N));
    in.guide_k = polar(1, uniform(r, 0, 2 * PI));
    in.guide_p = polar(1, uniform(r, 0, 2 * PI));
    in.gravity = uniform(r, 0, 1) < 0.5 ? vec(0, 0) : polar(9.81, uniform(r, 0, 2 * PI));
    return in;
}

static int test_equilibrium_random(void)
{
    int fails = 0;
    int t;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x5EED0000u + (uint64_t)t};
        double worst_imbalance = 0, worst_link = 0, worst_pair = 0;
        int tried = 0, solved = 0;
        while (solved < RANDOM_CONFIGURATIONS) {
            const dyad_input in = random_input(&r, type);
            const double conditioning = independent_conditioning(type, &in);
            const double complex d_m = uniform(&r, -1e3, 1e3) + I * uniform(&r, -1e3, 1e3);
            const double complex p = uniform(&r, -1e3, 1e3) + I * uniform(&r, -1e3, 1e3);
            dyad_result out;
            dyad_status status;
            imbalance residual;
            double violation;
            ++tried;
            if (conditioning < WELL_CONDITIONED) {
                continue;
            }
            status = dyad_solve(type, &in, &out);
            if (status != DYAD_STATUS_OK) {
                CHECK(0, "%s: status %s (field %s) at conditioning %.3g", dyad_type_name(type),
                      dyad_status_name(status), dyad_field_name(out.field), conditioning);
                if (fails > 10) {
                    return fails;
                }
                continue;
            }
            ++solved;
            residual = dyad_imbalance(&in, &out, d_m, p);
            violation = pair_violation(type, &in, &out);
            worst_imbalance = residual.dyad > worst_imbalance ? residual.dyad : worst_imbalance;
            worst_link = residual.link > worst_link ? residual.link : worst_link;
            worst_pair = violation > worst_pair ? violation : worst_pair;
            if (!(fabs((double)out.conditioning - conditioning) <= 1e-4 * conditioning + 1e-6)) {
                CHECK(0, "%s: conditioning %.9g, expected %.9g", dyad_type_name(type),
                      (double)out.conditioning, conditioning);
            }
        }
        printf("    %s %s: %d configurations solved (%d drawn); worst equilibrium residual "
               "%.3e of the dyad's load scale (limit %.0e), %.3e of the link's own; worst "
               "pair-constraint violation %.3e\n",
               dyad_type_name(type), REAL_NAME, solved, tried, worst_imbalance, RESIDUAL_LIMIT,
               worst_link, worst_pair);
        CHECK(worst_imbalance < RESIDUAL_LIMIT, "%s: residual %.3e", dyad_type_name(type),
              worst_imbalance);
        CHECK(worst_link < RESIDUAL_LIMIT, "%s: residual %.3e of a link's own terms",
              dyad_type_name(type), worst_link);
        CHECK(worst_pair < RESIDUAL_LIMIT, "%s: pair violation %.3e", dyad_type_name(type),
              worst_pair);
    }
    return fails;
}

/* ---- hand-checkable cases ------------------------------------------------------------------- */

/* The hand cases carry loads of about 1e3 N (and moments of about 1e2 N m): a
 * component that should vanish is met to HAND_LIMIT of that scale. */
#define HAND_SCALE 1e3

static int close_to(double got, double want)
{
    return fabs(got - want) <= HAND_LIMIT * (HAND_SCALE + fabs(want));
}

#define CHECK_VEC(v, wx, wy)                              \
    CHECK(close_to((v).x, (wx)) && close_to((v).y, (wy)), \
          "%s = (%.12g, %.12g), expected "                \
          "(%.12g, %.12g)",                               \
          #v, (double)(v).x, (double)(v).y, (double)(wx), (double)(wy))
#define CHECK_REAL(v, w) \
    CHECK(close_to((v), (w)), "%s = %.12g, expected %.12g", #v, (double)(v), (double)(w))

/* A massless link whose load sits at E: the symmetric RRR truss. */
static int test_rrr_symmetric_truss(void)
{
    /* D_m = (-0.3, 0), D_n = (0.3, 0), E = (0, 0.4): l = 0.5, sin(alpha) = 0.8.
     * A vertical load P = 1000 N at E, half on each link. Each link is a two-force
     * member in compression P / (2 sin alpha) = 625 N along its axis. */
    int fails = 0;
    dyad_input in = dyad_input_default();
    dyad_result out;
    in.m.dir = vec(0.6, 0.8);
    in.n.dir = vec(-0.6, 0.8);
    in.m.length = in.n.length = 0.5;
    in.m.com = in.n.com = vec(0.5, 0);
    in.m.force = in.n.force = vec(0, -500);
    CHECK(dyad_solve(DYAD_RRR, &in, &out) == DYAD_STATUS_OK, "status");
    CHECK_VEC(out.r_mk, 375, 500);
    CHECK_VEC(out.r_np, -375, 500);
    CHECK_VEC(out.r_mn, -375, 0);
    CHECK_REAL(out.conditioning, 0.96);
    return fails;
}

/* Slider-crank: slider m on a horizontal guide, massless rod n inclined 30
 * degrees, gas force P = 1000 N pushing the slider towards the crank. The rod
 * carries P / cos(phi); the guide pushes down with P tan(phi). */
static int test_rrt_slider_crank_rod_force(void)
{
    int fails = 0;
    const double phi = PI / 6, P = 1000;
    dyad_input in = dyad_input_default();
    dyad_result out;
    in.guide_k = vec(1, 0);
    in.m.length = 0;
    in.m.dir = vec(1, 0);
    in.m.force = vec(-P, 0);
    in.n.dir = polar(1, phi);
    in.n.length = 0.2;
    CHECK(dyad_solve(DYAD_RRT, &in, &out) == DYAD_STATUS_OK, "status");
    CHECK_REAL(out.n_mk, -P * tan(phi));
    CHECK_VEC(out.r_mk, 0, -P * tan(phi));
    CHECK_VEC(out.r_np, P, P * tan(phi));
    CHECK_VEC(out.r_mn, P, P * tan(phi));
    CHECK_REAL(out.m_mk, 0);
    CHECK_REAL(out.conditioning, cos(phi));
    return fails;
}

/* Slider-crank at top dead centre with a 2 kg slider under gravity whose centre
 * of mass is 50 mm ahead of the pin: the rod carries P, the guide the weight
 * 19.62 N, and a moment 0.05 m * 19.62 N = 0.981 N m against the weight's. */
static int test_rrt_dead_centre_with_weight(void)
{
    int fails = 0;
    const double P = 1000, weight = 2 * 9.81;
    dyad_input in = dyad_input_default();
    dyad_result out;
    in.gravity = vec(0, -9.81);
    in.m.length = 0;
    in.m.mass = 2;
    in.m.com = vec(0.05, 0);
    in.m.force = vec(-P, 0);
    in.n.length = 0.2;
    CHECK(dyad_solve(DYAD_RRT, &in, &out) == DYAD_STATUS_OK, "status");
    CHECK_VEC(out.r_np, P, 0);
    CHECK_VEC(out.r_mk, 0, weight);
    CHECK_REAL(out.n_mk, weight);
    CHECK_REAL(out.m_mk, 0.05 * weight);
    return fails;
}

/* Slotted lever: pivot D_m, slot along x, block pinned on the slot line at
 * 0.5 m; a moment of 100 N m on the lever is held by the block with a normal
 * force of 200 N. */
static int test_rtr_lever_torque(void)
{
    int fails = 0;
    dyad_input in = dyad_input_default();
    dyad_result out;
    in.m.length = 0.5;
    in.m.moment = 100;
    in.n.length = 0;
    CHECK(dyad_solve(DYAD_RTR, &in, &out) == DYAD_STATUS_OK, "status");
    CHECK_REAL(out.n_mn, -200);
    CHECK_VEC(out.r_mn, 0, -200);
    CHECK_VEC(out.r_np, 0, -200);
    CHECK_VEC(out.r_mk, 0, 200);
    CHECK_REAL(out.m_mn, 0);
    return fails;
}

/* Two sliders on perpendicular guides pinned at E; slider m's pin stands 0.2 m
 * above its guide. A load (300, -400) N on m at D_m is held by N_mk = 400 N and
 * N_np = 300 N; the pin force 300 N at 0.2 m needs a guide moment of -60 N m. */
static int test_trt_cross_slide(void)
{
    int fails = 0;
    dyad_input in = dyad_input_default();
    dyad_result out;
    in.guide_k = vec(1, 0);
    in.guide_p = vec(0, 1);
    in.m.dir = vec(0, 1);
    in.m.length = 0.2;
    in.m.force = vec(300, -400);
    in.n.length = 0;
    CHECK(dyad_solve(DYAD_TRT, &in, &out) == DYAD_STATUS_OK, "status");
    CHECK_REAL(out.n_mk, 400);
    CHECK_REAL(out.n_np, 300);
    CHECK_VEC(out.r_mk, 0, 400);
    CHECK_VEC(out.r_np, -300, 0);
    CHECK_VEC(out.r_mn, -300, 0);
    CHECK_REAL(out.m_mk, -60);
    CHECK_REAL(out.m_np, 0);
    return fails;
}

/* Scotch yoke: yoke m slides on a horizontal guide, slot vertical, block on the
 * slot 0.1 m above D_m; a resisting force of 500 N on the yoke at D_m. The crank
 * pushes with 500 N and the guide holds the couple 0.1 m * 500 N = 50 N m. */
static int test_rtt_scotch_yoke(void)
{
    int fails = 0;
    dyad_input in = dyad_input_default();
    dyad_result out;
    in.guide_k = vec(1, 0);
    in.m.dir = vec(0, 1);
    in.m.length = 0.1;
    in.m.force = vec(-500, 0);
    in.n.dir = vec(0, 1);
    in.n.length = 0;
    CHECK(dyad_solve(DYAD_RTT, &in, &out) == DYAD_STATUS_OK, "status");
    CHECK_REAL(out.n_mk, 0);
    CHECK_REAL(out.n_mn, -500);
    CHECK_VEC(out.r_mn, 500, 0);
    CHECK_VEC(out.r_np, 500, 0);
    CHECK_REAL(out.m_mk, 50);
    CHECK_REAL(out.m_mn, 0);
    return fails;
}

/* A spinning link: an RRR with only inertia. Link m rotates about a fixed D_m
 * at omega with its centre of mass at 0.25 m on the axis; link n is massless
 * and aligned so that it carries no force. The pivot must supply the
 * centripetal force m omega^2 r towards D_m. */
static int test_rrr_centripetal(void)
{
    int fails = 0;
    const double mass = 3, omega = 20, r = 0.25;
    dyad_input in = dyad_input_default();
    dyad_result out;
    in.m.dir = vec(0, 1);
    in.m.length = 0.5;
    in.m.omega = (dyad_real)omega;
    in.m.mass = (dyad_real)mass;
    in.m.com = vec(r, 0);
    in.n.dir = vec(1, 0);
    in.n.length = 0.4;
    CHECK(dyad_solve(DYAD_RRR, &in, &out) == DYAD_STATUS_OK, "status");
    /* n is a two-force member along x, m must be held along y: R_mn = 0. */
    CHECK_VEC(out.r_mk, 0, -mass * omega * omega * r);
    CHECK_VEC(out.r_np, 0, 0);
    CHECK_VEC(out.r_mn, 0, 0);
    return fails;
}

/* ---- invalid input -------------------------------------------------------------------------- */

/* A valid configuration of every type: a generic one from the random set. */
static dyad_input valid_input(dyad_type type)
{
    rng r = {42u + (uint64_t)type};
    for (;;) {
        dyad_input in = random_input(&r, type);
        in.m.length = in.n.length = 0.5;
        if (independent_conditioning(type, &in) > 0.3) {
            return in;
        }
    }
}

typedef struct real_field {
    dyad_field field;
    size_t offset;
    int guide; /* 0: always read; 1: guide_k; 2: guide_p */
} real_field;

static const real_field real_fields[] = {
    {DYAD_FIELD_M_DIR, offsetof(dyad_input, m.dir.x), 0},
    {DYAD_FIELD_M_DIR, offsetof(dyad_input, m.dir.y), 0},
    {DYAD_FIELD_M_LENGTH, offsetof(dyad_input, m.length), 0},
    {DYAD_FIELD_M_OMEGA, offsetof(dyad_input, m.omega), 0},
    {DYAD_FIELD_M_EPSILON, offsetof(dyad_input, m.epsilon), 0},
    {DYAD_FIELD_M_ACCEL_D, offsetof(dyad_input, m.accel_d.x), 0},
    {DYAD_FIELD_M_ACCEL_D, offsetof(dyad_input, m.accel_d.y), 0},
    {DYAD_FIELD_M_COM, offsetof(dyad_input, m.com.x), 0},
    {DYAD_FIELD_M_COM, offsetof(dyad_input, m.com.y), 0},
    {DYAD_FIELD_M_MASS, offsetof(dyad_input, m.mass), 0},
    {DYAD_FIELD_M_INERTIA, offsetof(dyad_input, m.inertia), 0},
    {DYAD_FIELD_M_FORCE, offsetof(dyad_input, m.force.x), 0},
    {DYAD_FIELD_M_FORCE, offsetof(dyad_input, m.force.y), 0},
    {DYAD_FIELD_M_MOMENT, offsetof(dyad_input, m.moment), 0},
    {DYAD_FIELD_N_DIR, offsetof(dyad_input, n.dir.x), 0},
    {DYAD_FIELD_N_DIR, offsetof(dyad_input, n.dir.y), 0},
    {DYAD_FIELD_N_LENGTH, offsetof(dyad_input, n.length), 0},
    {DYAD_FIELD_N_OMEGA, offsetof(dyad_input, n.omega), 0},
    {DYAD_FIELD_N_EPSILON, offsetof(dyad_input, n.epsilon), 0},
    {DYAD_FIELD_N_ACCEL_D, offsetof(dyad_input, n.accel_d.x), 0},
    {DYAD_FIELD_N_ACCEL_D, offsetof(dyad_input, n.accel_d.y), 0},
    {DYAD_FIELD_N_COM, offsetof(dyad_input, n.com.x), 0},
    {DYAD_FIELD_N_COM, offsetof(dyad_input, n.com.y), 0},
    {DYAD_FIELD_N_MASS, offsetof(dyad_input, n.mass), 0},
    {DYAD_FIELD_N_INERTIA, offsetof(dyad_input, n.inertia), 0},
    {DYAD_FIELD_N_FORCE, offsetof(dyad_input, n.force.x), 0},
    {DYAD_FIELD_N_FORCE, offsetof(dyad_input, n.force.y), 0},
    {DYAD_FIELD_N_MOMENT, offsetof(dyad_input, n.moment), 0},
    {DYAD_FIELD_GUIDE_K, offsetof(dyad_input, guide_k.x), 1},
    {DYAD_FIELD_GUIDE_K, offsetof(dyad_input, guide_k.y), 1},
    {DYAD_FIELD_GUIDE_P, offsetof(dyad_input, guide_p.x), 2},
    {DYAD_FIELD_GUIDE_P, offsetof(dyad_input, guide_p.y), 2},
    {DYAD_FIELD_GRAVITY, offsetof(dyad_input, gravity.x), 0},
    {DYAD_FIELD_GRAVITY, offsetof(dyad_input, gravity.y), 0},
    {DYAD_FIELD_SINGULAR_THRESHOLD, offsetof(dyad_input, singular_threshold), 0},
};

static dyad_real* field_at(dyad_input* in, size_t offset)
{
    return (dyad_real*)((char*)in + offset);
}

static int expect_invalid(dyad_type type, const dyad_input* in, dyad_field field, const char* what)
{
    int fails = 0;
    dyad_result out;
    const dyad_status status = dyad_solve(type, in, &out);
    CHECK(status == DYAD_STATUS_INVALID_INPUT && out.status == status && out.field == field,
          "%s, %s: status %s, field '%s', expected invalid input in '%s'", dyad_type_name(type),
          what, dyad_status_name(status), dyad_field_name(out.field), dyad_field_name(field));
    CHECK(all_outputs_nan(&out), "%s, %s: outputs not NaN", dyad_type_name(type), what);
    return fails;
}

static int test_invalid_nonfinite(void)
{
    int fails = 0;
    const dyad_real bad_values[3] = {(dyad_real)NAN, (dyad_real)INFINITY, -(dyad_real)INFINITY};
    int t;
    size_t f, v;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        const dyad_input base = valid_input(type);
        dyad_result out;
        CHECK(dyad_solve(type, &base, &out) == DYAD_STATUS_OK, "%s: base case not ok",
              dyad_type_name(type));
        for (f = 0; f < sizeof real_fields / sizeof real_fields[0]; ++f) {
            const real_field* rf = &real_fields[f];
            const int read = rf->guide == 0 ||
                             (rf->guide == 1 &&
                              dyad_pair_kind_of(type, DYAD_PAIR_DM) == DYAD_PAIR_TRANSLATIONAL) ||
                             (rf->guide == 2 &&
                              dyad_pair_kind_of(type, DYAD_PAIR_DN) == DYAD_PAIR_TRANSLATIONAL);
            for (v = 0; v < 3; ++v) {
                dyad_input in = base;
                *field_at(&in, rf->offset) = bad_values[v];
                if (read) {
                    fails += expect_invalid(type, &in, rf->field, "non-finite value");
                } else {
                    CHECK(dyad_solve(type, &in, &out) == DYAD_STATUS_OK,
                          "%s: unused %s must be ignored", dyad_type_name(type),
                          dyad_field_name(rf->field));
                }
            }
        }
    }
    return fails;
}

static int test_invalid_domain(void)
{
    int fails = 0;
    int t;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        const dyad_input base = valid_input(type);
        const int zero_m = dyad_length_may_be_zero(type, DYAD_LINK_M);
        const int zero_n = dyad_length_may_be_zero(type, DYAD_LINK_N);
        dyad_input in;
        dyad_result out;

        in = base, in.m.length = -1e-3f;
        fails += expect_invalid(type, &in, DYAD_FIELD_M_LENGTH, "negative l_m");
        in = base, in.n.length = -1e-3f;
        fails += expect_invalid(type, &in, DYAD_FIELD_N_LENGTH, "negative l_n");
        in = base, in.m.length = 0;
        if (zero_m) {
            CHECK(dyad_solve(type, &in, &out) != DYAD_STATUS_INVALID_INPUT, "%s: l_m = 0 allowed",
                  dyad_type_name(type));
        } else {
            fails += expect_invalid(type, &in, DYAD_FIELD_M_LENGTH, "zero l_m");
        }
        in = base, in.n.length = 0;
        if (zero_n) {
            CHECK(dyad_solve(type, &in, &out) != DYAD_STATUS_INVALID_INPUT, "%s: l_n = 0 allowed",
                  dyad_type_name(type));
        } else {
            fails += expect_invalid(type, &in, DYAD_FIELD_N_LENGTH, "zero l_n");
        }
        in = base, in.m.mass = -1;
        fails += expect_invalid(type, &in, DYAD_FIELD_M_MASS, "negative mass");
        in = base, in.n.mass = -1e-9f;
        fails += expect_invalid(type, &in, DYAD_FIELD_N_MASS, "negative mass");
        in = base, in.m.inertia = -1;
        fails += expect_invalid(type, &in, DYAD_FIELD_M_INERTIA, "negative inertia");
        in = base, in.n.inertia = -1;
        fails += expect_invalid(type, &in, DYAD_FIELD_N_INERTIA, "negative inertia");

        in = base, in.m.dir = vec(2, 0);
        fails += expect_invalid(type, &in, DYAD_FIELD_M_DIR, "i_m of length 2");
        in = base, in.n.dir = vec(0, 0);
        fails += expect_invalid(type, &in, DYAD_FIELD_N_DIR, "zero i_n");
        in = base, in.m.dir = vec(1, 0.01);
        fails += expect_invalid(type, &in, DYAD_FIELD_M_DIR, "i_m off unit by 1e-4");
        if (dyad_pair_kind_of(type, DYAD_PAIR_DM) == DYAD_PAIR_TRANSLATIONAL) {
            in = base, in.guide_k = vec(0.6, 0.6);
            fails += expect_invalid(type, &in, DYAD_FIELD_GUIDE_K, "non-unit guide i_k");
        }
        if (dyad_pair_kind_of(type, DYAD_PAIR_DN) == DYAD_PAIR_TRANSLATIONAL) {
            in = base, in.guide_p = vec(0, -0.5);
            fails += expect_invalid(type, &in, DYAD_FIELD_GUIDE_P, "non-unit guide i_p");
        }
        /* Within the tolerance a direction is accepted and normalised. */
        in = base, in.m.dir = dyad_scale(1 + (dyad_real)1e-7, base.m.dir);
        CHECK(dyad_solve(type, &in, &out) == DYAD_STATUS_OK, "%s: near-unit i_m rejected",
              dyad_type_name(type));

        in = base, in.singular_threshold = 0;
        fails += expect_invalid(type, &in, DYAD_FIELD_SINGULAR_THRESHOLD, "zero threshold");
        in = base, in.singular_threshold = -1e-3f;
        fails += expect_invalid(type, &in, DYAD_FIELD_SINGULAR_THRESHOLD, "negative threshold");
        in = base, in.singular_threshold = 1;
        fails += expect_invalid(type, &in, DYAD_FIELD_SINGULAR_THRESHOLD, "threshold 1");
    }
    {
        const dyad_input in = valid_input(DYAD_RRR);
        dyad_result out;
        CHECK(dyad_solve((dyad_type)99, &in, &out) == DYAD_STATUS_INVALID_INPUT &&
                  out.field == DYAD_FIELD_TYPE && all_outputs_nan(&out),
              "unknown type not rejected");
        CHECK(dyad_solve(DYAD_RTR, NULL, &out) == DYAD_STATUS_INVALID_INPUT &&
                  out.field == DYAD_FIELD_INPUT,
              "NULL input not rejected");
        CHECK(dyad_solve_trt(&in, NULL) == DYAD_STATUS_INVALID_INPUT, "NULL result not rejected");
        CHECK(strcmp(dyad_field_name(DYAD_FIELD_N_LENGTH), "link_n.length") == 0, "field name");
    }
    return fails;
}

/* Loads so large that the resultants overflow: reported, never inf. */
static int test_out_of_range(void)
{
    int fails = 0;
    int t;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        dyad_input in = valid_input(type);
        dyad_result out;
        in.m.mass = HUGE_REAL;
        in.m.accel_d = vec(HUGE_REAL, 0);
        CHECK(dyad_solve(type, &in, &out) == DYAD_STATUS_OUT_OF_RANGE && all_outputs_nan(&out),
              "%s: overflow not reported (status %s)", dyad_type_name(type),
              dyad_status_name(out.status));
    }
    return fails;
}

/* ---- singular positions --------------------------------------------------------------------- */

/* A configuration of the type at distance delta (rad or relative length) from
 * its singular position, with loads that the singular dyad cannot carry. */
static dyad_input near_singular(dyad_type type, double delta, int variant)
{
    dyad_input in = dyad_input_default();
    const double base = 0.7;
    in.m.length = 0.5;
    in.n.length = 0.3;
    in.m.force = vec(120, -80);
    in.n.force = vec(-30, 200);
    in.m.moment = 15;
    in.n.moment = -7;
    in.m.com = vec(0.2, 0.05);
    in.n.com = vec(0.1, -0.02);
    in.m.mass = 2;
    in.n.mass = 1;
    in.m.dir = polar(1, base);
    in.guide_k = polar(1, base - 0.4);
    switch (type) {
    case DYAD_RRR: /* links aligned */ in.n.dir = polar(1, base + delta); break;
    case DYAD_RRT: /* rod normal to the guide */
        in.n.dir = polar(1, base - 0.4 + PI / 2 - delta);
        break;
    case DYAD_TRT: /* parallel guides */
        in.n.dir = polar(1, base + 1);
        in.guide_p = polar(1, base - 0.4 + delta);
        break;
    case DYAD_RTT: /* slot parallel to the guide */
        in.n.dir = polar(1, base + 1);
        in.m.dir = polar(1, base - 0.4 + delta);
        break;
    case DYAD_RTR:
        if (variant == 0) { /* slot normal to D_m D_n: l_n i_n = l_m i_m - (delta, 1) l_m rotated */
            const double complex i_m = cexp(I * base);
            const double complex ln_in = 0.5 * i_m * (1 - delta - I);
            in.n.dir = vec(creal(ln_in / cabs(ln_in)), cimag(ln_in / cabs(ln_in)));
            in.n.length = (dyad_real)cabs(ln_in);
        } else { /* D_n approaching D_m along the slot */
            in.n.dir = in.m.dir;
            in.n.length = (dyad_real)(0.5 * (1 - delta));
        }
        break;
    case DYAD_TYPE_COUNT: break;
    }
    return in;
}

static int test_singular(void)
{
    int fails = 0;
    int t, variant;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        for (variant = 0; variant < (type == DYAD_RTR ? 2 : 1); ++variant) {
            dyad_input in = near_singular(type, 0, variant);
            dyad_result out;
            double previous = 0;
            int k, switched = 0;
            CHECK(dyad_solve(type, &in, &out) == DYAD_STATUS_SINGULAR && all_outputs_nan(&out) &&
                      out.field == DYAD_FIELD_NONE,
                  "%s/%d: exact singular position: status %s", dyad_type_name(type), variant,
                  dyad_status_name(out.status));
            CHECK(out.conditioning < 10 * DYAD_REAL_EPSILON, "%s/%d: conditioning %.3g at singular",
                  dyad_type_name(type), variant, (double)out.conditioning);
            /* Approach: delta = 1e-1 ... 1e-12. */
            for (k = 1; k <= 12; ++k) {
                const double delta = pow(10, -k);
                dyad_status status;
                in = near_singular(type, delta, variant);
                status = dyad_solve(type, &in, &out);
                /* 1 / conditioning, the geometric part of the amplification (all
                 * of it once singular), strictly growing while delta is resolved
                 * in the scalar type; the data factor on top is at least 1. */
                CHECK(1 / out.conditioning > previous ||
                          (delta < 1e3 * DYAD_REAL_EPSILON && 1 / out.conditioning >= previous),
                      "%s/%d: 1 / conditioning %.3g not growing at %.0e", dyad_type_name(type),
                      variant, 1 / (double)out.conditioning, delta);
                CHECK(status == DYAD_STATUS_OK ? out.amplification >= 1 / out.conditioning
                                               : out.amplification == 1 / out.conditioning,
                      "%s/%d: amplification %.3g, 1 / conditioning %.3g at %.0e",
                      dyad_type_name(type), variant, (double)out.amplification,
                      1 / (double)out.conditioning, delta);
                previous = 1 / out.conditioning;
                if (out.conditioning >= in.singular_threshold) {
                    CHECK(status == DYAD_STATUS_OK && !switched,
                          "%s/%d: status %s above threshold at %.0e", dyad_type_name(type), variant,
                          dyad_status_name(status), delta);
                    CHECK(dyad_imbalance(&in, &out, 0, 1 + I).dyad <
                              RESIDUAL_LIMIT * 100 * (double)out.amplification,
                          "%s/%d: residual at %.0e", dyad_type_name(type), variant, delta);
                } else {
                    switched = 1;
                    CHECK(status == DYAD_STATUS_SINGULAR && all_outputs_nan(&out),
                          "%s/%d: status %s below threshold at %.0e", dyad_type_name(type), variant,
                          dyad_status_name(status), delta);
                }
            }
            CHECK(switched, "%s/%d: never reported singular down to 1e-12", dyad_type_name(type),
                  variant);
            /* The caller's threshold is honoured. */
            in = near_singular(type, 1e-2, variant);
            in.singular_threshold = 0.5;
            CHECK(dyad_solve(type, &in, &out) == DYAD_STATUS_SINGULAR,
                  "%s/%d: threshold 0.5 not honoured", dyad_type_name(type), variant);
        }
    }
    return fails;
}

/* A non-finite input is named even where the configuration is also singular
 * (or overflows): invalid input takes precedence. */
static int test_invalid_before_singular(void)
{
    int fails = 0;
    int t;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        dyad_input in = near_singular(type, 0, 0);
        in.n.force.y = (dyad_real)NAN;
        fails += expect_invalid(type, &in, DYAD_FIELD_N_FORCE, "NaN force at a singular position");
        in = near_singular(type, 0.3, 0);
        in.m.omega = (dyad_real)INFINITY;
        fails += expect_invalid(type, &in, DYAD_FIELD_M_OMEGA, "infinite omega");
        in = near_singular(type, 0.3, 0);
        in.n.length = (dyad_real)INFINITY;
        fails += expect_invalid(type, &in, DYAD_FIELD_N_LENGTH, "infinite length");
    }
    return fails;
}

/* ---- runner --------------------------------------------------------------------------------- */

/* ---- the closed forms on reduced loads (dyadfmu/loaded.h) ----------------------------------- */

/* |x| + |y| of a complex number. */
static double cnorm1(double complex z)
{
    return fabs(creal(z)) + fabs(cimag(z));
}

/* Link g reduced by hand: a_S = a_D + (i eps - omega^2) r in complex numbers,
 * F = force + m (g - a_S), M = moment - J eps, and the moment about D; and the
 * sizes of those sums as loaded.h defines them (the magnitudes of their terms). */
static dyad_loaded_link loaded_link_of(const dyad_link* link, dyad_vec2 gravity)
{
    const double complex i_g = unit(link->dir);
    const double complex r = ((double)link->com.x + I * (double)link->com.y) * i_g;
    const double complex a_s =
        cvec(link->accel_d) + (I * (double)link->epsilon - (double)link->omega * link->omega) * r;
    const double complex f = cvec(link->force) + (double)link->mass * (cvec(gravity) - a_s);
    const double m = (double)link->moment - (double)link->inertia * link->epsilon;
    dyad_loaded_link out;
    out.i = vec(creal(i_g), cimag(i_g));
    out.j = vec(-cimag(i_g), creal(i_g));
    out.l = link->length;
    out.f = vec(creal(f), cimag(f));
    out.m = (dyad_real)m;
    out.m_d = (dyad_real)(m + creal(r) * cimag(f) - cimag(r) * creal(f));
    {
        /* every term but the centripetal one, which has no moment about D */
        const double lever = cnorm1(r);
        const double straight = cnorm1(cvec(link->force)) +
                                link->mass * (cnorm1(cvec(gravity)) + cnorm1(cvec(link->accel_d)) +
                                              fabs((double)link->epsilon) * lever);
        out.f_size = (dyad_real)(straight + link->mass * link->omega * link->omega * lever);
        out.m_d_size = (dyad_real)(fabs((double)link->moment) +
                                   link->inertia * fabs((double)link->epsilon) + lever * straight);
    }
    return out;
}

/* The dyad of an input with its links' loads reduced independently of the core. */
static dyad_loaded loaded_of(const dyad_input* in)
{
    dyad_loaded loaded;
    loaded.m = loaded_link_of(&in->m, in->gravity);
    loaded.n = loaded_link_of(&in->n, in->gravity);
    loaded.i_k = in->guide_k;
    loaded.j_k = vec(-in->guide_k.y, in->guide_k.x);
    loaded.i_p = in->guide_p;
    loaded.j_p = vec(-in->guide_p.y, in->guide_p.x);
    loaded.singular_threshold = in->singular_threshold;
    return loaded;
}

static double result_distance(const dyad_result* a, const dyad_result* b)
{
    const double d[] = {a->r_mk.x - b->r_mk.x, a->r_mk.y - b->r_mk.y, a->r_np.x - b->r_np.x,
                        a->r_np.y - b->r_np.y, a->r_mn.x - b->r_mn.x, a->r_mn.y - b->r_mn.y,
                        a->n_mk - b->n_mk,     a->n_np - b->n_np,     a->n_mn - b->n_mn,
                        a->m_mk - b->m_mk,     a->m_np - b->m_np,     a->m_mn - b->m_mn};
    const double s[] = {a->r_mk.x, a->r_mk.y, a->r_np.x, a->r_np.y, a->r_mn.x, a->r_mn.y,
                        a->n_mk,   a->n_np,   a->n_mn,   a->m_mk,   a->m_np,   a->m_mn};
    double worst = 0, scale = 0;
    size_t k;
    for (k = 0; k < sizeof d / sizeof d[0]; ++k) {
        worst = fabs(d[k]) > worst ? fabs(d[k]) : worst;
        scale = fabs(s[k]) > scale ? fabs(s[k]) : scale;
    }
    return worst / (scale > 0 ? scale : 1);
}

/* dyad_solve_valid_<type> against dyad_solve_<type>, bit for bit, on valid inputs:
 * random ones, and near-singular and exactly singular ones (statuses included);
 * and dyad_check_input naming what dyad_solve refuses. */
static int test_solve_valid_matches_solve(void)
{
    static const dyad_solver valid[DYAD_TYPE_COUNT] = {dyad_solve_valid_rrr, dyad_solve_valid_rrt,
                                                       dyad_solve_valid_rtr, dyad_solve_valid_trt,
                                                       dyad_solve_valid_rtt};
    int fails = 0;
    int t, k;
    rng r = {20261126u};
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        int singular = 0;
        for (k = 0; k < 2014; ++k) {
            /* the last 14: exactly singular, then approaching it */
            const dyad_input in = k < 2000
                                      ? random_input(&r, type)
                                      : near_singular(type, k == 2000 ? 0 : pow(10, 2000 - k), 0);
            dyad_result want, got;
            const dyad_status status = dyad_solve(type, &in, &want);
            CHECK(dyad_check_input(type, &in) == DYAD_FIELD_NONE, "%s case %d: refused (%s)",
                  dyad_type_name(type), k, dyad_field_name(dyad_check_input(type, &in)));
            CHECK(valid[t](&in, &got) == status && memcmp(&got, &want, sizeof got) == 0,
                  "%s case %d: valid solve %s, solve %s (R_mn.x %.17g, %.17g)",
                  dyad_type_name(type), k, dyad_status_name(got.status), dyad_status_name(status),
                  (double)got.r_mn.x, (double)want.r_mn.x);
            singular += status == DYAD_STATUS_SINGULAR;
        }
        CHECK(singular > 0, "%s: no singular case compared", dyad_type_name(type));
    }
    {
        dyad_input in = valid_input(DYAD_RRR);
        CHECK(dyad_check_input(DYAD_TYPE_COUNT, &in) == DYAD_FIELD_TYPE, "unknown type not named");
        CHECK(dyad_check_input(DYAD_RRR, NULL) == DYAD_FIELD_INPUT, "NULL input not named");
        in.n.mass = -1;
        CHECK(dyad_check_input(DYAD_RRR, &in) == DYAD_FIELD_N_MASS, "negative mass: %s",
              dyad_field_name(dyad_check_input(DYAD_RRR, &in)));
        in = valid_input(DYAD_RRR), in.m.length = 0;
        CHECK(dyad_check_input(DYAD_RRR, &in) == DYAD_FIELD_M_LENGTH &&
                  dyad_check_input(DYAD_RRT, &in) == DYAD_FIELD_NONE,
              "RRR refuses l_m = 0, RRT allows it");
    }
    return fails;
}

static int test_react_loaded(void)
{
    static dyad_status (*const react[DYAD_TYPE_COUNT])(const dyad_loaded*, dyad_result*) = {
        dyad_react_rrr, dyad_react_rrt, dyad_react_rtr, dyad_react_trt, dyad_react_rtt};
    int fails = 0;
    int t;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x10ADED00u + (uint64_t)t};
        double worst = 0;
        int solved = 0, singular = 0;
        while (solved < 2000) {
            const dyad_input in = random_input(&r, type);
            dyad_loaded loaded = loaded_of(&in);
            dyad_result want, got;
            loaded.singular_threshold = independent_conditioning(type, &in) < WELL_CONDITIONED
                                            ? (dyad_real)0.99
                                            : in.singular_threshold;
            dyad_solve(type, &in, &want);
            react[t](&loaded, &got);
            if (loaded.singular_threshold > (dyad_real)0.9) {
                /* a threshold no conditioning reaches: singular, NaN outputs */
                ++singular;
                CHECK(got.status == DYAD_STATUS_SINGULAR && all_outputs_nan(&got),
                      "%s: status %s with a threshold of 0.99", dyad_type_name(type),
                      dyad_status_name(got.status));
                continue;
            }
            if (want.status != DYAD_STATUS_OK) {
                continue;
            }
            ++solved;
            CHECK(got.status == DYAD_STATUS_OK, "%s: status %s", dyad_type_name(type),
                  dyad_status_name(got.status));
            CHECK(fabs((double)got.conditioning - (double)want.conditioning) <=
                      64 * DYAD_REAL_EPSILON,
                  "%s: conditioning %.9g, dyad_solve %.9g", dyad_type_name(type),
                  (double)got.conditioning, (double)want.conditioning);
            {
                /* the two reductions round differently; the closed forms amplify that */
                const double distance = result_distance(&want, &got) * (double)want.conditioning;
                worst = distance > worst ? distance : worst;
            }
            /* the same loads and sizes give the same amplification, to the
             * difference of the largest outputs the two reductions give */
            CHECK(fabs((double)got.amplification - (double)want.amplification) <=
                          sqrt(DYAD_REAL_EPSILON) * (double)want.amplification &&
                      got.amplification >= 1 / got.conditioning,
                  "%s: amplification %.17g, dyad_solve %.17g", dyad_type_name(type),
                  (double)got.amplification, (double)want.amplification);
        }
        printf("    %s %s: %d solved, %d singular; worst difference from dyad_solve %.3e of the "
               "largest reaction times the amplification\n",
               dyad_type_name(type), REAL_NAME, solved, singular, worst);
        CHECK(worst < REACT_LIMIT, "%s: dyad_react differs from dyad_solve by %.3e",
              dyad_type_name(type), worst);
        {
            dyad_result out;
            CHECK(react[t](NULL, &out) == DYAD_STATUS_INVALID_INPUT &&
                      out.field == DYAD_FIELD_INPUT && all_outputs_nan(&out),
                  "%s: a NULL dyad is not rejected", dyad_type_name(type));
            CHECK(react[t](NULL, NULL) == DYAD_STATUS_INVALID_INPUT, "%s: NULL result",
                  dyad_type_name(type));
        }
    }
    return fails;
}

/* The tangent of one type (dyad_solve_tangent_of, what a one-type program
 * links) gives what dyad_solve_tangent gives for that type, bit for bit, and a
 * missing type is refused. */
static int test_tangent_of_each_type(void)
{
    static const dyad_tangent_type* const kinds[DYAD_TYPE_COUNT] = {
        &dyad_tangent_rrr, &dyad_tangent_rrt, &dyad_tangent_rtr, &dyad_tangent_trt,
        &dyad_tangent_rtt};
    int fails = 0;
    int t, k;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x7A4E0000u + (uint64_t)t};
        int ok = 0;
        for (k = 0; k < 200; ++k) {
            const dyad_input in = random_input(&r, type);
            const dyad_input seed = random_input(&r, type);
            dyad_result value_a, rate_a, value_b, rate_b;
            const dyad_status a = dyad_solve_tangent(type, &in, &seed, &value_a, &rate_a);
            const dyad_status b = dyad_solve_tangent_of(kinds[t], &in, &seed, &value_b, &rate_b);
            ok += a == DYAD_STATUS_OK;
            CHECK(a == b && memcmp(&value_a, &value_b, sizeof value_a) == 0 &&
                      memcmp(&rate_a, &rate_b, sizeof rate_a) == 0,
                  "%s: dyad_solve_tangent_of differs from dyad_solve_tangent (sample %d)",
                  dyad_type_name(type), k);
        }
        CHECK(ok > 100, "%s: only %d of 200 samples solved", dyad_type_name(type), ok);
    }
    {
        const dyad_input in = dyad_input_default();
        dyad_result value, rate;
        CHECK(dyad_solve_tangent_of(NULL, &in, &in, &value, &rate) == DYAD_STATUS_INVALID_INPUT,
              "a NULL type is not refused");
    }
    return fails;
}

/* ---- the tangent of the closed forms on reduced loads (dyad_react_tangent_<type>) ----------- */

#ifdef DYAD_REAL_FLOAT
#define REACT_FD_STEP  2e-2
#define REACT_FD_LIMIT 3e-2
#else
#define REACT_FD_STEP  1e-3
#define REACT_FD_LIMIT 1e-7
#endif

/* The reactions, conditioning and amplification of a result, as numbers. */
#define REACT_OUTPUTS 14
static void react_outputs(const dyad_result* r, double v[REACT_OUTPUTS])
{
    const double all[REACT_OUTPUTS] = {
        r->r_mk.x, r->r_mk.y, r->r_np.x, r->r_np.y, r->r_mn.x, r->r_mn.y,       r->n_mk,
        r->n_np,   r->n_mn,   r->m_mk,   r->m_np,   r->m_mn,   r->conditioning, r->amplification};
    memcpy(v, all, sizeof all);
}

/* A unit vector turned at the rate its seed's normal part gives, by tau. */
static dyad_vec2 turned_by(dyad_vec2 i, dyad_vec2 di, double tau)
{
    return polar(1, atan2((double)i.y, (double)i.x) + tau * dyad_cross(i, di));
}

static void move_loaded_link(dyad_loaded_link* to, const dyad_loaded_link* a,
                             const dyad_loaded_link* s, double tau)
{
    to->i = turned_by(a->i, s->i, tau);
    to->j = dyad_perp(to->i);
    to->l = (dyad_real)(a->l + tau * s->l);
    to->f = vec(a->f.x + tau * s->f.x, a->f.y + tau * s->f.y);
    to->m = (dyad_real)(a->m + tau * s->m);
    to->m_d = (dyad_real)(a->m_d + tau * s->m_d);
    to->f_size = (dyad_real)(a->f_size + tau * s->f_size);
    to->m_d_size = (dyad_real)(a->m_d_size + tau * s->m_d_size);
}

static dyad_loaded moved_loaded(const dyad_loaded* a, const dyad_loaded* s, double tau)
{
    dyad_loaded b = *a;
    move_loaded_link(&b.m, &a->m, &s->m, tau);
    move_loaded_link(&b.n, &a->n, &s->n, tau);
    b.i_k = turned_by(a->i_k, s->i_k, tau);
    b.j_k = dyad_perp(b.i_k);
    b.i_p = turned_by(a->i_p, s->i_p, tau);
    b.j_p = dyad_perp(b.i_p);
    return b;
}

/* A seed of a loaded link: every field moves, in proportion to its size. */
static dyad_loaded_link random_loaded_seed(rng* r, const dyad_loaded_link* a)
{
    dyad_loaded_link s;
    s.i = dyad_scale((dyad_real)uniform(r, -1, 1), a->i);
    s.i = dyad_add(s.i, dyad_scale((dyad_real)uniform(r, -1, 1), a->j));
    s.j = dyad_perp(s.i);
    s.l = (dyad_real)(a->l * uniform(r, -0.5, 0.5));
    s.f = vec(uniform(r, -1, 1) * dyad_norm1(a->f), uniform(r, -1, 1) * dyad_norm1(a->f));
    s.m = (dyad_real)(uniform(r, -1, 1) * fabs((double)a->m));
    s.m_d = (dyad_real)(uniform(r, -1, 1) * fabs((double)a->m_d));
    s.f_size = (dyad_real)(uniform(r, -0.5, 0.5) * a->f_size);
    s.m_d_size = (dyad_real)(uniform(r, -0.5, 0.5) * a->m_d_size);
    return s;
}

/* dyad_react_tangent_<type> against fourth-order central differences of
 * dyad_react_<type> along the same seed: every reaction, the conditioning
 * and the amplification; the value bit for bit the plain solve's. */
static int test_react_tangent_finite_differences(void)
{
    static dyad_status (*const react[DYAD_TYPE_COUNT])(const dyad_loaded*, dyad_result*) = {
        dyad_react_rrr, dyad_react_rrt, dyad_react_rtr, dyad_react_trt, dyad_react_rtt};
    static dyad_status (*const tangent[DYAD_TYPE_COUNT])(const dyad_loaded*, const dyad_loaded*,
                                                         dyad_result*, dyad_result*) = {
        dyad_react_tangent_rrr, dyad_react_tangent_rrt, dyad_react_tangent_rtr,
        dyad_react_tangent_trt, dyad_react_tangent_rtt};
    static const double taus[4] = {-2, -1, 1, 2};
    int fails = 0;
    int t, k, j;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x7A46E47u + (uint64_t)t};
        double worst = 0;
        int solved = 0, smooth = 0;
        while (solved < 500) {
            const dyad_input in = random_input(&r, type);
            dyad_loaded a, s;
            dyad_result plain, value, rate, moved[4];
            double v[4][REACT_OUTPUTS], d[REACT_OUTPUTS], scale = 0, level = 0;
            int ok = 1;
            a = loaded_of(&in);
            s = a;
            s.m = random_loaded_seed(&r, &a.m);
            s.n = random_loaded_seed(&r, &a.n);
            s.i_k = dyad_scale((dyad_real)uniform(&r, -1, 1), a.j_k);
            s.i_p = dyad_scale((dyad_real)uniform(&r, -1, 1), a.j_p);
            if (tangent[t](&a, &s, &value, &rate) != DYAD_STATUS_OK ||
                value.conditioning < WELL_CONDITIONED) {
                continue;
            }
            react[t](&a, &plain);
            CHECK(memcmp(&plain, &value, sizeof plain) == 0, "%s: the value is not dyad_react's",
                  dyad_type_name(type));
            for (k = 0; k < 4; ++k) {
                const dyad_loaded b = moved_loaded(&a, &s, taus[k] * REACT_FD_STEP);
                ok &= react[t](&b, &moved[k]) == DYAD_STATUS_OK;
                react_outputs(&moved[k], v[k]);
            }
            if (!ok) {
                continue;
            }
            ++solved;
            react_outputs(&rate, d);
            for (j = 0; j < 12; ++j) {
                const double fd =
                    (8 * (v[2][j] - v[1][j]) - (v[3][j] - v[0][j])) / (12 * REACT_FD_STEP);
                scale = fabs(fd) > scale ? fabs(fd) : scale;
                level = fabs(v[1][j]) > level ? fabs(v[1][j]) : level;
                d[j] -= fd;
            }
            for (j = 12; j < REACT_OUTPUTS; ++j) {
                /* the conditioning and amplification have kinks (|x|, the larger of
                 * two sizes) that a difference may straddle: most samples agree */
                const double fd =
                    (8 * (v[2][j] - v[1][j]) - (v[3][j] - v[0][j])) / (12 * REACT_FD_STEP);
                smooth += fabs(d[j] - fd) <= REACT_FD_LIMIT * (fabs(fd) + fabs(v[1][j]));
            }
            for (j = 0; j < 12; ++j) {
                /* against the rate's own scale and the reactions' (a zero rate) */
                const double error = fabs(d[j]) / (scale + level) / (double)value.amplification;
                worst = error > worst ? error : worst;
            }
        }
        printf("    %s %s: %d samples; worst difference of the reactions from central "
               "differences %.3e; conditioning and amplification agree in %d of %d\n",
               dyad_type_name(type), REAL_NAME, solved, worst, smooth, 2 * solved);
        CHECK(smooth >= 2 * solved * 95 / 100,
              "%s: the conditioning's or amplification's rate "
              "differs in %d of %d",
              dyad_type_name(type), 2 * solved - smooth, 2 * solved);
        CHECK(worst < REACT_FD_LIMIT, "%s: dyad_react_tangent differs by %.3e",
              dyad_type_name(type), worst);
    }
    {
        const dyad_loaded* none = NULL;
        dyad_result value, rate;
        CHECK(dyad_react_tangent_rrt(none, none, &value, &rate) == DYAD_STATUS_INVALID_INPUT,
              "a NULL dyad is not refused");
    }
    return fails;
}

/* ---- kinematics (dyadfmu/kinematics.h) -------------------------------------------------------
 * Each configuration is built from the dyad outwards: smooth paths in time t of
 * E, the link angles, the slides and the guides' angles, from which the mounts
 * follow (D_m = E - l_m i_m, a guide's point G = D - s i, ...). Every path is
 * carried as a jet (value, first and second derivative in t) in double complex
 * arithmetic, here and independently of the core: the mounts' velocities and
 * accelerations are then exact inputs, and the dyad's own jets are the
 * expected outputs. */

#ifdef DYAD_REAL_FLOAT
/* Inputs rounded to float: the configuration is closed to 6e-8, and its
 * outputs move by that times the amplification. */
#define KIN_LIMIT 2e-3
/* Finite differences in float: steps large enough that the rounding of the
 * positions (eps / h, eps / h^2) stays below the tolerance. */
#define KIN_FD_STEP      0.02
#define KIN_TANGENT_STEP 5e-4
#define KIN_FD_LIMIT     3e-2
#else
#define KIN_LIMIT        1e-10
#define KIN_FD_STEP      4e-3
/* A random seed moves every input at once: a shorter step keeps the
 * samples inside the region where the dyad closes. */
#define KIN_TANGENT_STEP 2e-5
#define KIN_FD_LIMIT     1e-7
#endif
#define KIN_SAMPLES 2000
/* The least conditioning of the random samples (their closure at least its square):
 * float's amplification reaches 1 / threshold (2.9e3) at a closure near 7e-4. */
#ifdef DYAD_REAL_FLOAT
#define KIN_LEAST 0.1
#else
#define KIN_LEAST 0.05
#endif

/* A scalar and a planar (complex) quantity with their first two time derivatives. */
typedef struct sjet {
    double v, d, dd;
} sjet;
typedef struct vjet {
    double complex v, d, dd;
} vjet;

/* a + b t + c t^2 + amp sin(freq t + phase): a smooth path in time. */
typedef struct path {
    double a, b, c, amp, freq, phase;
} path;

static sjet path_at(const path* p, double t)
{
    const double s = sin(p->freq * t + p->phase), c = cos(p->freq * t + p->phase);
    sjet j;
    j.v = p->a + p->b * t + p->c * t * t + p->amp * s;
    j.d = p->b + 2 * p->c * t + p->amp * p->freq * c;
    j.dd = 2 * p->c - p->amp * p->freq * p->freq * s;
    return j;
}

static path random_path(rng* r, double lo, double hi, double rate)
{
    path p;
    p.a = uniform(r, lo, hi);
    p.b = uniform(r, -rate, rate);
    p.c = uniform(r, -rate, rate) / 2;
    p.amp = uniform(r, -rate, rate) / 4;
    p.freq = uniform(r, 0.5, 2);
    p.phase = uniform(r, -PI, PI);
    return p;
}

static sjet sconst(double v)
{
    sjet j = {v, 0, 0};
    return j;
}

/* e^(i theta) */
static vjet vpolar(sjet th)
{
    vjet j;
    j.v = cexp(I * th.v);
    j.d = I * th.d * j.v;
    j.dd = (I * th.dd - th.d * th.d) * j.v;
    return j;
}

/* a u, a scalar jet times a planar one */
static vjet vscale(sjet a, vjet u)
{
    vjet j;
    j.v = a.v * u.v;
    j.d = a.d * u.v + a.v * u.d;
    j.dd = a.dd * u.v + 2 * a.d * u.d + a.v * u.dd;
    return j;
}

/* u times a constant complex number */
static vjet vtimes(vjet u, double complex c)
{
    vjet j = {u.v * c, u.d * c, u.dd * c};
    return j;
}

static vjet vsub(vjet a, vjet b)
{
    vjet j = {a.v - b.v, a.d - b.d, a.dd - b.dd};
    return j;
}

static vjet vadd(vjet a, vjet b)
{
    vjet j = {a.v + b.v, a.d + b.d, a.dd + b.dd};
    return j;
}

static dyad_vec2 cv(double complex z)
{
    return vec(creal(z), cimag(z));
}

static dyad_point_motion motion_of(vjet j)
{
    dyad_point_motion m;
    m.position = cv(j.v);
    m.velocity = cv(j.d);
    m.acceleration = cv(j.dd);
    return m;
}

/* The random parameters of one configuration's motion. */
typedef struct kin_case {
    dyad_type type;
    path ex, ey;        /* E */
    path th_m, th_n;    /* link angles, where free */
    path phi_k, phi_p;  /* guide angles */
    path s_k, s_p, l_m; /* slides; l_m where E slides on m */
    double l_m0, l_n;   /* constant lengths */
    double delta_m, delta_n;
    double complex com_m, com_n;
} kin_case;

/* The built dyad at time t: what the core should find. */
typedef struct kin_built {
    vjet e, d_m, d_n, g_k, g_p, i_m, i_n, i_k, i_p;
    sjet th_m, th_n, phi_k, phi_p, s_k, s_p, l_m;
    double l_n;
    int branch;
} kin_built;

static kin_case random_kin_case(rng* r, dyad_type type)
{
    kin_case c;
    c.type = type;
    c.ex = random_path(r, -1, 1, 1);
    c.ey = random_path(r, -1, 1, 1);
    c.th_m = random_path(r, -PI, PI, 2);
    c.th_n = random_path(r, -PI, PI, 2);
    c.phi_k = random_path(r, -PI, PI, 1);
    c.phi_p = random_path(r, -PI, PI, 1);
    c.s_k = random_path(r, -1, 1, 1);
    c.s_p = random_path(r, -1, 1, 1);
    c.l_m = random_path(r, 0.8, 2, 0.3);
    c.l_m0 = uniform(r, 0.3, 2);
    c.l_n = uniform(r, 0.3, 2);
    c.delta_m = uniform(r, -PI, PI);
    c.delta_n = uniform(r, -PI, PI);
    c.com_m = uniform(r, -1, 1) + I * uniform(r, -1, 1);
    c.com_n = uniform(r, -1, 1) + I * uniform(r, -1, 1);
    if (type == DYAD_TRT || type == DYAD_RRT) {
        c.l_m0 = uniform(r, 0, 1) < 0.2 ? 0 : c.l_m0; /* a pin on the guide */
    }
    if (type != DYAD_RRR && type != DYAD_RRT && uniform(r, 0, 1) < 0.2) {
        c.l_n = 0;
    }
    return c;
}

static int sign_of(double x)
{
    return x < 0 ? -1 : 1;
}

/* The link angles, guides and lengths of the type at t. */
static void build_angles(const kin_case* c, double t, kin_built* b)
{
    const int d_m_slides = c->type == DYAD_RRT || c->type == DYAD_TRT || c->type == DYAD_RTT;
    b->phi_k = path_at(&c->phi_k, t);
    b->phi_p = path_at(&c->phi_p, t);
    b->th_m = path_at(&c->th_m, t);
    b->th_n = path_at(&c->th_n, t);
    if (d_m_slides) {
        b->th_m = b->phi_k;
        b->th_m.v += c->delta_m;
    }
    if (c->type == DYAD_TRT) {
        b->th_n = b->phi_p;
        b->th_n.v += c->delta_n;
    } else if (c->type == DYAD_RTR || c->type == DYAD_RTT) {
        b->th_n = b->th_m;
        b->th_n.v += c->delta_n;
    }
    b->l_m = c->type == DYAD_RTR || c->type == DYAD_RTT ? path_at(&c->l_m, t) : sconst(c->l_m0);
    b->l_n = c->l_n;
    b->i_m = vpolar(b->th_m);
    b->i_n = vpolar(b->th_n);
    b->i_k = vpolar(b->phi_k);
    b->i_p = vpolar(b->phi_p);
}

static kin_built build(const kin_case* c, double t)
{
    kin_built b;
    vjet e;
    build_angles(c, t, &b);
    e.v = path_at(&c->ex, t).v + I * path_at(&c->ey, t).v;
    e.d = path_at(&c->ex, t).d + I * path_at(&c->ey, t).d;
    e.dd = path_at(&c->ex, t).dd + I * path_at(&c->ey, t).dd;
    b.e = e;
    b.d_m = vsub(e, vscale(b.l_m, b.i_m));
    b.d_n = vsub(e, vscale(sconst(b.l_n), b.i_n));
    b.s_k = b.s_p = sconst(0);
    if (c->type == DYAD_RRT || c->type == DYAD_TRT || c->type == DYAD_RTT) {
        b.s_k = path_at(&c->s_k, t);
    }
    if (c->type == DYAD_TRT) {
        b.s_p = path_at(&c->s_p, t);
    }
    b.g_k = vsub(b.d_m, vscale(b.s_k, b.i_k));
    b.g_p = vsub(b.d_n, vscale(b.s_p, b.i_p));
    switch (c->type) {
    case DYAD_RRR: b.branch = sign_of(cimag((e.v - b.d_m.v) * conj(b.d_n.v - b.d_m.v))); break;
    case DYAD_RRT: b.branch = sign_of(creal((e.v - b.d_n.v) * conj(b.i_k.v))); break;
    case DYAD_RTR: b.branch = sign_of(b.l_m.v - b.l_n * cos(c->delta_n)); break;
    default: b.branch = 1; break;
    }
    return b;
}

static void set_mount(dyad_mount* m, vjet point, vjet guide, sjet angle, int slides)
{
    m->point = motion_of(point);
    if (slides) {
        m->guide = cv(guide.v);
        m->omega = (dyad_real)angle.d;
        m->epsilon = (dyad_real)angle.dd;
    }
}

/* The core's input at t (branch as built). */
static dyad_kin_input kin_input_at(const kin_case* c, double t, kin_built* out)
{
    const kin_built b = build(c, t);
    const int slides_k = c->type == DYAD_RRT || c->type == DYAD_TRT || c->type == DYAD_RTT;
    const int slides_p = c->type == DYAD_TRT;
    dyad_kin_input in = dyad_kin_input_default();
    set_mount(&in.k, slides_k ? b.g_k : b.d_m, b.i_k, b.phi_k, slides_k);
    set_mount(&in.p, slides_p ? b.g_p : b.d_n, b.i_p, b.phi_p, slides_p);
    in.length_m = (dyad_real)c->l_m0;
    in.length_n = (dyad_real)c->l_n;
    in.turn_m = cv(cexp(I * c->delta_m));
    in.turn_n = cv(cexp(I * c->delta_n));
    in.com_m = cv(c->com_m);
    in.com_n = cv(c->com_n);
    in.branch = b.branch;
    if (out != NULL) {
        *out = b;
    }
    return in;
}

/* The header's conditioning, from the built directions. */
static double built_conditioning(dyad_type type, const kin_built* b)
{
    const double complex i_m = b->i_m.v, i_n = b->i_n.v, i_k = b->i_k.v, i_p = b->i_p.v;
    switch (type) {
    case DYAD_RRR: return fabs(cimag(i_n * conj(i_m)));
    case DYAD_RRT: return fabs(creal(i_n * conj(i_k)));
    case DYAD_TRT: return fabs(cimag(i_p * conj(i_k)));
    case DYAD_RTT: return fabs(cimag(i_m * conj(i_k)));
    default: {
        const double complex d = b->d_n.v - b->d_m.v;
        const double slant = fabs(creal(d * conj(i_m))) / cabs(d);
        const double spread = cabs(d) / (b->l_m.v + b->l_n);
        return slant < spread ? slant : spread;
    }
    }
}

/* The sum of the absolute values of a vector's components. */
static double norm1(double complex v)
{
    return fabs(creal(v)) + fabs(cimag(v));
}

/* The header's closure, from the built dyad: the distance from the toggle or
 * branch point over the size of the terms it is formed from. */
static double built_closure(dyad_type type, const kin_built* b)
{
    const double l_m = b->l_m.v, l_n = b->l_n;
    double distance, size;
    switch (type) {
    case DYAD_RRR: {
        const double reach = cabs(b->d_n.v - b->d_m.v);
        const double far = l_m + l_n - reach, near = reach - fabs(l_m - l_n);
        distance = far < near ? far : near;
        size = l_m + l_n + reach;
        break;
    }
    case DYAD_RRT: {
        /* D_n from the line E runs on: through G_k + l_m i_m along i_k */
        const double off = fabs(cimag((b->d_n.v - b->g_k.v - l_m * b->i_m.v) * conj(b->i_k.v)));
        distance = l_n - off;
        size = l_n + off + norm1(b->g_k.v) + l_m + norm1(b->d_n.v);
        break;
    }
    case DYAD_RTR: {
        const double dist = cabs(b->d_n.v - b->d_m.v);
        const double reach = l_n * fabs(cimag(b->i_n.v * conj(b->i_m.v)));
        distance = dist - reach;
        size = dist + reach;
        break;
    }
    default: return 1; /* TRT, RTT: no root */
    }
    return distance / size;
}

/* Every output of a result, raw, in a fixed order (KIN_RAW numbers). */
#define KIN_RAW 53

static int put_motion(double* v, int k, const dyad_point_motion* p)
{
    v[k] = p->position.x, v[k + 1] = p->position.y;
    v[k + 2] = p->velocity.x, v[k + 3] = p->velocity.y;
    v[k + 4] = p->acceleration.x, v[k + 5] = p->acceleration.y;
    return k + 6;
}

static int put_link(double* v, int k, const dyad_kin_link* g)
{
    v[k] = g->dir.x, v[k + 1] = g->dir.y, v[k + 2] = g->omega, v[k + 3] = g->epsilon;
    v[k + 4] = g->length, v[k + 5] = g->length_rate, v[k + 6] = g->length_accel;
    return put_motion(v, put_motion(v, k + 7, &g->d), &g->com);
}

static void kin_raw(const dyad_kin_result* r, double v[KIN_RAW])
{
    int k = put_link(v, put_link(v, 0, &r->m), &r->n);
    k = put_motion(v, k, &r->e);
    v[k] = r->slide_k.s, v[k + 1] = r->slide_k.rate, v[k + 2] = r->slide_k.accel;
    v[k + 3] = r->slide_p.s, v[k + 4] = r->slide_p.rate, v[k + 5] = r->slide_p.accel;
    v[k + 6] = r->conditioning, v[k + 7] = r->closure, v[k + 8] = r->amplification;
}

/* 1 if two results hold the same outputs, bit for bit (NaN as NaN). */
static int kin_same(const dyad_kin_result* a, const dyad_kin_result* b)
{
    double x[KIN_RAW], y[KIN_RAW];
    int k;
    kin_raw(a, x);
    kin_raw(b, y);
    for (k = 0; k < KIN_RAW; ++k) {
        if (!(x[k] == y[k] || (isnan(x[k]) && isnan(y[k])))) {
            return 0;
        }
    }
    return a->status == b->status && a->field == b->field && a->failure == b->failure &&
           (a->gap == b->gap || (isnan(a->gap) && isnan(b->gap)));
}

static void jet_motion(dyad_point_motion* p, vjet j)
{
    *p = motion_of(j);
}

static void jet_link(dyad_kin_link* g, vjet dir, sjet angle, sjet length, vjet d,
                     double complex com)
{
    g->dir = cv(dir.v);
    g->omega = (dyad_real)angle.d;
    g->epsilon = (dyad_real)angle.dd;
    g->length = (dyad_real)length.v;
    g->length_rate = (dyad_real)length.d;
    g->length_accel = (dyad_real)length.dd;
    jet_motion(&g->d, d);
    jet_motion(&g->com, vadd(d, vtimes(dir, com)));
}

/* The result the built dyad should give, in the raw order (in double). */
static void expected_raw(const kin_case* c, const kin_built* b, double v[KIN_RAW])
{
    dyad_kin_result r;
    const double cond = built_conditioning(c->type, b), closure = built_closure(c->type, b);
    const double amplification = 1 + 1 / closure + 1 / cond; /* mounts known exactly */
    jet_link(&r.m, b->i_m, b->th_m, b->l_m, b->d_m, c->com_m);
    jet_link(&r.n, b->i_n, b->th_n, sconst(b->l_n), b->d_n, c->com_n);
    jet_motion(&r.e, b->e);
    r.slide_k.s = (dyad_real)b->s_k.v, r.slide_k.rate = (dyad_real)b->s_k.d;
    r.slide_k.accel = (dyad_real)b->s_k.dd;
    r.slide_p.s = (dyad_real)b->s_p.v, r.slide_p.rate = (dyad_real)b->s_p.d;
    r.slide_p.accel = (dyad_real)b->s_p.dd;
    r.conditioning = (dyad_real)cond;
    r.closure = (dyad_real)closure;
    r.amplification = (dyad_real)amplification;
    kin_raw(&r, v);
    /* the narrowing above is undone where double matters */
    v[KIN_RAW - 3] = cond;
    v[KIN_RAW - 2] = closure;
    v[KIN_RAW - 1] = amplification;
}

/* Worst of |got - want| / (1 + |want|) over n numbers. */
static double worst_error(const double* got, const double* want, int n)
{
    double worst = 0;
    int k;
    for (k = 0; k < n; ++k) {
        const double e = fabs(got[k] - want[k]) / (1 + fabs(want[k]));
        worst = e > worst || e != e ? e : worst;
    }
    return worst;
}

/* A random closed configuration of the type, conditioned at least `least`. */
static kin_case conditioned_case(rng* r, dyad_type type, double least, dyad_kin_input* in,
                                 kin_built* b)
{
    for (;;) {
        const kin_case c = random_kin_case(r, type);
        *in = kin_input_at(&c, 0, b);
        /* the closure falls like the conditioning squared */
        if (built_conditioning(type, b) >= least && built_closure(type, b) >= least * least) {
            return c;
        }
    }
}

/* (a) E closes from both links, the pair points sit on their guides, the
 * locked directions are locked; (b) the result is the built dyad, rates and
 * accelerations included (the jets are exact). */
static int test_kin_reproduces_built(void)
{
    int fails = 0, t, k;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x4B490000u + (uint64_t)t};
        double worst = 0, closure = 0;
        for (k = 0; k < KIN_SAMPLES; ++k) {
            dyad_kin_input in;
            kin_built b;
            dyad_kin_result out;
            double got[KIN_RAW], want[KIN_RAW];
            const kin_case c = conditioned_case(&r, type, KIN_LEAST, &in, &b);
            const dyad_status s = dyad_kinematics(type, &in, &out);
            if (s != DYAD_STATUS_OK) {
                CHECK(0, "%s sample %d: status %s", dyad_type_name(type), k, dyad_status_name(s));
                continue;
            }
            {
                const double complex e_m = cvec(out.m.d.position) + out.m.length * cvec(out.m.dir);
                const double complex e_n = cvec(out.n.d.position) + out.n.length * cvec(out.n.dir);
                double gap = cabs(e_m - e_n) + cabs(e_n - cvec(out.e.position));
                if (type == DYAD_RRT || type == DYAD_TRT || type == DYAD_RTT) {
                    gap += cabs(cvec(in.k.point.position) + out.slide_k.s * unit(in.k.guide) -
                                cvec(out.m.d.position));
                    gap += cabs(cvec(out.m.dir) - unit(in.turn_m) * unit(in.k.guide));
                }
                if (type == DYAD_TRT) {
                    gap += cabs(cvec(in.p.point.position) + out.slide_p.s * unit(in.p.guide) -
                                cvec(out.n.d.position));
                    gap += cabs(cvec(out.n.dir) - unit(in.turn_n) * unit(in.p.guide));
                }
                if (type == DYAD_RTR || type == DYAD_RTT) {
                    gap += cabs(cvec(out.n.dir) - unit(in.turn_n) * cvec(out.m.dir));
                }
                closure = gap > closure ? gap : closure;
            }
            kin_raw(&out, got);
            expected_raw(&c, &b, want);
            {
                const double e = worst_error(got, want, KIN_RAW) * out.conditioning;
                worst = e > worst ? e : worst;
                CHECK(e < KIN_LIMIT, "%s sample %d: off the built dyad by %.3g",
                      dyad_type_name(type), k, e);
            }
        }
        CHECK(closure < 40 * KIN_LIMIT, "%s: closure off by %.3g", dyad_type_name(type), closure);
        printf("    %s: worst closure %.3g, worst error x conditioning %.3g\n",
               dyad_type_name(type), closure, worst);
    }
    return fails;
}

/* The positions of a result and their time derivatives as the result states
 * them: dir (by omega k0 x dir, epsilon k0 x dir - omega^2 dir), lengths, D_m,
 * D_n, E, the centres of mass and the slides (KIN_POS numbers each). */
#define KIN_POS 18

static int put_dir(double* v, int k, const dyad_kin_link* g, int order)
{
    const double complex i = cvec(g->dir);
    const double complex z = order == 0   ? i
                             : order == 1 ? I * g->omega * i
                                          : (I * g->epsilon - g->omega * g->omega) * i;
    v[k] = creal(z), v[k + 1] = cimag(z);
    return k + 2;
}

static int put_point(double* v, int k, const dyad_point_motion* p, int order)
{
    const dyad_vec2 z = order == 0 ? p->position : order == 1 ? p->velocity : p->acceleration;
    v[k] = z.x, v[k + 1] = z.y;
    return k + 2;
}

static double order_of(double q, double rate, double accel, int order)
{
    return order == 0 ? q : order == 1 ? rate : accel;
}

/* order 0: positions; 1: their velocities; 2: their accelerations. */
static void kin_positions(const dyad_kin_result* r, int order, double v[KIN_POS])
{
    int k = put_dir(v, put_dir(v, 0, &r->m, order), &r->n, order);
    v[k++] = order_of(r->m.length, r->m.length_rate, r->m.length_accel, order);
    v[k++] = order_of(r->n.length, r->n.length_rate, r->n.length_accel, order);
    k = put_point(v, put_point(v, put_point(v, k, &r->m.d, order), &r->n.d, order), &r->e, order);
    k = put_point(v, put_point(v, k, &r->m.com, order), &r->n.com, order);
    v[k++] = order_of(r->slide_k.s, r->slide_k.rate, r->slide_k.accel, order);
    v[k] = order_of(r->slide_p.s, r->slide_p.rate, r->slide_p.accel, order);
}

/* First and second derivative at 0 of f, sampled at -h, -h/2, 0, h/2, h, by
 * central differences with one Richardson step: errors O(h^4). */
static void richardson(const double f[5][KIN_RAW], int n, double h, double* d1, double* d2)
{
    int k;
    for (k = 0; k < n; ++k) {
        const double c1 = (f[4][k] - f[0][k]) / (2 * h);
        const double c1_half = (f[3][k] - f[1][k]) / h;
        const double c2 = (f[4][k] - 2 * f[2][k] + f[0][k]) / (h * h);
        const double c2_half = (f[3][k] - 2 * f[2][k] + f[1][k]) / (h * h / 4);
        d1[k] = (4 * c1_half - c1) / 3;
        d2[k] = (4 * c2_half - c2) / 3;
    }
}

static const double fd_steps[5] = {-1, -0.5, 0, 0.5, 1};

/* (c) The velocities and accelerations the core states are the time
 * derivatives of the positions it finds along the mounts' motion. A dropped
 * Coriolis, centripetal or tangential term fails this. */
static int test_kin_rates_finite_differences(void)
{
    int fails = 0, t, k, j;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x4B520000u + (uint64_t)t};
        double worst = 0;
        for (k = 0; k < KIN_SAMPLES / 10; ++k) {
            dyad_kin_input in;
            kin_built b;
            dyad_kin_result out;
            double f[5][KIN_RAW], d1[KIN_RAW], d2[KIN_RAW], v[KIN_POS], a[KIN_POS];
            const kin_case c = conditioned_case(&r, type, KIN_LEAST, &in, &b);
            int ok = dyad_kinematics(type, &in, &out) == DYAD_STATUS_OK;
            kin_positions(&out, 1, v);
            kin_positions(&out, 2, a);
            for (j = 0; j < 5; ++j) {
                dyad_kin_input at = kin_input_at(&c, fd_steps[j] * KIN_FD_STEP, NULL);
                dyad_kin_result o;
                at.branch = in.branch;
                ok &= dyad_kinematics(type, &at, &o) == DYAD_STATUS_OK;
                kin_positions(&o, 0, f[j]);
            }
            CHECK(ok, "%s sample %d: not solved", dyad_type_name(type), k);
            richardson((const double (*)[KIN_RAW])f, KIN_POS, KIN_FD_STEP, d1, d2);
            {
                const double e1 = worst_error(v, d1, KIN_POS) * out.conditioning;
                const double e2 = worst_error(a, d2, KIN_POS) * out.conditioning;
                const double e = e1 > e2 ? e1 : e2;
                worst = e > worst ? e : worst;
                CHECK(e < KIN_FD_LIMIT, "%s sample %d: velocities off by %.3g, accelerations %.3g",
                      dyad_type_name(type), k, e1, e2);
            }
        }
        printf("    %s: worst x conditioning %.3g\n", dyad_type_name(type), worst);
    }
    return fails;
}

static dyad_vec2 move_vec(dyad_vec2 v, dyad_vec2 s, double tau)
{
    return vec(v.x + tau * s.x, v.y + tau * s.y);
}

/* A unit vector turned by tau times the angle rate its seed gives. */
static dyad_vec2 turn_unit(dyad_vec2 u, dyad_vec2 s, double tau)
{
    const double complex z = unit(u);
    return cv(z * cexp(I * tau * cimag(conj(z) * cvec(s))));
}

static void move_mount(dyad_mount* m, const dyad_mount* s, double tau)
{
    m->point.position = move_vec(m->point.position, s->point.position, tau);
    m->point.velocity = move_vec(m->point.velocity, s->point.velocity, tau);
    m->point.acceleration = move_vec(m->point.acceleration, s->point.acceleration, tau);
    m->guide = turn_unit(m->guide, s->guide, tau);
    m->omega = (dyad_real)(m->omega + tau * s->omega);
    m->epsilon = (dyad_real)(m->epsilon + tau * s->epsilon);
}

/* The input moved by tau along the seed. */
static dyad_kin_input kin_moved(const dyad_kin_input* in, const dyad_kin_input* seed, double tau)
{
    dyad_kin_input x = *in;
    move_mount(&x.k, &seed->k, tau);
    move_mount(&x.p, &seed->p, tau);
    x.length_m = (dyad_real)(x.length_m + tau * seed->length_m);
    x.length_n = (dyad_real)(x.length_n + tau * seed->length_n);
    x.turn_m = turn_unit(x.turn_m, seed->turn_m, tau);
    x.turn_n = turn_unit(x.turn_n, seed->turn_n, tau);
    x.com_m = move_vec(x.com_m, seed->com_m, tau);
    x.com_n = move_vec(x.com_n, seed->com_n, tau);
    return x;
}

static dyad_vec2 random_vec(rng* r)
{
    return vec(uniform(r, -1, 1), uniform(r, -1, 1));
}

static void random_mount_seed(rng* r, dyad_mount* m)
{
    m->point.position = random_vec(r);
    m->point.velocity = random_vec(r);
    m->point.acceleration = random_vec(r);
    m->guide = random_vec(r);
    m->omega = (dyad_real)uniform(r, -1, 1);
    m->epsilon = (dyad_real)uniform(r, -1, 1);
}

/* A random seed; a length at 0 (its lower bound) stays. */
static dyad_kin_input random_seed(rng* r, const dyad_kin_input* in)
{
    static const dyad_kin_input zero;
    dyad_kin_input s = zero;
    random_mount_seed(r, &s.k);
    random_mount_seed(r, &s.p);
    s.length_m = in->length_m > 0 ? (dyad_real)uniform(r, -1, 1) : 0;
    s.length_n = in->length_n > 0 ? (dyad_real)uniform(r, -1, 1) : 0;
    s.turn_m = random_vec(r);
    s.turn_n = random_vec(r);
    s.com_m = random_vec(r);
    s.com_n = random_vec(r);
    return s;
}

/* (d) The tangent along random seeds is the derivative of the values. */
static int test_kin_tangent_finite_differences(void)
{
    int fails = 0, t, k, j;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x4B540000u + (uint64_t)t};
        double worst = 0;
        for (k = 0; k < KIN_SAMPLES / 10; ++k) {
            dyad_kin_input in;
            kin_built b;
            dyad_kin_result value, rate, plain;
            double f[5][KIN_RAW], d1[KIN_RAW], d2[KIN_RAW], got[KIN_RAW];
            int ok;
            (void)conditioned_case(&r, type, KIN_LEAST, &in, &b);
            {
                const dyad_kin_input seed = random_seed(&r, &in);
                ok = dyad_kinematics_tangent(type, &in, &seed, &value, &rate) == DYAD_STATUS_OK;
                ok &= dyad_kinematics(type, &in, &plain) == DYAD_STATUS_OK;
                CHECK(kin_same(&plain, &value),
                      "%s sample %d: the tangent's value differs from dyad_kinematics",
                      dyad_type_name(type), k);
                for (j = 0; j < 5; ++j) {
                    const dyad_kin_input at = kin_moved(&in, &seed, fd_steps[j] * KIN_TANGENT_STEP);
                    dyad_kin_result o;
                    ok &= dyad_kinematics(type, &at, &o) == DYAD_STATUS_OK;
                    kin_raw(&o, f[j]);
                }
            }
            CHECK(ok, "%s sample %d: not solved", dyad_type_name(type), k);
            richardson((const double (*)[KIN_RAW])f, KIN_RAW, KIN_TANGENT_STEP, d1, d2);
            kin_raw(&rate, got);
            {
                const double e = worst_error(got, d1, KIN_RAW) * value.conditioning;
                worst = e > worst ? e : worst;
                CHECK(e < KIN_FD_LIMIT, "%s sample %d: tangent off by %.3g", dyad_type_name(type),
                      k, e);
            }
        }
        printf("    %s: worst x conditioning %.3g\n", dyad_type_name(type), worst);
    }
    return fails;
}

/* The seed that moves the mounts as they move in time: positions by their
 * velocities, velocities by their accelerations, a guide by omega, omega by
 * epsilon. */
static dyad_kin_input motion_seed(const dyad_kin_input* in)
{
    static const dyad_kin_input zero;
    dyad_kin_input s = zero;
    const dyad_mount* from[2] = {&in->k, &in->p};
    dyad_mount* to[2] = {&s.k, &s.p};
    int g;
    for (g = 0; g < 2; ++g) {
        to[g]->point.position = from[g]->point.velocity;
        to[g]->point.velocity = from[g]->point.acceleration;
        to[g]->guide = dyad_scale(from[g]->omega, dyad_perp(from[g]->guide));
        to[g]->omega = from[g]->epsilon;
    }
    return s;
}

/* The velocity-level outputs (accel 0) or their acceleration-level
 * counterparts (accel 1), in matching order: KIN_VEL numbers. */
#define KIN_VEL 16

static int put_rate_level(double* v, int k, const dyad_kin_link* g, int accel)
{
    const dyad_vec2 d = accel ? g->d.acceleration : g->d.velocity;
    const dyad_vec2 s = accel ? g->com.acceleration : g->com.velocity;
    v[k] = accel ? g->epsilon : g->omega;
    v[k + 1] = accel ? g->length_accel : g->length_rate;
    v[k + 2] = d.x, v[k + 3] = d.y, v[k + 4] = s.x, v[k + 5] = s.y;
    return k + 6;
}

static void kin_rate_level(const dyad_kin_result* r, int accel, double v[KIN_VEL])
{
    const int k = put_rate_level(v, put_rate_level(v, 0, &r->m, accel), &r->n, accel);
    const dyad_vec2 e = accel ? r->e.acceleration : r->e.velocity;
    v[k] = e.x, v[k + 1] = e.y;
    v[k + 2] = accel ? r->slide_k.accel : r->slide_k.rate;
    v[k + 3] = accel ? r->slide_p.accel : r->slide_p.rate;
}

/* (d) Along the motion seed, the tangent of each position is the velocity the
 * core states, and that of each velocity the acceleration, to round-off. */
static int test_kin_tangent_along_motion(void)
{
    int fails = 0, t, k;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x4B4D0000u + (uint64_t)t};
        double worst = 0;
        for (k = 0; k < KIN_SAMPLES; ++k) {
            dyad_kin_input in, seed;
            kin_built b;
            dyad_kin_result value, rate;
            double p1[KIN_POS], v0[KIN_POS], v1[KIN_VEL], a0[KIN_VEL], e1, e2;
            (void)conditioned_case(&r, type, KIN_LEAST, &in, &b);
            seed = motion_seed(&in);
            CHECK(dyad_kinematics_tangent(type, &in, &seed, &value, &rate) == DYAD_STATUS_OK,
                  "%s sample %d: not solved", dyad_type_name(type), k);
            kin_positions(&rate, 0, p1);
            kin_positions(&value, 1, v0);
            kin_rate_level(&rate, 0, v1);
            kin_rate_level(&value, 1, a0);
            e1 = worst_error(p1, v0, KIN_POS) * value.conditioning;
            e2 = worst_error(v1, a0, KIN_VEL) * value.conditioning;
            e1 = e1 > e2 ? e1 : e2;
            worst = e1 > worst ? e1 : worst;
            CHECK(e1 < KIN_LIMIT, "%s sample %d: rates off by %.3g", dyad_type_name(type), k, e1);
        }
        printf("    %s: worst x conditioning %.3g\n", dyad_type_name(type), worst);
    }
    return fails;
}

/* 1 if every motion output is NaN (and, with conditioning, also those two). */
static int kin_all_nan(const dyad_kin_result* r, int with_figures)
{
    double v[KIN_RAW];
    int k;
    kin_raw(r, v);
    /* the figures (conditioning, closure, amplification) come last */
    for (k = 0; k < KIN_RAW - (with_figures ? 0 : 3); ++k) {
        if (!isnan(v[k])) {
            return 0;
        }
    }
    return 1;
}

/* A dyad with D_m at the origin and D_n at (x, y); guides along x. */
static dyad_kin_input kin_plain_input(double x, double y, double l_m, double l_n)
{
    dyad_kin_input in = dyad_kin_input_default();
    in.p.point.position = vec(x, y);
    in.length_m = (dyad_real)l_m;
    in.length_n = (dyad_real)l_n;
    return in;
}

typedef struct kin_failure_case {
    dyad_type type;
    double x, y, l_m, l_n, delta_m, delta_n;
    int branch;
    dyad_kin_failure failure;
    double gap;
    double gap_rate; /* of the gap as D_n moves along +x */
} kin_failure_case;

/* (e) Each failure figure, with its gap and the gap's rate. */
static int test_kin_failures(void)
{
    static const kin_failure_case cases[] = {
        {DYAD_RRR, 5, 0, 1, 2, 0, 0, 1, DYAD_KIN_TOO_FAR, 2, 1},
        {DYAD_RRR, 0, -4, 1, 2, 0, 0, -1, DYAD_KIN_TOO_FAR, 1, 0},
        {DYAD_RRR, 0.5, 0, 3, 1, 0, 0, 1, DYAD_KIN_TOO_CLOSE, 1.5, -1},
        {DYAD_RRR, 0, 0.25, 1, 2, 0, 0, 1, DYAD_KIN_TOO_CLOSE, 0.75, 0},
        {DYAD_RRT, 0.3, 3, 0, 1, 0, 0, 1, DYAD_KIN_OFF_LINE, 2, 0},
        {DYAD_RRT, 0.3, -3, 0.5, 1, PI / 2, 0, -1, DYAD_KIN_OFF_LINE, 2.5, 0},
        {DYAD_RTR, 0.5, 0, 0, 1, 0, PI / 2, 1, DYAD_KIN_OFF_SLOT, 0.5, -1},
        {DYAD_RTR, 3, 0, 0, 1, 0, 0, -1, DYAD_KIN_BEHIND_PIVOT, 2, 1},
        {DYAD_RTR, -1, 0, 0, 3, 0, PI, 1, DYAD_KIN_BEHIND_PIVOT, 2, 1},
    };
    int fails = 0;
    size_t k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        const kin_failure_case* c = &cases[k];
        static const dyad_kin_input zero;
        dyad_kin_input in = kin_plain_input(c->x, c->y, c->l_m, c->l_n);
        dyad_kin_input seed = zero;
        dyad_kin_result out, value, rate;
        in.turn_m = cv(cexp(I * c->delta_m));
        in.turn_n = cv(cexp(I * c->delta_n));
        in.branch = c->branch;
        seed.p.point.position = vec(1, 0);
        CHECK(dyad_kinematics(c->type, &in, &out) == DYAD_STATUS_CANNOT_ASSEMBLE &&
                  out.status == DYAD_STATUS_CANNOT_ASSEMBLE,
              "case %zu: status %s", k, dyad_status_name(out.status));
        CHECK(out.failure == c->failure, "case %zu: failure %d (%s), want %d", k, out.failure,
              dyad_kin_failure_name(out.failure), c->failure);
        CHECK(fabs(out.gap - c->gap) <= 1e-6 * c->gap, "case %zu: gap %.17g, want %g", k,
              (double)out.gap, c->gap);
        CHECK(kin_all_nan(&out, 1), "case %zu: an output is not NaN", k);
        CHECK(out.field == DYAD_KIN_FIELD_NONE && strlen(dyad_kin_failure_name(out.failure)) > 0,
              "case %zu: field or failure name", k);
        CHECK(dyad_kinematics_tangent(c->type, &in, &seed, &value, &rate) ==
                      DYAD_STATUS_CANNOT_ASSEMBLE &&
                  kin_same(&value, &out),
              "case %zu: the tangent's value differs", k);
        CHECK(rate.failure == c->failure && fabs(rate.gap - c->gap_rate) <= 1e-6 &&
                  kin_all_nan(&rate, 1),
              "case %zu: gap rate %g, want %g", k, (double)rate.gap, c->gap_rate);
    }
    return fails;
}

/* (e) At a singular position the result is singular, the conditioning
 * stated, the outputs NaN. */
static int test_kin_singular(void)
{
    int fails = 0;
    size_t k;
    struct {
        dyad_type type;
        dyad_kin_input in;
    } cases[8];
    size_t count = 0;
    cases[count].type = DYAD_RRR, cases[count++].in = kin_plain_input(3, 0, 1, 2); /* stretched */
    cases[count].type = DYAD_RRR, cases[count++].in = kin_plain_input(0, 1, 3, 2); /* folded */
    cases[count].type = DYAD_RRR, cases[count++].in = kin_plain_input(0, 0, 2, 2); /* coincident */
    cases[count].type = DYAD_RRT, cases[count++].in = kin_plain_input(0.5, 1, 0, 1);
    cases[count].type = DYAD_RTR, cases[count++].in = kin_plain_input(0, 0, 0, 1);
    cases[count].type = DYAD_TRT, cases[count].in = kin_plain_input(2, 1, 1, 1);
    cases[count++].in.p.guide = vec(-1, 0); /* parallel guides */
    cases[count].type = DYAD_RTT, cases[count++].in = kin_plain_input(2, 1, 1, 1); /* i_m = i_k */
    cases[count].type = DYAD_RTT, cases[count].in = kin_plain_input(2, 1, 1, 1);
    cases[count++].in.turn_m = vec(-1, 0);
    for (k = 0; k < count; ++k) {
        const dyad_type type = cases[k].type;
        dyad_kin_result out, value, rate;
        static const dyad_kin_input zero;
        const dyad_status s = dyad_kinematics(type, &cases[k].in, &out);
        CHECK(s == DYAD_STATUS_SINGULAR && out.status == s, "%s case %zu: status %s",
              dyad_type_name(type), k, dyad_status_name(s));
        CHECK(out.conditioning >= 0 && out.conditioning < cases[k].in.singular_threshold &&
                  out.closure >= 0 && out.closure <= 1 &&
                  out.amplification == 1 + 1 / out.closure + 1 / out.conditioning &&
                  1 / out.amplification < cases[k].in.singular_threshold,
              "%s case %zu: conditioning %g, closure %g, amplification %g", dyad_type_name(type), k,
              (double)out.conditioning, (double)out.closure, (double)out.amplification);
        CHECK(kin_all_nan(&out, 0) && out.failure == DYAD_KIN_CLOSES && out.gap == 0,
              "%s case %zu: outputs not NaN", dyad_type_name(type), k);
        CHECK(dyad_kinematics_tangent(type, &cases[k].in, &zero, &value, &rate) == s &&
                  kin_same(&value, &out) && kin_all_nan(&rate, 0),
              "%s case %zu: the tangent differs", dyad_type_name(type), k);
    }
    return fails;
}

/* One number of the input, the field it belongs to, and the types that read it. */
typedef struct kin_real_field {
    size_t offset;
    dyad_kin_field field;
    unsigned types; /* bit t: type t reads it */
} kin_real_field;

#define KIN_ALL   0x1Fu
#define KIN_DM_T  ((1u << DYAD_RRT) | (1u << DYAD_TRT) | (1u << DYAD_RTT))
#define KIN_DN_T  (1u << DYAD_TRT)
#define KIN_LM    ((1u << DYAD_RRR) | (1u << DYAD_RRT) | (1u << DYAD_TRT))
#define KIN_TN    ((1u << DYAD_RTR) | (1u << DYAD_TRT) | (1u << DYAD_RTT))
#define KIN_AT(f) offsetof(dyad_kin_input, f)

static const kin_real_field kin_real_fields[] = {
    {KIN_AT(k.point.position.x), DYAD_KIN_FIELD_K_POSITION, KIN_ALL},
    {KIN_AT(k.point.position.y), DYAD_KIN_FIELD_K_POSITION, KIN_ALL},
    {KIN_AT(k.point.velocity.x), DYAD_KIN_FIELD_K_VELOCITY, KIN_ALL},
    {KIN_AT(k.point.acceleration.y), DYAD_KIN_FIELD_K_ACCELERATION, KIN_ALL},
    {KIN_AT(k.guide.x), DYAD_KIN_FIELD_K_GUIDE, KIN_DM_T},
    {KIN_AT(k.guide.y), DYAD_KIN_FIELD_K_GUIDE, KIN_DM_T},
    {KIN_AT(k.omega), DYAD_KIN_FIELD_K_OMEGA, KIN_DM_T},
    {KIN_AT(k.epsilon), DYAD_KIN_FIELD_K_EPSILON, KIN_DM_T},
    {KIN_AT(p.point.position.y), DYAD_KIN_FIELD_P_POSITION, KIN_ALL},
    {KIN_AT(p.point.velocity.x), DYAD_KIN_FIELD_P_VELOCITY, KIN_ALL},
    {KIN_AT(p.point.acceleration.x), DYAD_KIN_FIELD_P_ACCELERATION, KIN_ALL},
    {KIN_AT(p.guide.y), DYAD_KIN_FIELD_P_GUIDE, KIN_DN_T},
    {KIN_AT(p.omega), DYAD_KIN_FIELD_P_OMEGA, KIN_DN_T},
    {KIN_AT(p.epsilon), DYAD_KIN_FIELD_P_EPSILON, KIN_DN_T},
    {KIN_AT(length_m), DYAD_KIN_FIELD_LENGTH_M, KIN_LM},
    {KIN_AT(length_n), DYAD_KIN_FIELD_LENGTH_N, KIN_ALL},
    {KIN_AT(turn_m.x), DYAD_KIN_FIELD_TURN_M, KIN_DM_T},
    {KIN_AT(turn_n.y), DYAD_KIN_FIELD_TURN_N, KIN_TN},
    {KIN_AT(com_m.x), DYAD_KIN_FIELD_COM_M, KIN_ALL},
    {KIN_AT(com_n.y), DYAD_KIN_FIELD_COM_N, KIN_ALL},
    {KIN_AT(singular_threshold), DYAD_KIN_FIELD_SINGULAR_THRESHOLD, KIN_ALL},
};

static dyad_real* kin_real_at(dyad_kin_input* in, size_t offset)
{
    return (dyad_real*)(void*)((char*)in + offset);
}

/* The call is refused, naming `field`, with NaN outputs, in both entries. */
static int expect_kin_invalid(dyad_type type, const dyad_kin_input* in, dyad_kin_field field,
                              const char* what)
{
    int fails = 0;
    dyad_kin_result out, value, rate;
    const dyad_kin_input seed = *in;
    const dyad_status s = dyad_kinematics(type, in, &out);
    CHECK(s == DYAD_STATUS_INVALID_INPUT && out.field == field && kin_all_nan(&out, 1),
          "%s, %s: status %s, field '%s', want '%s'", dyad_type_name(type), what,
          dyad_status_name(s), dyad_kin_field_name(out.field), dyad_kin_field_name(field));
    CHECK(dyad_kinematics_tangent(type, in, &seed, &value, &rate) == DYAD_STATUS_INVALID_INPUT &&
              value.field == field && rate.field == field && kin_all_nan(&rate, 1),
          "%s, %s: the tangent names '%s'", dyad_type_name(type), what,
          dyad_kin_field_name(value.field));
    return fails;
}

/* (e) A non-finite number in each field a type reads is named; in a field it
 * does not read it is ignored. */
static int test_kin_invalid_nonfinite(void)
{
    int fails = 0, t;
    size_t f;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        rng r = {0x4B560000u + (uint64_t)t};
        dyad_kin_input base;
        kin_built b;
        dyad_kin_result good;
        (void)conditioned_case(&r, type, KIN_LEAST, &base, &b);
        CHECK(dyad_kinematics(type, &base, &good) == DYAD_STATUS_OK, "%s: base not solved",
              dyad_type_name(type));
        for (f = 0; f < sizeof kin_real_fields / sizeof kin_real_fields[0]; ++f) {
            const kin_real_field* field = &kin_real_fields[f];
            const double poisons[2] = {NAN, INFINITY};
            int p;
            for (p = 0; p < 2; ++p) {
                dyad_kin_input in = base;
                dyad_kin_result out;
                *kin_real_at(&in, field->offset) = (dyad_real)poisons[p];
                if (field->types & (1u << type)) {
                    fails += expect_kin_invalid(type, &in, field->field,
                                                dyad_kin_field_name(field->field));
                } else {
                    CHECK(dyad_kinematics(type, &in, &out) == DYAD_STATUS_OK &&
                              kin_same(&out, &good),
                          "%s: '%s' is not read, yet changes the result", dyad_type_name(type),
                          dyad_kin_field_name(field->field));
                }
            }
        }
    }
    return fails;
}

/* (e) Out-of-domain directions, lengths, branch and threshold are named; the
 * first in the order of dyad_kin_field wins. */
static int test_kin_invalid_domain(void)
{
    int fails = 0, t;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        const unsigned bit = 1u << type;
        rng r = {0x4B440000u + (uint64_t)t};
        dyad_kin_input base, in;
        kin_built b;
        dyad_kin_result out;
        (void)conditioned_case(&r, type, KIN_LEAST, &base, &b);
        if (bit & KIN_DM_T) {
            in = base, in.k.guide = dyad_scale((dyad_real)1.01, in.k.guide);
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_K_GUIDE, "long guide k");
            in = base, in.turn_m = dyad_scale((dyad_real)0.99, in.turn_m);
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_TURN_M, "short turn_m");
            in = base, in.k.guide = dyad_scale((dyad_real)(1 + 1e-7), in.k.guide);
            CHECK(dyad_kinematics(type, &in, &out) == DYAD_STATUS_OK,
                  "%s: a guide unit within the tolerance is refused", dyad_type_name(type));
        }
        if (bit & KIN_DN_T) {
            in = base, in.p.guide = vec(0, 0);
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_P_GUIDE, "zero guide p");
        }
        if (bit & KIN_TN) {
            in = base, in.turn_n = dyad_scale(2, in.turn_n);
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_TURN_N, "long turn_n");
        }
        in = base, in.length_n = -1;
        fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_LENGTH_N, "negative l_n");
        if (type == DYAD_RRR || type == DYAD_RRT) {
            in = base, in.length_n = 0;
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_LENGTH_N, "zero l_n");
        }
        if (bit & KIN_LM) {
            in = base, in.length_m = type == DYAD_RRR ? 0 : (dyad_real)-0.5;
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_LENGTH_M, "l_m out of domain");
        }
        in = base, in.branch = 0;
        if (type == DYAD_RRR || type == DYAD_RRT || type == DYAD_RTR) {
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_BRANCH, "branch 0");
            in.branch = 2;
            fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_BRANCH, "branch 2");
        } else {
            CHECK(dyad_kinematics(type, &in, &out) == DYAD_STATUS_OK, "%s: branch is read",
                  dyad_type_name(type));
        }
        in = base, in.singular_threshold = 0;
        fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_SINGULAR_THRESHOLD, "threshold 0");
        in.singular_threshold = 1;
        fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_SINGULAR_THRESHOLD, "threshold 1");
        in.k.point.velocity.x = (dyad_real)NAN;
        fails += expect_kin_invalid(type, &in, DYAD_KIN_FIELD_K_VELOCITY, "two bad fields");
    }
    return fails;
}

/* (e) NULL pointers and a bad type. */
static int test_kin_invalid_pointers(void)
{
    int fails = 0, t;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = all_types[t];
        const dyad_kin_input base = dyad_kin_input_default();
        dyad_kin_result out;
        CHECK(dyad_kinematics(type, NULL, &out) == DYAD_STATUS_INVALID_INPUT &&
                  out.field == DYAD_KIN_FIELD_INPUT && kin_all_nan(&out, 1),
              "%s: a NULL input is not named", dyad_type_name(type));
        CHECK(dyad_kinematics(type, &base, NULL) == DYAD_STATUS_INVALID_INPUT,
              "%s: a NULL result is not refused", dyad_type_name(type));
        CHECK(dyad_kinematics_tangent(type, &base, NULL, &out, &out) == DYAD_STATUS_INVALID_INPUT &&
                  out.field == DYAD_KIN_FIELD_INPUT,
              "%s: a NULL seed is not named", dyad_type_name(type));
    }
    {
        const dyad_kin_input in = dyad_kin_input_default();
        dyad_kin_result out;
        CHECK(dyad_kinematics(DYAD_TYPE_COUNT, &in, &out) == DYAD_STATUS_INVALID_INPUT &&
                  out.field == DYAD_KIN_FIELD_TYPE && kin_all_nan(&out, 1),
              "a bad type is not named");
        CHECK(dyad_kinematics_tangent(DYAD_TYPE_COUNT, &in, &in, &out, &out) ==
                      DYAD_STATUS_INVALID_INPUT &&
                  out.field == DYAD_KIN_FIELD_TYPE,
              "the tangent: a bad type is not named");
    }
    return fails;
}

/* dyad_point_on_link: a point fixed on a moving link, against its jet. */
static int test_kin_point_on_link(void)
{
    int fails = 0, k;
    rng r = {0x4B500000u};
    double worst = 0;
    for (k = 0; k < 1000; ++k) {
        const path x = random_path(&r, -1, 1, 2), y = random_path(&r, -1, 1, 2);
        const path th = random_path(&r, -PI, PI, 3);
        const double complex at = uniform(&r, -2, 2) + I * uniform(&r, -2, 2);
        const sjet angle = path_at(&th, 0);
        const sjet px = path_at(&x, 0), py = path_at(&y, 0);
        vjet origin, want;
        dyad_point_motion o, got;
        double g[6], w[6];
        origin.v = px.v + I * py.v, origin.d = px.d + I * py.d, origin.dd = px.dd + I * py.dd;
        want = vadd(origin, vtimes(vpolar(angle), at));
        o = motion_of(origin);
        got = dyad_point_on_link(&o, cv(cexp(I * angle.v)), (dyad_real)angle.d, (dyad_real)angle.dd,
                                 cv(at));
        put_motion(g, 0, &got);
        o = motion_of(want);
        put_motion(w, 0, &o);
        worst = worst_error(g, w, 6) > worst ? worst_error(g, w, 6) : worst;
    }
    CHECK(worst < KIN_LIMIT, "dyad_point_on_link off by %.3g", worst);
    return fails;
}

/* ---- one sample of a batch (dyad_lanes.h) against its twin ----------------------------------- */

/* Bit for bit: the motion reals and figures of two kinematic results. */
static int same_kin_outputs(const dyad_kin_result* a, const dyad_kin_result* b)
{
    return memcmp(&a->m, &b->m, DYAD_KIN_MOTION_REALS * sizeof(dyad_real)) == 0 &&
           memcmp(&a->conditioning, &b->conditioning, sizeof a->conditioning) == 0 &&
           memcmp(&a->closure, &b->closure, sizeof a->closure) == 0 &&
           memcmp(&a->amplification, &b->amplification, sizeof a->amplification) == 0;
}

/* Bit for bit: the reactions and figures of two results. */
static int same_reactions(const dyad_result* a, const dyad_result* b)
{
    const dyad_real x[] = {a->r_mk.x, a->r_mk.y, a->r_np.x,      a->r_np.y,       a->r_mn.x,
                           a->r_mn.y, a->n_mk,   a->n_np,        a->n_mn,         a->m_mk,
                           a->m_np,   a->m_mn,   a->denominator, a->conditioning, a->amplification};
    const dyad_real y[] = {b->r_mk.x, b->r_mk.y, b->r_np.x,      b->r_np.y,       b->r_mn.x,
                           b->r_mn.y, b->n_mk,   b->n_np,        b->n_mn,         b->m_mk,
                           b->m_np,   b->m_mn,   b->denominator, b->conditioning, b->amplification};
    return memcmp(x, y, sizeof x) == 0;
}

/* A kinematic input spoiled one way in two: a mount moved out of reach, a threshold no
 * conditioning passes, a length NaN, a branch 0 or 2 (which the types with none ignore);
 * or left as built. */
static dyad_kin_input spoiled_kin_input(rng* r, dyad_type type)
{
    kin_built b;
    const kin_case c = random_kin_case(r, type);
    dyad_kin_input in = kin_input_at(&c, uniform(r, -1, 1), &b);
    switch ((int)uniform(r, 0, 8)) {
    case 0: in.p.point.position = dyad_scale((dyad_real)40, in.p.point.position); break;
    case 1: in.singular_threshold = (dyad_real)0.999; break;
    case 2: in.length_n = (dyad_real)NAN; break;
    case 3: in.branch = 0; break;
    case 4: in.branch = 2; break;
    default: break;
    }
    return in;
}

/* dyad_kin_lane_<type> and dyad_react_lane_<type> answer 0 exactly where their twins
 * say ok, and then give their outputs bit for bit; over random dyads, a quarter of them
 * spoiled (out of reach, singular, NaN, overflowing loads). */
static int test_lanes_match_their_twins(void)
{
    static dyad_status (*const kin[DYAD_TYPE_COUNT])(const dyad_kin_input*, dyad_kin_result*) = {
        dyad_kinematics_rrr, dyad_kinematics_rrt, dyad_kinematics_rtr, dyad_kinematics_trt,
        dyad_kinematics_rtt};
    static dyad_real (*const kin_lane[DYAD_TYPE_COUNT])(
        const dyad_kin_input*, dyad_real, dyad_kin_result*) = {dyad_kin_lane_rrr, dyad_kin_lane_rrt,
                                                               dyad_kin_lane_rtr, dyad_kin_lane_trt,
                                                               dyad_kin_lane_rtt};
    static dyad_status (*const react[DYAD_TYPE_COUNT])(const dyad_loaded*, dyad_result*) = {
        dyad_react_rrr, dyad_react_rrt, dyad_react_rtr, dyad_react_trt, dyad_react_rtt};
    static dyad_real (*const react_lane[DYAD_TYPE_COUNT])(const dyad_loaded*, dyad_result*) = {
        dyad_react_lane_rrr, dyad_react_lane_rrt, dyad_react_lane_rtr, dyad_react_lane_trt,
        dyad_react_lane_rtt};
    int fails = 0, t, k;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        rng r = {0x1A4E5000u + (uint64_t)t};
        int ok[2] = {0, 0}, refused[2] = {0, 0};
        for (k = 0; k < 4000; ++k) {
            const dyad_kin_input in = spoiled_kin_input(&r, all_types[t]);
            dyad_kin_input lane_in = in;
            dyad_kin_result want, got;
            const dyad_status s = kin[t](&in, &want);
            dyad_real bad;
            lane_in.branch = 1; /* left at its default: the lane takes the branch as a real */
            bad = kin_lane[t](&lane_in, (dyad_real)in.branch, &got);
            CHECK((bad == 0) == (s == DYAD_STATUS_OK), "%s kinematics %d: status %s, lane %g",
                  dyad_type_name(all_types[t]), k, dyad_status_name(s), (double)bad);
            CHECK(s != DYAD_STATUS_OK || same_kin_outputs(&want, &got),
                  "%s kinematics %d: the lane's outputs differ", dyad_type_name(all_types[t]), k);
            ++*(s == DYAD_STATUS_OK ? &ok[0] : &refused[0]);
        }
        for (k = 0; k < 4000; ++k) {
            const dyad_input in = random_input(&r, all_types[t]);
            dyad_loaded loaded = loaded_of(&in);
            dyad_result want, got;
            dyad_status s;
            dyad_real bad;
            switch ((int)uniform(&r, 0, 8)) {
            case 0: loaded.singular_threshold = (dyad_real)0.999; break;
            case 1: loaded.m.f.x = (dyad_real)NAN; break;
            case 2:
                loaded.n.m_d = HUGE_REAL * HUGE_REAL; /* inf */
                break;
            default: break;
            }
            s = react[t](&loaded, &want);
            bad = react_lane[t](&loaded, &got);
            CHECK((bad == 0) == (s == DYAD_STATUS_OK), "%s reactions %d: status %s, lane %g",
                  dyad_type_name(all_types[t]), k, dyad_status_name(s), (double)bad);
            CHECK(s != DYAD_STATUS_OK || (same_reactions(&want, &got) &&
                                          dyad_force_size(&want) == dyad_lane_force_size(&got) &&
                                          dyad_moment_size(&want) == dyad_lane_moment_size(&got)),
                  "%s reactions %d: the lane's outputs differ", dyad_type_name(all_types[t]), k);
            ++*(s == DYAD_STATUS_OK ? &ok[1] : &refused[1]);
        }
        /* both sides of every check were reached */
        CHECK(ok[0] > 1000 && refused[0] > 500 && ok[1] > 1000 && refused[1] > 500,
              "%s: kinematics %d ok, %d not; reactions %d ok, %d not", dyad_type_name(all_types[t]),
              ok[0], refused[0], ok[1], refused[1]);
    }
    {
        const dyad_kin_input a = dyad_kin_input_default(), b = dyad_lane_kin_input_default();
        CHECK(a.length_m == b.length_m && a.length_n == b.length_n && a.branch == b.branch &&
                  a.singular_threshold == b.singular_threshold && a.k.guide.x == b.k.guide.x &&
                  a.turn_n.x == b.turn_n.x && a.mount_amplification == b.mount_amplification,
              "the lane's default kinematic input differs");
    }
    return fails;
}

/* Names: every field and failure has its own, NONE and CLOSES none. */
static int test_kin_names(void)
{
    int fails = 0, a, b;
    for (a = 1; a < DYAD_KIN_FIELD_COUNT; ++a) {
        CHECK(strlen(dyad_kin_field_name((dyad_kin_field)a)) > 0, "field %d has no name", a);
        for (b = 1; b < a; ++b) {
            CHECK(strcmp(dyad_kin_field_name((dyad_kin_field)a),
                         dyad_kin_field_name((dyad_kin_field)b)) != 0,
                  "fields %d and %d share a name", a, b);
        }
    }
    for (a = 1; a < DYAD_KIN_FAILURE_COUNT; ++a) {
        CHECK(strlen(dyad_kin_failure_name((dyad_kin_failure)a)) > 0, "failure %d has no name", a);
    }
    CHECK(dyad_kin_field_name(DYAD_KIN_FIELD_NONE)[0] == 0 &&
              dyad_kin_failure_name(DYAD_KIN_CLOSES)[0] == 0 &&
              strcmp(dyad_kin_field_name(DYAD_KIN_FIELD_K_GUIDE), "k.guide") == 0 &&
              strcmp(dyad_status_name(DYAD_STATUS_CANNOT_ASSEMBLE), "cannot assemble") == 0,
          "names of NONE, CLOSES, k.guide, cannot assemble");
    return fails;
}

/* ---- the batch call ------------------------------------------------------------------------- */

enum { BATCH_ROWS = 203 }; /* not a multiple of the block: the last block is short */

/* The scalars of an input row, in the order of dyad_input_column (a dyad_input
 * is those scalars, without padding). */
typedef char input_is_its_columns[sizeof(dyad_input) == DYAD_INPUT_COLUMN_COUNT * sizeof(dyad_real)
                                      ? 1
                                      : -1];

static dyad_real input_scalar(const dyad_input* in, int column)
{
    dyad_real scalars[DYAD_INPUT_COLUMN_COUNT];
    memcpy(scalars, in, sizeof scalars);
    return scalars[column];
}

static int same_real(dyad_real a, dyad_real b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* The same for doubles in either build (the angles are doubles in a float build too). */
static int same_double(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Every output of every row of a batch against dyad_solve on the row, bit for bit. */
static int batch_rows_match(dyad_type type, const dyad_input rows[], const dyad_real out[],
                            const unsigned char status[], const unsigned char field[], size_t ok)
{
    int fails = 0;
    size_t r, solved = 0;
    int c;
    for (r = 0; r < BATCH_ROWS; ++r) {
        dyad_result want;
        solved += dyad_solve(type, &rows[r], &want) == DYAD_STATUS_OK;
        CHECK(status[r] == (unsigned char)want.status && field[r] == (unsigned char)want.field,
              "%s row %zu: status %d field %d, solve %d %d", dyad_type_name(type), r, status[r],
              field[r], want.status, want.field);
        for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
            dyad_real w[DYAD_OUTPUT_COLUMN_COUNT];
            memcpy(w, &want.r_mk, sizeof w); /* the outputs after status and field */
            CHECK(same_real(out[c * BATCH_ROWS + r], w[c]), "%s row %zu column %d: %g, solve %g",
                  dyad_type_name(type), r, c, (double)out[c * BATCH_ROWS + r], (double)w[c]);
        }
    }
    CHECK(ok == solved, "%s: %zu rows ok, solve %zu", dyad_type_name(type), ok, solved);
    return fails;
}

/* Random rows, some invalid or singular; columns varying by row (contiguous and
 * strided), given once (stride 0) and left out (the default). In the widest lanes this
 * CPU runs, and capped at each instruction set's. */
static int test_batch_matches_solve(void)
{
    static dyad_input rows[BATCH_ROWS];
    static dyad_real columns[DYAD_INPUT_COLUMN_COUNT][2 * BATCH_ROWS];
    static dyad_real out[DYAD_OUTPUT_COLUMN_COUNT * BATCH_ROWS];
    static unsigned char status[BATCH_ROWS], field[BATCH_ROWS];
    int fails = 0, t, c, cap;
    size_t r;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = (dyad_type)t;
        rng g = {0xBA7C0000u + (uint64_t)t};
        dyad_batch_input in;
        dyad_batch_output res;
        const dyad_real once = (dyad_real)-9.81;
        for (r = 0; r < BATCH_ROWS; ++r) {
            rows[r] = random_input(&g, type);
            rows[r].gravity.x = 0;    /* the left-out column: its default */
            rows[r].gravity.y = once; /* the column given once */
            if (r % 17 == 3) {
                rows[r].m.mass = (dyad_real)NAN;
            } else if (r % 19 == 5) {
                rows[r].n.length = -1;
            } else if (r % 23 == 7) {
                rows[r].n.dir = rows[r].m.dir; /* aligned links or guides: often singular */
                rows[r].guide_k = rows[r].m.dir;
                rows[r].guide_p = rows[r].m.dir;
            }
        }
        for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
            /* odd columns strided: every other element of a twice longer array */
            const ptrdiff_t stride = c % 2 ? 2 : 1;
            for (r = 0; r < BATCH_ROWS; ++r) {
                columns[c][(ptrdiff_t)r * stride] = input_scalar(&rows[r], c);
            }
            in.column[c].data = columns[c];
            in.column[c].stride = stride;
        }
        in.column[DYAD_IN_GRAVITY_X].data = NULL;
        in.column[DYAD_IN_GRAVITY_Y].data = &once;
        in.column[DYAD_IN_GRAVITY_Y].stride = 0;
        for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
            res.column[c].data = &out[c * BATCH_ROWS];
            res.column[c].stride = 1;
        }
        res.status = status;
        res.field = field;
        fails += batch_rows_match(type, rows, out, status, field,
                                  dyad_solve_batch(type, BATCH_ROWS, &in, &res));
        for (cap = DYAD_LANES_BASELINE; cap <= DYAD_LANES_AVX512; ++cap) {
            memset(out, 0xff, sizeof out); /* a NaN no solve writes: each cap writes anew */
            fails += batch_rows_match(
                type, rows, out, status, field,
                dyad_solve_batch_at_most((dyad_lanes_isa)cap, type, BATCH_ROWS, &in, &res));
        }
    }
    return fails;
}

/* Columns in pairs of one interleaved array, as NumPy's (N, 2) arrays come: columns
 * 2k and 2k + 1 read x and y of one array, and fill adjacent members of dyad_input, so
 * a whole block copies both at once; the outputs likewise. Bit for bit dyad_solve. */
static int test_batch_interleaved_pairs(void)
{
    static dyad_input rows[BATCH_ROWS];
    static dyad_real pairs[DYAD_INPUT_COLUMN_COUNT / 2 + 1][2 * BATCH_ROWS];
    static dyad_real written[DYAD_OUTPUT_COLUMN_COUNT / 2 + 1][2 * BATCH_ROWS];
    static dyad_real out[DYAD_OUTPUT_COLUMN_COUNT * BATCH_ROWS];
    static unsigned char status[BATCH_ROWS], field[BATCH_ROWS];
    int fails = 0, t, c;
    size_t r;
    for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
        const dyad_type type = (dyad_type)t;
        rng g = {0x1A7E0000u + (uint64_t)t};
        dyad_batch_input in;
        dyad_batch_output res;
        size_t ok;
        for (r = 0; r < BATCH_ROWS; ++r) {
            rows[r] = random_input(&g, type);
        }
        for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
            for (r = 0; r < BATCH_ROWS; ++r) {
                pairs[c / 2][2 * r + (size_t)(c % 2)] = input_scalar(&rows[r], c);
            }
            in.column[c].data = &pairs[c / 2][c % 2];
            in.column[c].stride = 2;
        }
        for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
            res.column[c].data = &written[c / 2][c % 2];
            res.column[c].stride = 2;
        }
        res.status = status;
        res.field = field;
        ok = dyad_solve_batch(type, BATCH_ROWS, &in, &res);
        for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
            for (r = 0; r < BATCH_ROWS; ++r) {
                out[c * BATCH_ROWS + r] = written[c / 2][2 * r + (size_t)(c % 2)];
            }
        }
        fails += batch_rows_match(type, rows, out, status, field, ok);
    }
    return fails;
}

/* An unknown type or no input: every row invalid and named so, outputs NaN. */
static int test_batch_refusals(void)
{
    int fails = 0;
    dyad_batch_input in;
    dyad_batch_output res;
    dyad_real out[DYAD_OUTPUT_COLUMN_COUNT][11];
    unsigned char status[11], field[11];
    size_t r;
    int c;
    memset(&in, 0, sizeof in);
    for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
        res.column[c].data = out[c];
        res.column[c].stride = 1;
    }
    res.status = status;
    res.field = field;
    CHECK(dyad_solve_batch(DYAD_TYPE_COUNT, 11, &in, &res) == 0, "unknown type solved");
    for (r = 0; r < 11; ++r) {
        CHECK(status[r] == DYAD_STATUS_INVALID_INPUT && field[r] == DYAD_FIELD_TYPE &&
                  isnan(out[0][r]) && isnan(out[DYAD_OUT_AMPLIFICATION][r]),
              "row %zu of an unknown type: status %d field %d", r, status[r], field[r]);
    }
    CHECK(dyad_solve_batch(DYAD_RRR, 11, NULL, &res) == 0, "no input solved");
    for (r = 0; r < 11; ++r) {
        CHECK(status[r] == DYAD_STATUS_INVALID_INPUT && field[r] == DYAD_FIELD_INPUT,
              "row %zu without input: status %d field %d", r, status[r], field[r]);
    }
    CHECK(dyad_solve_batch(DYAD_RRR, 11, &in, NULL) == 0, "no output");
    {
        /* every column left out: each row is dyad_input_default() (RRT: solvable) */
        const dyad_input defaults = dyad_input_default();
        dyad_result want;
        dyad_solve(DYAD_RRT, &defaults, &want);
        CHECK(want.status == DYAD_STATUS_OK && dyad_solve_batch(DYAD_RRT, 11, &in, &res) == 11 &&
                  status[10] == DYAD_STATUS_OK && same_real(out[DYAD_OUT_R_MK_Y][10], want.r_mk.y),
              "rows of defaults");
    }
    return fails;
}

/* dyadfmu/angle.h against libm (within half a unit of the truth) over a dense sweep of
 * a few turns and of large angles: within 2.8e-16 of it, and a unit vector. */
static int test_angle_cos_sin_near_libm(void)
{
    int fails = 0;
    double worst = 0, worst_norm = 0;
    long k;
    for (k = -400000; k <= 400000; ++k) {
        const double angle = k < -200000 || k > 200000 ? (double)k * 4.999 + 0.123 : k * 1e-4;
        double c, s;
        dyad_angle_cos_sin(angle, &c, &s);
        worst = fmax(worst, fmax(fabs(c - cos(angle)), fabs(s - sin(angle))));
        worst_norm = fmax(worst_norm, fabs(c * c + s * s - 1));
    }
    CHECK(worst <= 2.8e-16, "cos and sin differ from libm by %.3g", worst);
    CHECK(worst_norm <= 4.5e-16, "|(cos, sin)|^2 - 1 = %.3g", worst_norm);
    {
        double c, s;
        dyad_angle_cos_sin(3e9, &c, &s);
        CHECK(c == cos(3e9) && s == sin(3e9), "beyond the fast range: not libm's");
        dyad_angle_cos_sin((double)NAN, &c, &s);
        CHECK(isnan(c) && isnan(s), "a NaN angle gave (%g, %g)", c, s);
    }
    return fails;
}

/* dyad_cos_sin_pair gives what dyad_cos_sin gives for each angle, bit for bit, in
 * either lane and with the other lane anywhere: in range, beyond it, infinite, NaN. */
static int test_angle_pair_matches_single(void)
{
    static const double odd[] = {
        3e9,         -1.5e6, 1e6,  -1e6,  1.0000000001e6, (double)INFINITY, -(double)INFINITY,
        (double)NAN, 0.0,    -0.0, 1e-300};
    int fails = 0;
    long mismatches = 0;
    long k;
    size_t a, b;
    for (k = -200000; k <= 200000; ++k) {
        const double angle0 = k * 7.3e-5 - 0.01;
        const double angle1 = (double)k * 31.7 + 0.5;
        double one0[2], one1[2], pair0[2], pair1[2];
        dyad_cos_sin(angle0, &one0[0], &one0[1]);
        dyad_cos_sin(angle1, &one1[0], &one1[1]);
        dyad_cos_sin_pair(angle0, angle1, pair0, pair1);
        mismatches +=
            memcmp(one0, pair0, sizeof one0) != 0 || memcmp(one1, pair1, sizeof one1) != 0;
    }
    CHECK(mismatches == 0, "%ld pairs of angles differ from one at a time", mismatches);
    for (a = 0; a < sizeof odd / sizeof odd[0]; ++a) {
        for (b = 0; b < sizeof odd / sizeof odd[0]; ++b) {
            double one0[2], one1[2], pair0[2], pair1[2];
            dyad_cos_sin(odd[a], &one0[0], &one0[1]);
            dyad_cos_sin(odd[b], &one1[0], &one1[1]);
            dyad_cos_sin_pair(odd[a], odd[b], pair0, pair1);
            CHECK(same_double(one0[0], pair0[0]) && same_double(one0[1], pair0[1]) &&
                      same_double(one1[0], pair1[0]) && same_double(one1[1], pair1[1]),
                  "angles %g and %g: (%.17g, %.17g) (%.17g, %.17g) in a pair, (%.17g, %.17g) "
                  "(%.17g, %.17g) one at a time",
                  odd[a], odd[b], pair0[0], pair0[1], pair1[0], pair1[1], one0[0], one0[1], one1[0],
                  one1[1]);
        }
    }
    return fails;
}

#if defined(DYAD_ANGLE_HAVE_WIDE)
/* `count` angles turned by `turn` against dyad_cos_sin one at a time, both ways of
 * calling it (apart and in place, cos_out = angle): the count of angles whose bits differ. */
static long wide_mismatches(void (*turn)(const double*, double*, double*, size_t),
                            const double* angle, size_t count)
{
    double one_cos[24], one_sin[24], wide_cos[24], wide_sin[24], inplace_sin[24];
    long differ = 0;
    size_t i;
    for (i = 0; i < count; ++i) {
        dyad_cos_sin(angle[i], &one_cos[i], &one_sin[i]);
    }
    turn(angle, wide_cos, wide_sin, count);
    for (i = 0; i < count; ++i) {
        differ += !same_double(one_cos[i], wide_cos[i]) || !same_double(one_sin[i], wide_sin[i]);
    }
    memcpy(wide_cos, angle, count * sizeof *angle);
    turn(wide_cos, wide_cos, inplace_sin, count);
    for (i = 0; i < count; ++i) {
        differ += !same_double(one_cos[i], wide_cos[i]) || !same_double(one_sin[i], inplace_sin[i]);
    }
    return differ;
}
#endif

/* dyad_cos_sin_avx2 and _avx512, where this CPU runs them, give what dyad_cos_sin gives
 * for each angle, bit for bit: over a sweep of 24 angles a call, every count up to 24 (the
 * rest one at a time), and each odd angle (beyond the fast range, infinite, NaN, signed
 * zero) in every lane of a call among angles in range. */
static int test_angle_wide_matches_single(void)
{
    static const double odd[] = {
        3e9,         -1.5e6, 1e6,  -1e6,   1.0000000001e6, (double)INFINITY, -(double)INFINITY,
        (double)NAN, 0.0,    -0.0, 1e-300, 2.5e-2};
    int fails = 0;
#if defined(DYAD_ANGLE_HAVE_WIDE)
    struct {
        const char* name;
        void (*turn)(const double*, double*, double*, size_t);
    } ways[2];
    size_t w, n_ways = 0;
    if (__builtin_cpu_supports("avx2")) {
        ways[n_ways].name = "avx2";
        ways[n_ways++].turn = dyad_cos_sin_avx2;
    }
    if (__builtin_cpu_supports("avx512f")) {
        ways[n_ways].name = "avx512";
        ways[n_ways++].turn = dyad_cos_sin_avx512;
    }
    if (n_ways < 2) { /* said, so that a pass on such a CPU is not read as more */
        printf("    angle_wide_matches_single: this CPU runs %s\n",
               n_ways == 0 ? "neither AVX2 nor AVX-512F: nothing compared" : "no AVX-512F");
    }
    for (w = 0; w < n_ways; ++w) {
        double angle[24];
        long sweep = 0, odd_lanes = 0;
        long k;
        size_t a, lane, count;
        for (k = -100000; k <= 100000; ++k) {
            for (lane = 0; lane < 24; ++lane) {
                angle[lane] = (double)(k * 24 + (long)lane) * (k % 2 ? 7.3e-5 : 1.37) - 0.01;
            }
            sweep += wide_mismatches(ways[w].turn, angle, (size_t)(k % 25 + 25) % 25);
        }
        CHECK(sweep == 0, "%s: %ld angles of the sweep differ from one at a time", ways[w].name,
              sweep);
        for (a = 0; a < sizeof odd / sizeof odd[0]; ++a) {
            for (lane = 0; lane < 24; ++lane) {
                for (count = 0; count < 24; ++count) {
                    angle[count] = count == lane ? odd[a] : 0.3 * (double)count - 2;
                }
                odd_lanes += wide_mismatches(ways[w].turn, angle, 24);
            }
        }
        CHECK(odd_lanes == 0, "%s: %ld angles differ where an odd one is among them", ways[w].name,
              odd_lanes);
    }
#else
    (void)odd;
#endif
    return fails;
}

#include "dyad_cylinder_tests.h"

static const named_test tests[] = {
    {"equilibrium_random", test_equilibrium_random},
    {"rrr_symmetric_truss", test_rrr_symmetric_truss},
    {"rrr_centripetal", test_rrr_centripetal},
    {"rrt_slider_crank_rod_force", test_rrt_slider_crank_rod_force},
    {"rrt_dead_centre_with_weight", test_rrt_dead_centre_with_weight},
    {"rtr_lever_torque", test_rtr_lever_torque},
    {"trt_cross_slide", test_trt_cross_slide},
    {"rtt_scotch_yoke", test_rtt_scotch_yoke},
    {"invalid_nonfinite", test_invalid_nonfinite},
    {"invalid_domain", test_invalid_domain},
    {"out_of_range", test_out_of_range},
    {"singular", test_singular},
    {"invalid_before_singular", test_invalid_before_singular},
    {"react_loaded", test_react_loaded},
    {"solve_valid_matches_solve", test_solve_valid_matches_solve},
    {"batch_matches_solve", test_batch_matches_solve},
    {"batch_interleaved_pairs", test_batch_interleaved_pairs},
    {"batch_refusals", test_batch_refusals},
    {"angle_cos_sin_near_libm", test_angle_cos_sin_near_libm},
    {"angle_pair_matches_single", test_angle_pair_matches_single},
    {"angle_wide_matches_single", test_angle_wide_matches_single},
    {"tangent_of_each_type", test_tangent_of_each_type},
    {"react_tangent_finite_differences", test_react_tangent_finite_differences},
    {"kin_reproduces_built", test_kin_reproduces_built},
    {"kin_rates_finite_differences", test_kin_rates_finite_differences},
    {"kin_tangent_finite_differences", test_kin_tangent_finite_differences},
    {"kin_tangent_along_motion", test_kin_tangent_along_motion},
    {"kin_failures", test_kin_failures},
    {"kin_singular", test_kin_singular},
    {"kin_invalid_nonfinite", test_kin_invalid_nonfinite},
    {"kin_invalid_domain", test_kin_invalid_domain},
    {"kin_invalid_pointers", test_kin_invalid_pointers},
    {"kin_point_on_link", test_kin_point_on_link},
    {"kin_names", test_kin_names},
    {"lanes_match_their_twins", test_lanes_match_their_twins},
    {"cylinder_equilibrium", test_cylinder_equilibrium},
    {"cylinder_kinematics", test_cylinder_kinematics},
    {"cylinder_energy", test_cylinder_energy},
    {"cylinder_tangent", test_cylinder_tangent},
    {"cylinder_statuses", test_cylinder_statuses},
    {"cylinder_pins_close", test_cylinder_pins_close},
    {"cylinder_invalid", test_cylinder_invalid},
    {"cylinder_every_field_poisoned", test_cylinder_every_field_poisoned},
    {"cylinder_lane_matches_cylinder", test_cylinder_lane_matches_cylinder},
};

int main(int argc, char** argv)
{
    return run_named_tests(tests, sizeof tests / sizeof tests[0], REAL_NAME, argv + 1, argc - 1) ==
                   0
               ? 0
               : 1;
}
