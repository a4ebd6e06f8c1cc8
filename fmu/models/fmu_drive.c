/* dyadfmu FMU layer: the crank drive (see fmu_drive.h).
 *
 * The crank turns about the fixed pivot O at angle phi and speed omega:
 *
 *     (J + J_load) eps = T_m(omega) + tau_load - tau_demand + (r_c x m_c g),
 *     T_m(omega) = T_stall (1 - omega / omega_0),
 *
 * with J the rotor's and crank's inertia about O, r_c the crank's centre of
 * mass turned by phi, tau_load the mechanism's torque on the crank at zero
 * acceleration and J_load the inertia it adds (its torque is tau_load -
 * J_load eps; a co-simulation master that knows the mechanism's sensitivity
 * passes it so that the loop closes inside the step). tau_demand is the same
 * torque with the sign of a mechanism FMU's driving torque (its crank.torque0):
 * a system that connects that output here needs no change of sign, which some
 * importers do not apply (fmpy's SSP runner).
 *
 * Integrator: the classical 4th-order Runge-Kutta method, with the inputs held
 * over the communication step and as many equal substeps as keep each below a
 * twentieth of the motor's mechanical time constant (J + J_load) omega_0 /
 * T_stall and below 0.005 rad of crank turn (which holds the integration
 * error near 1e-9 of the speed, below the co-simulation's own). The state has two components and is
 * smooth (gravity is a sine of phi), so an explicit method of high order is both accurate and cheap
 * once the substep resolves the one stiff scale, the motor's damping; it needs no Newton iteration,
 * and its result does not depend on anything but the step, which keeps co-simulation reproducible.
 * A step that needs more than FMU_DRIVE_MAX_SUBSTEPS substeps is refused before
 * any of them is taken: the count is compared as a double, since h / limit
 * may exceed every integer type.
 *
 * No output is ever infinite: an input such as load.torque = -DBL_MAX passes
 * the setters but overflows the acceleration, which is then NaN with status 3,
 * as a dyad reports a load that overflows. crank.epsilon is NaN whenever status
 * is not 0; motor.torque only where it overflows itself, since it depends on the
 * state alone (its declared dependencies stay empty); crank.angle and
 * crank.omega are the states.
 */
#include "fmu_drive.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

/* At 0.005 rad a substep this is over 5000 rad of crank turn, or 50000 of the
 * motor's time constants, in one communication step: a step that long is a
 * mistake, and it would take about a tenth of a second. */
#define FMU_DRIVE_MAX_SUBSTEPS 1e6

/* Values of the status output. */
enum { FMU_DRIVE_OK = 0, FMU_DRIVE_INVALID_INPUT = 2, FMU_DRIVE_OUT_OF_RANGE = 3 };

static double total_inertia(const fmu_drive_input* in)
{
    return in->inertia + in->load_inertia;
}

static double motor_torque(const fmu_drive_input* in, double speed)
{
    return in->stall_torque * (1 - speed / in->no_load_speed);
}

static double acceleration(const fmu_drive_input* in, double angle, double speed)
{
    const double c = cos(angle), s = sin(angle);
    const double rx = c * in->crank_com_x - s * in->crank_com_y;
    const double ry = s * in->crank_com_x + c * in->crank_com_y;
    const double gravity = in->crank_mass * (rx * in->gravity_y - ry * in->gravity_x);
    return (motor_torque(in, speed) + in->load_torque - in->load_demand + gravity) /
           total_inertia(in);
}

static void initialise(const fmu_model* model, void* input)
{
    static const fmu_drive_input zero;
    (void)model;
    *(fmu_drive_input*)input = zero;
}

static void start(const fmu_model* model, void* input)
{
    fmu_drive_input* in = (fmu_drive_input*)input;
    (void)model;
    in->angle = in->start_angle;
    in->speed = in->start_speed;
}

/* The loaded inertia must stay positive: the parameters' bounds guarantee
 * J > 0, but J_load is an input that a master computes. */
static int check(const fmu_model* model, const fmu_drive_input* in, fmu_evaluation* e)
{
    if (!(total_inertia(in) > 0)) {
        e->status = FMU_ERROR;
        e->bad_variable = fmu_variable_named(model, "load.inertia");
        snprintf(e->reason, sizeof e->reason, "inertia + load.inertia = %g kg.m2 must be positive",
                 total_inertia(in));
        return 0;
    }
    return 1;
}

static void evaluate(const fmu_model* model, const void* input, void* output,
                     fmu_evaluation* evaluation)
{
    const fmu_drive_input* in = (const fmu_drive_input*)input;
    fmu_drive_output* out = (fmu_drive_output*)output;
    /* N.m; depends on the state alone, so it is NaN where it overflows whether
     * or not the inertia check below passes */
    const double torque = motor_torque(in, in->speed);
    evaluation->status = FMU_OK;
    evaluation->bad_variable = -1;
    evaluation->reason[0] = '\0';
    out->angle = in->angle;
    out->speed = in->speed;
    out->motor_torque = isfinite(torque) ? torque : (double)NAN;
    out->acceleration = (double)NAN;
    out->status = FMU_DRIVE_INVALID_INPUT;
    if (!check(model, in, evaluation)) {
        return;
    }
    out->acceleration = acceleration(in, in->angle, in->speed);
    out->status = FMU_DRIVE_OK;
    if (!isfinite(torque) || !isfinite(out->acceleration)) {
        evaluation->status = FMU_DISCARD;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "the motor torque (%g N.m) or the crank's acceleration (%g rad/s2) overflows "
                 "double; it is NaN",
                 torque, out->acceleration);
        out->status = FMU_DRIVE_OUT_OF_RANGE;
        out->acceleration = (double)NAN;
    }
}

/* The state after `substeps` classical Runge-Kutta steps of dt seconds. */
static void integrate(const fmu_drive_input* in, double dt, long substeps, double* angle,
                      double* speed)
{
    double q = *angle, w = *speed;
    long k;
    for (k = 0; k < substeps; ++k) {
        const double a1 = acceleration(in, q, w);
        const double w2 = w + 0.5 * dt * a1;
        const double a2 = acceleration(in, q + 0.5 * dt * w, w2);
        const double w3 = w + 0.5 * dt * a2;
        const double a3 = acceleration(in, q + 0.5 * dt * w2, w3);
        const double w4 = w + dt * a3;
        const double a4 = acceleration(in, q + dt * w3, w4);
        q += dt / 6 * (w + 2 * w2 + 2 * w3 + w4);
        w += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    }
    *angle = q;
    *speed = w;
}

static double advance(const fmu_model* model, void* input, double h, fmu_evaluation* evaluation)
{
    fmu_drive_input* in = (fmu_drive_input*)input;
    const double time_constant = total_inertia(in) * in->no_load_speed / in->stall_torque;
    const double turn = fabs(in->speed) > 0 ? 0.005 / fabs(in->speed) : h;
    double limit = 0.05 * time_constant < turn ? 0.05 * time_constant : turn;
    double angle = in->angle, speed = in->speed, needed;

    evaluation->status = FMU_OK;
    evaluation->bad_variable = -1;
    evaluation->reason[0] = '\0';
    if (!check(model, in, evaluation)) {
        return 0;
    }
    if (!(limit > 0) || limit > h) {
        limit = h;
    }
    needed = ceil(h / limit);
    if (!(needed <= FMU_DRIVE_MAX_SUBSTEPS)) {
        evaluation->status = FMU_ERROR;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "communicationStepSize = %g s needs %.3g substeps of %.3g s (speed %.3g "
                 "rad/s, time constant %.3g s), over the %g allowed: take shorter steps",
                 h, needed, limit, speed, time_constant, FMU_DRIVE_MAX_SUBSTEPS);
        return 0;
    }
    integrate(in, h / needed, (long)needed, &angle, &speed);
    if (!isfinite(angle) || !isfinite(speed)) {
        evaluation->status = FMU_DISCARD;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "the crank's state is no longer finite (angle %g rad, speed %g rad/s)", angle,
                 speed);
        return 0;
    }
    /* A step is taken only if the outputs at its end are finite: one that ends
     * where the motor torque or the acceleration overflows is discarded with
     * the state kept, as the importer is told (last successful time = t). */
    if (!isfinite(motor_torque(in, speed)) || !isfinite(acceleration(in, angle, speed))) {
        evaluation->status = FMU_DISCARD;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "the step would end where the motor torque (%g N.m) or the crank's "
                 "acceleration (%g rad/s2) overflows double (angle %g rad, speed %g rad/s)",
                 motor_torque(in, speed), acceleration(in, angle, speed), angle, speed);
        return 0;
    }
    in->angle = angle;
    in->speed = speed;
    return h;
}

/* The crank's angle and speed: what an FMU state keeps of the drive beyond its
 * parameters and inputs. */
static const fmu_model_state drive_states[] = {
    {"crank.angle", "rad", offsetof(fmu_drive_input, angle)},
    {"crank.omega", "rad/s", offsetof(fmu_drive_input, speed)},
};

/* A step leaves the states finite (advance refuses one that would not), and so does
 * start, from finite parameters; any finite pair is a start. */
static int state_refused(const fmu_model* model, const void* input)
{
    const fmu_drive_input* in = (const fmu_drive_input*)input;
    (void)model;
    if (!isfinite(in->angle)) {
        return 0;
    }
    return isfinite(in->speed) ? -1 : 1;
}

static const fmu_states drive_state_table = {
    drive_states, sizeof drive_states / sizeof drive_states[0], state_refused};

const fmu_behaviour fmu_drive_behaviour = {sizeof(fmu_drive_input),
                                           sizeof(fmu_drive_output),
                                           initialise,
                                           evaluate,
                                           start,
                                           advance,
                                           NULL,
                                           &drive_state_table,
                                           NULL,
                                           NULL,
                                           NULL};
