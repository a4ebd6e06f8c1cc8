/* dyadfmu: tests of the cylinder between two pins (dyadfmu/cylinder.h), included
 * by dyad_tests.c, whose random numbers and CHECK they use. Every check is made
 * from the outputs by means independent of the solver's formulas: each body's
 * Newton-Euler equations summed here in complex double, the motion against
 * finite differences of the closed positions, the energy balance, and the
 * tangent against a central difference. */
#include "dyadfmu/cylinder.h"

#ifdef DYAD_REAL_FLOAT
#define CYL_EPS      1.1920929e-7
#define CYL_FD_LIMIT 2e-2
#else
#define CYL_EPS      2.220446049250313e-16
#define CYL_FD_LIMIT 1e-6
#endif

/* A random cylinder: A and O moving, a link with loads, barrel and rod with mass. */
static dyad_cylinder_input cyl_random(rng* r, int moving)
{
    dyad_cylinder_input in = dyad_cylinder_input_default();
    const double big = moving ? 1 : 0;
    const double rb = uniform(r, 0.3, 1.5), len = uniform(r, 0.5, 2.0);
    const double lo = fabs(rb - len), hi = rb + len;
    const double L = lo + (hi - lo) * uniform(r, 0.15, 0.85), th = uniform(r, -PI, PI);
    in.o.position = vec(uniform(r, -1, 1), uniform(r, -1, 1));
    in.a.position = dyad_add(in.o.position, vec(L * cos(th), L * sin(th)));
    in.a.velocity = vec(big * uniform(r, -2, 2), big * uniform(r, -2, 2));
    in.a.acceleration = vec(big * uniform(r, -5, 5), big * uniform(r, -5, 5));
    in.o.velocity = vec(big * uniform(r, -2, 2), big * uniform(r, -2, 2));
    in.o.acceleration = vec(big * uniform(r, -5, 5), big * uniform(r, -5, 5));
    in.pin_b = polar(rb, uniform(r, -PI, PI));
    in.length = (dyad_real)len;
    in.rate = (dyad_real)uniform(r, -1, 1);
    in.accel = (dyad_real)uniform(r, -3, 3);
    in.branch = uniform(r, 0, 1) < 0.5 ? -1 : 1;
    in.barrel.mass = (dyad_real)uniform(r, 0, 20);
    in.barrel.com = (dyad_real)uniform(r, -0.1, 0.6);
    in.barrel.inertia = (dyad_real)uniform(r, 0, 2);
    in.rod.mass = (dyad_real)uniform(r, 0, 10);
    in.rod.com = (dyad_real)uniform(r, -0.1, 0.6);
    in.rod.inertia = (dyad_real)uniform(r, 0, 1);
    in.link.mass = (dyad_real)uniform(r, 0, 50);
    in.link.com = vec(uniform(r, -1, 1), uniform(r, -1, 1));
    in.link.inertia = (dyad_real)uniform(r, 0, 5);
    in.link.force = vec(uniform(r, -500, 500), uniform(r, -500, 500));
    in.link.moment = (dyad_real)uniform(r, -200, 200);
    in.gravity = vec(uniform(r, -10, 10), uniform(r, -10, 10));
    return in;
}

/* One body's Newton-Euler sums: forces and moments about p, with the size
 * (sum of the magnitudes) of their terms. */
typedef struct cyl_sum {
    double complex f;
    double m, f_size, m_size;
} cyl_sum;

static void cyl_add(cyl_sum* s, double complex at, double complex force, double complex p)
{
    const double complex lever = at - p;
    const double moment = creal(lever) * cimag(force) - cimag(lever) * creal(force);
    s->f += force;
    s->f_size += cabs(force);
    s->m += moment;
    s->m_size += cabs(lever) * cabs(force);
}

static void cyl_add_inertia(cyl_sum* s, const dyad_point_motion* com, double mass, double inertia,
                            double epsilon, dyad_vec2 gravity, double complex p)
{
    cyl_add(s, cvec(com->position), mass * (cvec(gravity) - cvec(com->acceleration)), p);
    s->m -= inertia * epsilon;
    s->m_size += fabs(inertia * epsilon);
}

static double cyl_imbalance(const cyl_sum* s)
{
    const double f = cabs(s->f) / (s->f_size > 0 ? s->f_size : 1);
    const double m = fabs(s->m) / (s->m_size > 0 ? s->m_size : 1);
    return f > m ? f : m;
}

/* The worst relative imbalance of the three bodies, moments about p. */
static double cyl_worst_imbalance(const dyad_cylinder_input* in, const dyad_cylinder_result* out,
                                  double complex p)
{
    const double complex a = cvec(in->a.position), b = cvec(out->b.position);
    const double complex u = cvec(out->axis), j = I * u;
    const double complex on_rod = out->axial_force * u + out->n_rod * j;
    cyl_sum c = {0, 0, 0, 0}, r = {0, 0, 0, 0}, l = {0, 0, 0, 0};
    double worst;
    cyl_add(&c, a, cvec(out->r_a), p);
    cyl_add(&c, b, -on_rod, p);
    c.m -= out->m_rod, c.m_size += fabs(out->m_rod);
    cyl_add_inertia(&c, &out->barrel_com, in->barrel.mass, in->barrel.inertia,
                    out->cylinder_epsilon, in->gravity, p);
    cyl_add(&r, b, on_rod, p);
    cyl_add(&r, b, -cvec(out->r_b), p);
    r.m += out->m_rod, r.m_size += fabs(out->m_rod);
    cyl_add_inertia(&r, &out->rod_com, in->rod.mass, in->rod.inertia, out->cylinder_epsilon,
                    in->gravity, p);
    cyl_add(&l, cvec(in->o.position), cvec(out->r_o), p);
    cyl_add(&l, b, cvec(out->r_b), p);
    cyl_add(&l, cvec(out->link_com.position), cvec(in->link.force), p);
    l.m += in->link.moment, l.m_size += fabs(in->link.moment);
    cyl_add_inertia(&l, &out->link_com, in->link.mass, in->link.inertia, out->link_epsilon,
                    in->gravity, p);
    worst = cyl_imbalance(&c);
    worst = cyl_imbalance(&r) > worst ? cyl_imbalance(&r) : worst;
    return cyl_imbalance(&l) > worst ? cyl_imbalance(&l) : worst;
}

/* Each body's Newton-Euler equations with the computed reactions. */
static int test_cylinder_equilibrium(void)
{
    int fails = 0, k;
    double worst = 0, worst_scaled = 0;
    rng r = {0xC7100001u};
    for (k = 0; k < RANDOM_CONFIGURATIONS; ++k) {
        const dyad_cylinder_input in = cyl_random(&r, k % 2);
        const double complex p = uniform(&r, -3, 3) + I * uniform(&r, -3, 3);
        dyad_cylinder_result out;
        double e;
        if (dyad_cylinder(&in, &out) != DYAD_STATUS_OK) {
            CHECK(0, "configuration %d: status %s", k, dyad_status_name(out.status));
            continue;
        }
        e = cyl_worst_imbalance(&in, &out, p);
        worst = e > worst ? e : worst;
        e /= CYL_EPS * out.amplification;
        worst_scaled = e > worst_scaled ? e : worst_scaled;
    }
    CHECK(worst_scaled < 16, "worst imbalance %.3g = %.3g eps x amplification", worst,
          worst_scaled);
    printf("    worst relative imbalance %.3g (%.3g eps x amplification)\n", worst, worst_scaled);
    return fails;
}

/* Point motion along t: p + v t + a t^2 / 2. */
static dyad_point_motion cyl_move(const dyad_point_motion* p, double t)
{
    dyad_point_motion q = *p;
    q.position = dyad_add(p->position, dyad_combine((dyad_real)t, p->velocity,
                                                    (dyad_real)(t * t / 2), p->acceleration));
    q.velocity = dyad_add(p->velocity, dyad_scale((dyad_real)t, p->acceleration));
    return q;
}

static dyad_cylinder_input cyl_at(const dyad_cylinder_input* in, double t)
{
    dyad_cylinder_input q = *in;
    q.a = cyl_move(&in->a, t);
    q.o = cyl_move(&in->o, t);
    q.length = (dyad_real)(in->length + in->rate * t + in->accel * t * t / 2);
    q.rate = (dyad_real)(in->rate + in->accel * t);
    return q;
}

/* The closed positions hold; the rates are the positions' derivatives. */
static double cyl_position_error(const dyad_cylinder_input* in, const dyad_cylinder_result* out)
{
    const double complex o = cvec(in->o.position), b = cvec(out->b.position);
    const double complex il = cexp(I * out->link_angle), u = cexp(I * out->cylinder_angle);
    const double complex side = conj(cvec(in->a.position) - o) * (b - o);
    double e = cabs(o + il * cvec(in->pin_b) - b);
    e += cabs(cvec(in->a.position) + in->length * u - b);
    e += cabs(cvec(in->a.position) + in->barrel.com * u - cvec(out->barrel_com.position));
    e += cabs(b - in->rod.com * u - cvec(out->rod_com.position));
    e += cabs(o + il * cvec(in->link.com) - cvec(out->link_com.position));
    return e + (cimag(side) * in->branch > 0 ? 0 : 1);
}

static double cyl_wrap(double a)
{
    return a - 2 * PI * floor((a + PI) / (2 * PI));
}

/* Five-point differences of the angles and points against the rates. */
static double cyl_rate_error(const dyad_cylinder_input* in, const dyad_cylinder_result* out,
                             double h)
{
    dyad_cylinder_result s[4];
    const double t[4] = {-2 * h, -h, h, 2 * h};
    double e = 0, d, dd;
    int k;
    for (k = 0; k < 4; ++k) {
        const dyad_cylinder_input q = cyl_at(in, t[k]);
        if (dyad_cylinder(&q, &s[k]) != DYAD_STATUS_OK) {
            return 1;
        }
    }
#define CYL_D1(f)  ((8 * (f(s[2]) - f(s[1])) - (f(s[3]) - f(s[0]))) / (12 * h))
#define CYL_LA(R)  cyl_wrap((R).link_angle - out->link_angle)
#define CYL_CA(R)  cyl_wrap((R).cylinder_angle - out->cylinder_angle)
#define CYL_BX(R)  ((R).b.position.x)
#define CYL_BY(R)  ((R).b.position.y)
#define CYL_VX(R)  ((R).link_com.velocity.x)
#define CYL_RVY(R) ((R).rod_com.velocity.y)
#define CYL_CVX(R) ((R).barrel_com.velocity.x)
    d = CYL_D1(CYL_LA) - out->link_omega;
    dd = CYL_D1(CYL_CA) - out->cylinder_omega;
    e = fabs(d) + fabs(dd);
    e += fabs(CYL_D1(CYL_BX) - out->b.velocity.x) + fabs(CYL_D1(CYL_BY) - out->b.velocity.y);
    e += fabs(CYL_D1(CYL_VX) - out->link_com.acceleration.x);
    e += fabs(CYL_D1(CYL_RVY) - out->rod_com.acceleration.y);
    e += fabs(CYL_D1(CYL_CVX) - out->barrel_com.acceleration.x);
#define CYL_LW(R) ((R).link_omega)
#define CYL_CW(R) ((R).cylinder_omega)
    e += fabs(CYL_D1(CYL_LW) - out->link_epsilon) + fabs(CYL_D1(CYL_CW) - out->cylinder_epsilon);
    return e;
}

static int test_cylinder_kinematics(void)
{
    int fails = 0, k;
    double worst_pos = 0, worst_rate = 0;
    rng r = {0xC7100002u};
    for (k = 0; k < 2000; ++k) {
        const dyad_cylinder_input in = cyl_random(&r, 1);
        dyad_cylinder_result out;
        double e, scale;
        if (dyad_cylinder(&in, &out) != DYAD_STATUS_OK) {
            CHECK(0, "configuration %d: status %s", k, dyad_status_name(out.status));
            continue;
        }
        e = cyl_position_error(&in, &out) / (CYL_EPS * out.kin_amplification);
        worst_pos = e > worst_pos ? e : worst_pos;
        scale = 1 + fabs(out.link_omega) + fabs(out.cylinder_omega) + fabs(out.link_epsilon) +
                fabs(out.cylinder_epsilon) + cabs(cvec(out.link_com.acceleration));
        e = cyl_rate_error(&in, &out, 1e-3) / (scale * out.kin_amplification);
        worst_rate = e > worst_rate ? e : worst_rate;
    }
    CHECK(worst_pos < 64, "closed positions off by %.3g eps x kin_amplification", worst_pos);
    CHECK(worst_rate < CYL_FD_LIMIT, "rates off their finite differences by %.3g", worst_rate);
    printf("    positions within %.3g eps x kin_amplification, rates within %.3g of their "
           "differences\n",
           worst_pos, worst_rate);
    return fails;
}

static double cyl_dot(double complex a, double complex b)
{
    return creal(a) * creal(b) + cimag(a) * cimag(b);
}

/* The power balance of a cylinder; *size gets the sum of the terms' magnitudes. */
static double cyl_power_residual(const dyad_cylinder_input* in, const dyad_cylinder_result* out,
                                 double* size)
{
    const dyad_point_motion* com[3] = {&out->barrel_com, &out->rod_com, &out->link_com};
    const double mass[3] = {in->barrel.mass, in->rod.mass, in->link.mass};
    const double inertia[3] = {in->barrel.inertia, in->rod.inertia, in->link.inertia};
    const double omega[3] = {out->cylinder_omega, out->cylinder_omega, out->link_omega};
    const double epsilon[3] = {out->cylinder_epsilon, out->cylinder_epsilon, out->link_epsilon};
    double terms[12];
    double sum = 0;
    int k;
    terms[0] = out->axial_force * in->rate;
    terms[1] = cyl_dot(cvec(out->r_a), cvec(in->a.velocity));
    terms[2] = cyl_dot(cvec(out->r_o), cvec(in->o.velocity));
    terms[3] = cyl_dot(cvec(in->link.force), cvec(out->link_com.velocity));
    terms[4] = in->link.moment * out->link_omega;
    for (k = 0; k < 3; ++k) {
        const double complex v = cvec(com[k]->velocity);
        terms[5 + 2 * k] = -mass[k] * cyl_dot(v, cvec(com[k]->acceleration) - cvec(in->gravity));
        terms[6 + 2 * k] = -inertia[k] * omega[k] * epsilon[k];
    }
    terms[11] = 0;
    *size = 0;
    for (k = 0; k < 12; ++k) {
        sum += terms[k];
        *size += fabs(terms[k]);
    }
    return sum;
}

/* The actuator's power with the supports' and the loads' equals the rate of
 * the kinetic and potential energy. */
static int test_cylinder_energy(void)
{
    int fails = 0, k;
    double worst = 0;
    rng r = {0xC7100003u};
    for (k = 0; k < RANDOM_CONFIGURATIONS; ++k) {
        const dyad_cylinder_input in = cyl_random(&r, k % 2);
        dyad_cylinder_result out;
        double size, e;
        if (dyad_cylinder(&in, &out) != DYAD_STATUS_OK) {
            CHECK(0, "configuration %d: status %s", k, dyad_status_name(out.status));
            continue;
        }
        e = fabs(cyl_power_residual(&in, &out, &size)) / (size * CYL_EPS * out.amplification);
        worst = e > worst ? e : worst;
    }
    CHECK(worst < 64, "power balance off by %.3g eps x amplification of its terms", worst);
    printf("    power balance within %.3g eps x amplification of its terms\n", worst);
    return fails;
}

#define CYL_OUTPUTS 44

static void cyl_outputs(const dyad_cylinder_result* r, double v[CYL_OUTPUTS])
{
    const dyad_point_motion* p[4] = {&r->b, &r->barrel_com, &r->rod_com, &r->link_com};
    int k, n = 0;
    for (k = 0; k < 4; ++k) {
        v[n++] = p[k]->position.x, v[n++] = p[k]->position.y;
        v[n++] = p[k]->velocity.x, v[n++] = p[k]->velocity.y;
        v[n++] = p[k]->acceleration.x, v[n++] = p[k]->acceleration.y;
    }
    v[n++] = r->link_omega, v[n++] = r->link_epsilon, v[n++] = r->cylinder_omega;
    v[n++] = r->cylinder_epsilon, v[n++] = r->axial_force, v[n++] = r->r_a.x, v[n++] = r->r_a.y;
    v[n++] = r->r_b.x, v[n++] = r->r_b.y, v[n++] = r->r_o.x, v[n++] = r->r_o.y;
    v[n++] = r->n_rod, v[n++] = r->m_rod;
    v[n++] = r->link_dir.x, v[n++] = r->link_dir.y, v[n++] = r->axis.x, v[n++] = r->axis.y;
    /* not the amplification: its data factor jumps where a largest output changes */
    v[n++] = r->conditioning, v[n++] = r->closure, v[n++] = r->kin_amplification;
}

/* input + t seed, field by field (the seed has the input's layout; branch and
 * threshold are not moved). */
static dyad_cylinder_input cyl_step(const dyad_cylinder_input* in, const dyad_cylinder_input* s,
                                    double t)
{
    dyad_cylinder_input q = *in;
    dyad_real* to = (dyad_real*)&q;
    const dyad_real* from = (const dyad_real*)in;
    const dyad_real* by = (const dyad_real*)s;
    const size_t before = offsetof(dyad_cylinder_input, branch) / sizeof(dyad_real);
    const size_t after = offsetof(dyad_cylinder_input, barrel) / sizeof(dyad_real);
    const size_t end = offsetof(dyad_cylinder_input, singular_threshold) / sizeof(dyad_real);
    size_t k;
    for (k = 0; k < end; ++k) {
        if (k < before || k >= after) {
            to[k] = (dyad_real)(from[k] + t * by[k]);
        }
    }
    return q;
}

static dyad_cylinder_input cyl_random_seed(rng* r, const dyad_cylinder_input* in)
{
    dyad_cylinder_input s, zero;
    dyad_real* to = (dyad_real*)&s;
    const size_t end = offsetof(dyad_cylinder_input, singular_threshold) / sizeof(dyad_real);
    size_t k;
    memset(&zero, 0, sizeof zero);
    s = zero;
    for (k = 0; k < end; ++k) {
        to[k] = (dyad_real)uniform(r, -1, 1);
    }
    s.branch = 0;
    /* a mass or inertia moves in proportion to itself: no step leaves its domain */
    s.barrel.mass *= in->barrel.mass, s.barrel.inertia *= in->barrel.inertia;
    s.rod.mass *= in->rod.mass, s.rod.inertia *= in->rod.inertia;
    s.link.mass *= in->link.mass, s.link.inertia *= in->link.inertia;
    return s;
}

/* The exact tangent against a central difference of the outputs. */
static int test_cylinder_tangent(void)
{
    int fails = 0, k, i;
    double worst = 0;
    rng r = {0xC7100004u};
    for (k = 0; k < 2000; ++k) {
        const dyad_cylinder_input in = cyl_random(&r, 1), seed = cyl_random_seed(&r, &in);
        const double h = 1e-5 * (CYL_EPS > 1e-10 ? 1e3 : 1);
        const dyad_cylinder_input plus = cyl_step(&in, &seed, h), minus = cyl_step(&in, &seed, -h);
        dyad_cylinder_result v, d, rp, rm, plain;
        double vd[CYL_OUTPUTS], vp[CYL_OUTPUTS], vm[CYL_OUTPUTS], vv[CYL_OUTPUTS], scale = 1;
        if (dyad_cylinder_tangent(&in, &seed, &v, &d) != DYAD_STATUS_OK ||
            dyad_cylinder(&plus, &rp) != DYAD_STATUS_OK ||
            dyad_cylinder(&minus, &rm) != DYAD_STATUS_OK || dyad_cylinder(&in, &plain) != 0) {
            CHECK(0, "configuration %d does not solve: %s %s %s", k, dyad_status_name(v.status),
                  dyad_status_name(rp.status), dyad_status_name(rm.status));
            continue;
        }
        cyl_outputs(&plain, vp), cyl_outputs(&v, vv);
        CHECK(memcmp(vp, vv, sizeof vp) == 0 && plain.amplification == v.amplification,
              "configuration %d: the tangent's value differs from dyad_cylinder's", k);
        cyl_outputs(&d, vd), cyl_outputs(&rp, vp), cyl_outputs(&rm, vm);
        for (i = 0; i < CYL_OUTPUTS; ++i) {
            scale += fabs(vd[i]) + fabs(vv[i]);
        }
        for (i = 0; i < CYL_OUTPUTS; ++i) {
            const double e = fabs((vp[i] - vm[i]) / (2 * h) - vd[i]) / (scale * v.amplification);
            worst = e > worst ? e : worst;
        }
    }
    CHECK(worst < CYL_FD_LIMIT, "tangent off its central difference by %.3g", worst);
    printf("    tangent within %.3g of its central difference (relative)\n", worst);
    return fails;
}

static dyad_cylinder_input cyl_line_input;

static int cyl_expect_invalid(const dyad_cylinder_input* in, dyad_cylinder_field field);

/* O at the origin, A at (1, 0), B on the x axis of the link. */
static dyad_status cyl_line(double s, double b_dist, dyad_cylinder_result* out)
{
    dyad_cylinder_input in = dyad_cylinder_input_default();
    in.a.position = vec(1, 0);
    in.pin_b = vec(b_dist, 0);
    in.length = (dyad_real)s;
    in.rate = (dyad_real)0.1;
    in.link.force = vec(0, 100);
    in.rod.mass = 2;
    in.gravity = vec(0, -9.81);
    cyl_line_input = in;
    return dyad_cylinder(&in, out);
}

/* The frame pins 1 mm apart (10 cm in float, whose threshold is higher) and the link 1 m
 * long: the triangle is thin, its conditioning about 1e-3, and every body still balances
 * within 16 eps x amplification. */
static int test_cylinder_pins_close(void)
{
    int fails = 0, k;
    for (k = 0; k < 5; ++k) {
        dyad_cylinder_input in = dyad_cylinder_input_default();
        dyad_cylinder_result out;
#ifdef DYAD_REAL_FLOAT
        in.a.position = vec(0.1, 0);
#else
        in.a.position = vec(1e-3, 0);
#endif
        in.pin_b = vec(1, 0);
        in.length = (dyad_real)(0.9995 + 0.00025 * k);
        in.rate = (dyad_real)0.1;
        in.accel = (dyad_real)-0.2;
        in.link.force = vec(30, 100);
        in.link.moment = -5;
        in.rod.mass = 2;
        in.barrel.mass = 3;
        in.gravity = vec(0, -9.81);
        CHECK(dyad_cylinder(&in, &out) == DYAD_STATUS_OK, "length %g: %s", (double)in.length,
              dyad_status_name(out.status));
        if (out.status == DYAD_STATUS_OK) {
            const double worst = cyl_worst_imbalance(&in, &out, 0.3);
            CHECK(worst < 16 * CYL_EPS * out.amplification,
                  "length %g: imbalance %g above 16 eps x amplification %g", (double)in.length,
                  worst, 16 * CYL_EPS * out.amplification);
        }
    }
    return fails;
}
/* Near and beyond the toggle and the stroke. */
static int test_cylinder_statuses(void)
{
    int fails = 0, k;
    dyad_cylinder_result out;
    const double rb = 0.5, ends[2] = {1 - rb, 1 + rb};
    int e;
    for (e = 0; e < 2; ++e) {
        int seen_singular = 0;
        for (k = 1; k <= 15; ++k) {
            const double delta = pow(10, -k), inward = e == 0 ? 1 : -1;
            const dyad_status st = cyl_line(ends[e] + inward * delta, rb, &out);
            if (st == DYAD_STATUS_OK) {
                CHECK(!seen_singular, "ok at %g from the toggle after a singular nearer", delta);
                CHECK(CYL_EPS * out.kin_amplification <= 1.01 * sqrt(CYL_EPS) &&
                          cyl_worst_imbalance(&cyl_line_input, &out, 0.3) <
                              16 * CYL_EPS * out.amplification,
                      "ok at %g from the toggle with eps x kin_amplification %g", delta,
                      CYL_EPS * out.kin_amplification);
            } else {
                CHECK(st == DYAD_STATUS_SINGULAR, "%g from the toggle: %s", delta,
                      dyad_status_name(st));
                CHECK(out.conditioning >= 0 && isnan(out.axial_force),
                      "singular without conditioning or with an axial force");
                seen_singular = 1;
            }
        }
        CHECK(seen_singular, "never singular on the way to toggle %d", e);
        CHECK(cyl_line(ends[e], rb, &out) == DYAD_STATUS_SINGULAR, "at toggle %d: %s", e,
              dyad_status_name(out.status));
        CHECK(cyl_line(ends[e] - (e == 0 ? 1 : -1) * 0.01, rb, &out) ==
                      DYAD_STATUS_CANNOT_ASSEMBLE &&
                  fabs(out.gap - 0.01) < 1e-6 && isnan(out.r_o.x),
              "beyond stroke end %d: %s, gap %g", e, dyad_status_name(out.status), out.gap);
        CHECK(out.failure == (e == 0 ? DYAD_KIN_TOO_FAR : DYAD_KIN_TOO_CLOSE),
              "beyond stroke end %d: failure %d", e, (int)out.failure);
    }
    CHECK(cyl_line(0.9, 0.5, &out) == DYAD_STATUS_OK && out.conditioning > 0.3,
          "mid-stroke: %s, conditioning %g", dyad_status_name(out.status), out.conditioning);
    {
        /* the mounts' round-off carried in: |A|_1 + |O|_1 = 1, size 0.5 + 0.9 + 1 = 2.4 */
        const double own = 1 + 1 / out.closure + 1 / out.conditioning;
        dyad_cylinder_input in = cyl_line_input;
        dyad_cylinder_result moved;
        in.mount_amplification = 100;
        CHECK(dyad_cylinder(&in, &moved) == DYAD_STATUS_OK &&
                  fabs(moved.kin_amplification / (own * (1 + 100 * (1 + 1 / 2.4))) - 1) < 1e-5,
              "mount amplification 100: kin_amplification %g, own %g", moved.kin_amplification,
              own);
        in.mount_amplification = 1 / (4 * in.singular_threshold);
        CHECK(dyad_cylinder(&in, &moved) == DYAD_STATUS_SINGULAR,
              "mount amplification 1 / (4 threshold) not singular: %s",
              dyad_status_name(moved.status));
        in.mount_amplification = -1;
        fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_MOUNT_AMPLIFICATION);
    }
    return fails;
}

static int cyl_expect_invalid(const dyad_cylinder_input* in, dyad_cylinder_field field)
{
    int fails = 0;
    dyad_cylinder_result out;
    CHECK(dyad_cylinder(in, &out) == DYAD_STATUS_INVALID_INPUT && out.field == field &&
              isnan(out.axial_force),
          "expected %s refused, got %s naming '%s'", dyad_cylinder_field_name(field),
          dyad_status_name(out.status), dyad_cylinder_field_name(out.field));
    return fails;
}

/* Every real field of the input, by its place, with the field that names it. */
typedef struct cyl_real_field {
    size_t offset;
    dyad_cylinder_field field;
} cyl_real_field;

#define CYL_FIELD(member, name) {offsetof(dyad_cylinder_input, member), DYAD_CYL_FIELD_##name}
static const cyl_real_field cyl_real_fields[] = {
    CYL_FIELD(a.position.x, A_POSITION),
    CYL_FIELD(a.position.y, A_POSITION),
    CYL_FIELD(a.velocity.x, A_VELOCITY),
    CYL_FIELD(a.velocity.y, A_VELOCITY),
    CYL_FIELD(a.acceleration.x, A_ACCELERATION),
    CYL_FIELD(a.acceleration.y, A_ACCELERATION),
    CYL_FIELD(o.position.x, O_POSITION),
    CYL_FIELD(o.position.y, O_POSITION),
    CYL_FIELD(o.velocity.x, O_VELOCITY),
    CYL_FIELD(o.velocity.y, O_VELOCITY),
    CYL_FIELD(o.acceleration.x, O_ACCELERATION),
    CYL_FIELD(o.acceleration.y, O_ACCELERATION),
    CYL_FIELD(pin_b.x, PIN_B),
    CYL_FIELD(pin_b.y, PIN_B),
    CYL_FIELD(length, LENGTH),
    CYL_FIELD(rate, RATE),
    CYL_FIELD(accel, ACCEL),
    CYL_FIELD(barrel.mass, BARREL_MASS),
    CYL_FIELD(barrel.com, BARREL_COM),
    CYL_FIELD(barrel.inertia, BARREL_INERTIA),
    CYL_FIELD(rod.mass, ROD_MASS),
    CYL_FIELD(rod.com, ROD_COM),
    CYL_FIELD(rod.inertia, ROD_INERTIA),
    CYL_FIELD(link.mass, LINK_MASS),
    CYL_FIELD(link.com.x, LINK_COM),
    CYL_FIELD(link.com.y, LINK_COM),
    CYL_FIELD(link.inertia, LINK_INERTIA),
    CYL_FIELD(link.force.x, LINK_FORCE),
    CYL_FIELD(link.force.y, LINK_FORCE),
    CYL_FIELD(link.moment, LINK_MOMENT),
    CYL_FIELD(gravity.x, GRAVITY),
    CYL_FIELD(gravity.y, GRAVITY),
    CYL_FIELD(singular_threshold, SINGULAR_THRESHOLD),
    CYL_FIELD(mount_amplification, MOUNT_AMPLIFICATION),
};
#undef CYL_FIELD

/* Each real field NaN, infinite or (a mass or an inertia, the amplification of the
 * mounts) negative is named, alone or with a later field bad too; one left as it was
 * solves. */
static int test_cylinder_every_field_poisoned(void)
{
    int fails = 0;
    rng r = {0xC7100006u};
    const dyad_cylinder_input base = cyl_random(&r, 1);
    const double poisons[3] = {NAN, INFINITY, -1};
    dyad_cylinder_result out;
    size_t f;
    int p;
    CHECK(dyad_cylinder(&base, &out) == DYAD_STATUS_OK, "the base case does not solve");
    for (f = 0; f < sizeof cyl_real_fields / sizeof cyl_real_fields[0]; ++f) {
        const cyl_real_field* field = &cyl_real_fields[f];
        for (p = 0; p < 3; ++p) {
            dyad_cylinder_input in = base;
            const int negative_is_bad = field->field == DYAD_CYL_FIELD_BARREL_MASS ||
                                        field->field == DYAD_CYL_FIELD_BARREL_INERTIA ||
                                        field->field == DYAD_CYL_FIELD_ROD_MASS ||
                                        field->field == DYAD_CYL_FIELD_ROD_INERTIA ||
                                        field->field == DYAD_CYL_FIELD_LINK_MASS ||
                                        field->field == DYAD_CYL_FIELD_LINK_INERTIA ||
                                        field->field == DYAD_CYL_FIELD_LENGTH ||
                                        field->field == DYAD_CYL_FIELD_SINGULAR_THRESHOLD ||
                                        field->field == DYAD_CYL_FIELD_MOUNT_AMPLIFICATION;
            if (p == 2 && !negative_is_bad) {
                continue;
            }
            *(dyad_real*)(void*)((char*)&in + field->offset) = (dyad_real)poisons[p];
            fails += cyl_expect_invalid(&in, field->field);
            in.mount_amplification = (dyad_real)-1; /* the last field bad too */
            fails += cyl_expect_invalid(&in, field->field);
        }
    }
    return fails;
}

static int test_cylinder_invalid(void)
{
    int fails = 0;
    rng r = {0xC7100005u};
    const dyad_cylinder_input base = cyl_random(&r, 1);
    dyad_cylinder_input in;
    dyad_cylinder_result out;
    in = base, in.length = 0;
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_LENGTH);
    in = base, in.pin_b = vec(0, 0);
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_PIN_B);
    in = base, in.branch = 0;
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_BRANCH);
    in = base, in.rod.mass = -1;
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_ROD_MASS);
    in = base, in.barrel.com = (dyad_real)NAN;
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_BARREL_COM);
    in = base, in.link.force.y = (dyad_real)INFINITY;
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_LINK_FORCE);
    in = base, in.o.acceleration.x = (dyad_real)NAN;
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_O_ACCELERATION);
    in = base, in.singular_threshold = 1;
    fails += cyl_expect_invalid(&in, DYAD_CYL_FIELD_SINGULAR_THRESHOLD);
    CHECK(dyad_cylinder(NULL, &out) == DYAD_STATUS_INVALID_INPUT &&
              out.field == DYAD_CYL_FIELD_INPUT,
          "a NULL input is not refused");
    CHECK(dyad_cylinder(&base, NULL) == DYAD_STATUS_INVALID_INPUT, "a NULL result is not refused");
    CHECK(strcmp(dyad_cylinder_field_name(DYAD_CYL_FIELD_ROD_INERTIA), "rod.inertia") == 0,
          "field name");
    return fails;
}

/* dyad_cylinder_lane answers 0 exactly where dyad_cylinder says ok, and then gives its
 * outputs bit for bit but for the two angles (taken after a batch's loop); over random
 * cylinders, most of them spoiled: beyond the stroke, a threshold no conditioning
 * passes, a field NaN, infinite or negative, a load that overflows, a branch 0 or 2. */
static int test_cylinder_lane_matches_cylinder(void)
{
    int fails = 0, k, ok = 0, refused = 0;
    rng r = {0xC7100007u};
    const size_t fields = sizeof cyl_real_fields / sizeof cyl_real_fields[0];
    const size_t angles[2] = {offsetof(dyad_cylinder_result, link_angle),
                              offsetof(dyad_cylinder_result, cylinder_angle)};
    for (k = 0; k < 6000; ++k) {
        dyad_cylinder_input in = cyl_random(&r, k % 2);
        dyad_cylinder_result want, got;
        dyad_status s;
        dyad_real bad;
        size_t j;
        switch ((int)uniform(&r, 0, 10)) {
        case 0: in.length = (dyad_real)(3 * in.length + 5); break;
        case 1: in.singular_threshold = (dyad_real)0.999; break;
        case 2:
        case 3: {
            const cyl_real_field* f = &cyl_real_fields[(size_t)uniform(&r, 0, (double)fields)];
            const double poison = k % 3 == 0 ? NAN : k % 3 == 1 ? INFINITY : -1;
            *(dyad_real*)(void*)((char*)&in + f->offset) = (dyad_real)poison;
            break;
        }
        case 4: in.link.moment = (dyad_real)(HUGE_REAL * 0.5); break;
        case 5: in.branch = k % 3 == 0 ? 0 : 2; break;
        default: break;
        }
        memset(&want, 0, sizeof want); /* the padding too: compared as bytes */
        memset(&got, 0, sizeof got);
        s = dyad_cylinder(&in, &want);
        {
            dyad_cylinder_input lane_in = in;
            lane_in.branch = 1; /* left at its default: the lane takes the branch as a real */
            bad = dyad_cylinder_lane(&lane_in, (dyad_real)in.branch, &got);
        }
        CHECK((bad == 0) == (s == DYAD_STATUS_OK), "cylinder %d: status %s, lane %g", k,
              dyad_status_name(s), (double)bad);
        if (s == DYAD_STATUS_OK) {
            for (j = 0; j < 2; ++j) { /* the angles the lane leaves: the same as the twin's */
                memcpy((char*)&got + angles[j], (const char*)&want + angles[j], sizeof(dyad_real));
            }
            got.status = want.status;
            got.field = want.field;
            got.failure = want.failure;
            got.gap = want.gap;
            CHECK(memcmp(&got, &want, sizeof got) == 0, "cylinder %d: the lane's outputs differ",
                  k);
            ++ok;
        } else {
            ++refused;
        }
    }
    CHECK(ok > 2000 && refused > 2000, "%d ok, %d not: both sides of the checks reached", ok,
          refused);
    {
        const dyad_cylinder_input a = dyad_cylinder_input_default();
        const dyad_cylinder_input b = dyad_lane_cylinder_input_default();
        CHECK(memcmp(&a, &b, sizeof a) == 0, "the lane's default cylinder input differs");
    }
    return fails;
}
