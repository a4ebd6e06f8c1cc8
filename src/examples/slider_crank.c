/* dyadfmu example: joint reactions of an offset slider-crank over one crank
 * revolution at constant speed, from the RRT solver, printed as a table.
 *
 * The crank (length r, about the frame origin) drives the connecting rod n
 * (length L) from the crank pin A = D_n to the slider pin B = E; the slider m
 * runs on a horizontal guide at height e (the offset), its pin on the guide
 * (l_m = 0). A gas force pushes the slider towards the crank.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dyadfmu/dyad.h"
#include "dyadfmu/vec2.h"

#define PI 3.14159265358979323846

typedef struct slider_crank {
    double crank;       /* r (m) */
    double rod;         /* L (m) */
    double offset;      /* e (m) */
    double rod_mass;    /* kg */
    double rod_inertia; /* about its centre of mass, kg m^2 */
    double slider_mass; /* kg */
    double peak_gas;    /* peak gas force on the slider (N) */
} slider_crank;

static void usage(FILE* to)
{
    fprintf(to, "usage: slider_crank [--steps N] [--rpm RPM] [--help]\n"
                "Prints the joint reactions of an offset slider-crank (r = 0.05 m, L = 0.2 m,\n"
                "e = 0.01 m) over one revolution at constant crank speed, solved as an RRT dyad.\n"
                "  --steps N   crank positions per revolution (default 24, 1..100000)\n"
                "  --rpm RPM   crank speed in rev/min (default 3000, 0..100000)\n"
                "Columns: crank angle (deg); R_np, the force of the crank pin on the rod (N);\n"
                "R_mn, the force of the rod on the slider (N); N_mk, the guide's normal force on\n"
                "the slider (N); M_mk, the guide's reactive moment on the slider (N m);\n"
                "conditioning |i_n . i_k| (-).\n");
}

static int parse_number(const char* text, double lo, double hi, double* value)
{
    char* end = NULL;
    const double v = strtod(text, &end);
    if (end == text || *end != '\0' || !(v >= lo && v <= hi)) {
        return 0;
    }
    *value = v;
    return 1;
}

/* The dyad inputs at crank angle phi (rad), speed w (rad/s), zero crank
 * acceleration, from the closed-form position, velocity and acceleration. */
static dyad_input dyad_at(const slider_crank* sc, double phi, double w)
{
    const double r = sc->crank, L = sc->rod;
    const double sin_t = (sc->offset - r * sin(phi)) / L;
    const double cos_t = sqrt(1 - sin_t * sin_t);
    const double theta_dot = -r * cos(phi) * w / (L * cos_t);
    const double theta_ddot =
        (r * sin(phi) * w * w + L * sin_t * theta_dot * theta_dot) / (L * cos_t);
    const double accel_pin_x = -r * cos(phi) * w * w;
    const double accel_pin_y = -r * sin(phi) * w * w;
    const double accel_slider =
        -r * cos(phi) * w * w - L * cos_t * theta_dot * theta_dot - L * sin_t * theta_ddot;
    dyad_input in = dyad_input_default();

    in.gravity = dyad_vec2_make(0, (dyad_real)-9.81);
    in.guide_k = dyad_vec2_make(1, 0);

    in.m.dir = dyad_vec2_make(1, 0);
    in.m.length = 0;
    in.m.accel_d = dyad_vec2_make((dyad_real)accel_slider, 0);
    in.m.mass = (dyad_real)sc->slider_mass;
    in.m.force = dyad_vec2_make((dyad_real)(-sc->peak_gas * 0.5 * (1 + cos(phi))), 0);

    in.n.dir = dyad_vec2_make((dyad_real)cos_t, (dyad_real)sin_t);
    in.n.length = (dyad_real)L;
    in.n.omega = (dyad_real)theta_dot;
    in.n.epsilon = (dyad_real)theta_ddot;
    in.n.accel_d = dyad_vec2_make((dyad_real)accel_pin_x, (dyad_real)accel_pin_y);
    in.n.com = dyad_vec2_make((dyad_real)(0.3 * L), 0);
    in.n.mass = (dyad_real)sc->rod_mass;
    in.n.inertia = (dyad_real)sc->rod_inertia;
    return in;
}

int main(int argc, char** argv)
{
    const slider_crank sc = {0.05, 0.2, 0.01, 0.6, 2.4e-3, 0.45, 8000};
    double steps = 24, rpm = 3000, w;
    int a, k, failures = 0;

    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--help") == 0 || strcmp(argv[a], "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(argv[a], "--steps") == 0 && a + 1 < argc) {
            if (!parse_number(argv[++a], 1, 100000, &steps) || steps != floor(steps)) {
                fprintf(stderr,
                        "slider_crank: --steps wants a whole number from 1 to 100000, "
                        "got '%s'\n",
                        argv[a]);
                return 2;
            }
        } else if (strcmp(argv[a], "--rpm") == 0 && a + 1 < argc) {
            if (!parse_number(argv[++a], 0, 100000, &rpm)) {
                fprintf(stderr, "slider_crank: --rpm wants a number from 0 to 100000, got '%s'\n",
                        argv[a]);
                return 2;
            }
        } else {
            fprintf(stderr, "slider_crank: unknown or incomplete argument '%s'\n", argv[a]);
            usage(stderr);
            return 2;
        }
    }
    w = rpm * 2 * PI / 60;

    printf("%9s %12s %12s %12s %12s %12s %10s %8s\n", "angle/deg", "R_np.x/N", "R_np.y/N",
           "R_mn.x/N", "R_mn.y/N", "N_mk/N", "M_mk/N.m", "cond");
    for (k = 0; k < (int)steps; ++k) {
        const double phi = 2 * PI * k / steps;
        const dyad_input in = dyad_at(&sc, phi, w);
        dyad_result out;
        if (dyad_solve_rrt(&in, &out) != DYAD_STATUS_OK) {
            fprintf(stderr, "slider_crank: at %.1f deg: %s %s\n", phi * 180 / PI,
                    dyad_status_name(out.status), dyad_field_name(out.field));
            ++failures;
            continue;
        }
        /* "+ 0.0" prints a zero moment as 0 rather than -0. */
        printf("%9.1f %12.3f %12.3f %12.3f %12.3f %12.3f %10.4f %8.5f\n", phi * 180 / PI,
               (double)out.r_np.x, (double)out.r_np.y, (double)out.r_mn.x, (double)out.r_mn.y,
               (double)out.n_mk, (double)out.m_mk + 0.0, (double)out.conditioning);
    }
    return failures == 0 ? 0 : 1;
}
