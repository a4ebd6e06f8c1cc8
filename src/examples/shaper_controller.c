/* A controller's feed-forward on the generated code of a mechanism FMU.
 *
 * A simulated controller ticks every 1 ms. At each tick it reads the crank's angle,
 * speed and acceleration from a trajectory (an encoder and an observer in a real
 * drive) and calls shaper_evaluate, the shaper's generated scene code
 * (modelDescription/scenes/shaper.toml) as its bundle for firmware holds it
 * (scripts/build-scene --bundle: the scene's code and the core's files it calls, built
 * in float): the kinematics of the chain are solved inside, so the crank's motion and
 * the cutting force are its only inputs. Out come the feed-forward motor
 * torque and the loads on the bearings (the crank's main bearing O, the lever's pivot
 * O2, the lever tip B), which a bearing-load monitor would compare with its limits.
 *
 * The cutting force acts on the working stroke, while the ram moves towards -x: the
 * controller sees the ram's direction from the pair position the scene outputs at
 * the previous tick.
 *
 * usage: shaper_controller [--ticks N] [--every K]
 *   N ticks of 1 ms (default 2000), a line printed every K ticks (default 100).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shaper_scene.h"

#define TICK_SECONDS 1e-3
#define PI           3.14159265358979323846

/* The crank's trajectory: mean speed w0 with a 30 % ripple, as a drive would hold it. */
typedef struct crank_state {
    double angle;   /* rad */
    double omega;   /* rad/s */
    double epsilon; /* rad/s2 */
} crank_state;

static crank_state trajectory(double t)
{
    const double w0 = 6.0, ripple = 0.3;
    crank_state s;
    s.angle = w0 * t + ripple * (1.0 - cos(w0 * t));
    s.omega = w0 * (1.0 + ripple * sin(w0 * t));
    s.epsilon = ripple * w0 * w0 * cos(w0 * t);
    return s;
}

static double magnitude(double x, double y)
{
    return sqrt(x * x + y * y);
}

static int parse_count(const char* text, long* value)
{
    char* end = NULL;
    const long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || v <= 0 || v > 100000000L) {
        return 0;
    }
    *value = v;
    return 1;
}

static int parse_arguments(int argc, char** argv, long* ticks, long* every)
{
    int i;
    for (i = 1; i < argc; ++i) {
        if (i + 1 < argc && strcmp(argv[i], "--ticks") == 0 && parse_count(argv[i + 1], ticks)) {
            ++i;
        } else if (i + 1 < argc && strcmp(argv[i], "--every") == 0 &&
                   parse_count(argv[i + 1], every)) {
            ++i;
        } else {
            fprintf(stderr, "usage: %s [--ticks N] [--every K]  (N, K positive integers)\n",
                    argv[0]);
            return 0;
        }
    }
    return 1;
}

int main(int argc, char** argv)
{
    long ticks = 2000, every = 100, k;
    shaper_input in;
    shaper_output out;
    fmu_evaluation evaluation;
    double ram_x_before = NAN, ram_x_now = NAN; /* the ram's pin at the last two ticks (m) */
    double peak_torque = 0.0, peak_o = 0.0, peak_o2 = 0.0;
    long refused = 0;
    if (!parse_arguments(argc, argv, &ticks, &every)) {
        return 2;
    }
    memset(&in, 0, sizeof in);
    in.slider_mass = 12.0;
    in.gravity_x = 0.0;
    in.gravity_y = -9.81;
    printf("%8s %9s %11s %11s %11s %11s\n", "t [s]", "phi [deg]", "torque [Nm]", "|R_O| [N]",
           "|R_O2| [N]", "|R_B| [N]");
    for (k = 0; k < ticks; ++k) {
        const double t = (double)k * TICK_SECONDS;
        const crank_state crank = trajectory(t);
        in.crank_dir = dyad_dir_from_angle((dyad_real)crank.angle);
        in.crank_omega = crank.omega;
        in.crank_epsilon = crank.epsilon;
        /* the cutting force on the working stroke (ram moving towards -x); NaN compares false */
        in.slider_force_x = ram_x_now < ram_x_before ? 2000.0 : 0.0; /* opposes the ram */
        in.slider_force_y = 0.0;
        shaper_evaluate(&in, &out, &evaluation);
        if (evaluation.status != FMU_OK) {
            ++refused;
            fprintf(stderr, "tick %ld: %s\n", k, evaluation.reason);
            continue;
        }
        ram_x_before = ram_x_now;
        ram_x_now = out.ram_d_m_position_x;
        peak_torque = fmax(peak_torque, fabs(out.crank_torque));
        peak_o = fmax(peak_o, magnitude(out.crank_r_o_x, out.crank_r_o_y));
        peak_o2 = fmax(peak_o2, magnitude(out.slot_r_mk_x, out.slot_r_mk_y));
        if (k % every == 0) {
            printf("%8.3f %9.2f %11.3f %11.2f %11.2f %11.2f\n", t,
                   fmod(crank.angle, 2 * PI) * 180.0 / PI, out.crank_torque,
                   magnitude(out.crank_r_o_x, out.crank_r_o_y),
                   magnitude(out.slot_r_mk_x, out.slot_r_mk_y),
                   magnitude(out.ram_r_np_x, out.ram_r_np_y));
        }
    }
    printf("%ld ticks, %ld refused; peak |torque| %.3f N m, peak |R_O| %.2f N, peak |R_O2| "
           "%.2f N\n",
           ticks, refused, peak_torque, peak_o, peak_o2);
    return refused == 0 ? 0 : 1;
}
