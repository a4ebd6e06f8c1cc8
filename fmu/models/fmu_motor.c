/* dyadfmu FMU layer: the DC motor (see fmu_motor.h).
 *
 * The armature circuit, with the rotor turning at r omega (omega the shaft's speed, r the
 * gear ratio) and its back-EMF k r omega:
 *
 *     L di/dt = V - R i - k r omega,
 *     T_shaft = r (k i - c r omega).
 *
 * The rotor's inertia belongs to the mechanism plant the motor drives, which integrates
 * the motion; here the motor's own state is the current i alone.
 *
 * The circuit is linear, so a communication step is solved in closed form rather than
 * integrated. With u = V - k r omega, and the inputs held over the step or following
 * their first derivatives (canInterpolateInputs: V(tau) = V0 + V' tau, omega likewise,
 * so that u(tau) = u0 + u' tau), the exact solution at tau = h, x = h R / L, is
 *
 *     i(h) = i0 + (h / L) phi1(-x) (u0 - R i0) + (h^2 / L) phi2(-x) u',
 *     phi1(z) = (e^z - 1) / z,    phi2(z) = (e^z - 1 - z) / z^2,
 *
 * the homogeneous decay and the particular solution linear in tau. Below x = 1 phi1
 * comes from expm1 and phi2 from its series, both accurate to rounding however small x
 * is (no i0 + u'h/R - u'h/R to cancel); from x = 1 on the same terms are written with
 * 1 / R, so that a circuit whose time constant L / R is many orders below the step
 * (x up to infinity) gives the algebraic current u(h) / R less the lag L u' / R^2.
 * L = 0 is that limit itself: the current follows the inputs, i = u / R. No
 * iteration and no allocation: a step is a few dozen operations, the same on every run.
 *
 * No output is ever infinite: an input such as shaft.omega = DBL_MAX passes the
 * setters (they refuse only what is not finite) but overflows the torque, which is then
 * NaN with status 3, and so is the current where it overflows itself (without inductance,
 * where it follows the inputs); a step that would end where either overflows is discarded
 * with the state kept.
 */
#include "fmu_motor.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

/* Values of the status output. */
enum { FMU_MOTOR_OK = 0, FMU_MOTOR_OUT_OF_RANGE = 3 };

static void clear(fmu_evaluation* evaluation)
{
    evaluation->status = FMU_OK;
    evaluation->bad_variable = -1;
    evaluation->reason[0] = '\0';
}

/* u = V - k r omega: the voltage that drives the current through R and L. */
static double driving_voltage(const fmu_motor_input* in, double voltage, double omega)
{
    return voltage - in->torque_constant * in->ratio * omega;
}

static double shaft_torque(const fmu_motor_input* in, double current, double omega)
{
    return in->ratio * (in->torque_constant * current - in->friction * in->ratio * omega);
}

/* The current the output shows: the state, or without inductance the inputs' own. */
static double current_now(const fmu_motor_input* in)
{
    if (in->inductance == 0) {
        return driving_voltage(in, in->voltage, in->omega) / in->resistance;
    }
    return in->current;
}

/* phi2(-x) = (e^-x - 1 + x) / x^2 for 0 <= x <= 1, by its series
 * 1/2! - x/3! + x^2/4! - ..., nested: terms up to x^17 / 19! (below 1e-17 of 1/2). */
static double phi2_series(double x)
{
    double p = 1;
    int n;
    for (n = 19; n >= 3; --n) {
        p = 1 - x * p / n;
    }
    return p / 2;
}

/* a = (h / L) phi1(-x) and b = (h^2 / L) phi2(-x), x = h R / L: the change of the
 * current over h per volt of u0 - R i0 and per volt/second of u'. */
static void step_gains(const fmu_motor_input* in, double h, double* a, double* b)
{
    const double R = in->resistance, L = in->inductance;
    const double x = h * R / L;
    if (x < 1) {
        const double phi1 = x > 0 ? -expm1(-x) / x : 1;
        *a = h / L * phi1;
        *b = h / L * h * phi2_series(x);
    } else {
        const double decayed = -expm1(-x); /* 1 - e^-x: the share of the way to u / R */
        *a = decayed / R;
        *b = h / R * (1 - decayed / x);
    }
}

static void initialise(const fmu_model* model, void* input)
{
    static const fmu_motor_input zero;
    (void)model;
    *(fmu_motor_input*)input = zero;
}

static void start(const fmu_model* model, void* input)
{
    fmu_motor_input* in = (fmu_motor_input*)input;
    (void)model;
    in->current = in->current_start;
}

/* Status 3: the torque NaN, and the current too where it overflows itself (only without
 * inductance: with it the current is the state, finite after every start and step). */
FMU_COLD static void out_of_range(fmu_motor_output* out, fmu_evaluation* evaluation)
{
    evaluation->status = FMU_DISCARD;
    snprintf(evaluation->reason, sizeof evaluation->reason,
             "the shaft torque (%g N.m) or the current (%g A) overflows double; the torque is NaN",
             out->torque, out->current);
    if (!isfinite(out->current)) {
        out->current = (double)NAN;
    }
    out->torque = (double)NAN;
    out->status = FMU_MOTOR_OUT_OF_RANGE;
}

static void evaluate(const fmu_model* model, const void* input, void* output,
                     fmu_evaluation* evaluation)
{
    const fmu_motor_input* in = (const fmu_motor_input*)input;
    fmu_motor_output* out = (fmu_motor_output*)output;
    (void)model;
    clear(evaluation);
    out->current = current_now(in);
    out->torque = shaft_torque(in, out->current, in->omega);
    out->status = FMU_MOTOR_OK;
    if (!isfinite(out->current) || !isfinite(out->torque)) {
        out_of_range(out, evaluation);
    }
}

/* FMU_ERROR, naming the input, where its derivative carries it past the finite within
 * h seconds: the step's end would be no input a setter accepts. */
FMU_COLD static double ramp_too_far(const fmu_model* model, const fmu_motor_input* in, double h,
                                    fmu_evaluation* evaluation)
{
    const int voltage = !isfinite(in->voltage + h * in->voltage_rate);
    const char* name = voltage ? "motor.voltage" : "shaft.omega";
    evaluation->status = FMU_ERROR;
    evaluation->bad_variable = fmu_variable_named(model, name);
    snprintf(evaluation->reason, sizeof evaluation->reason,
             "%s = %g with its derivative %g per second is not finite %g s on: set a smaller "
             "derivative or a shorter step",
             name, voltage ? in->voltage : in->omega, voltage ? in->voltage_rate : in->omega_rate,
             h);
    return 0;
}

FMU_COLD static double overflows(double current, double torque, fmu_evaluation* evaluation)
{
    evaluation->status = FMU_DISCARD;
    snprintf(evaluation->reason, sizeof evaluation->reason,
             "the step would end where the current (%g A) or the shaft torque (%g N.m) "
             "overflows double",
             current, torque);
    return 0;
}

/* The current at the end of a communication step of h seconds, in closed form (see the
 * file's comment); the inputs move along their derivatives to the step's end, where the
 * outputs are computed from. */
static double advance(const fmu_model* model, void* input, double h, fmu_evaluation* evaluation)
{
    fmu_motor_input* in = (fmu_motor_input*)input;
    /* a rate of 0 leaves its input as it is (-0 stays -0) */
    const double voltage = in->voltage_rate != 0 ? in->voltage + h * in->voltage_rate : in->voltage;
    const double omega = in->omega_rate != 0 ? in->omega + h * in->omega_rate : in->omega;
    double current, a, b;
    clear(evaluation);
    if (!isfinite(voltage) || !isfinite(omega)) {
        return ramp_too_far(model, in, h, evaluation);
    }
    if (in->inductance == 0) {
        current = driving_voltage(in, voltage, omega) / in->resistance;
    } else {
        const double u0 = driving_voltage(in, in->voltage, in->omega);
        const double u_rate = driving_voltage(in, in->voltage_rate, in->omega_rate);
        step_gains(in, h, &a, &b);
        current = in->current + a * (u0 - in->resistance * in->current) + b * u_rate;
    }
    if (!isfinite(current) || !isfinite(shaft_torque(in, current, omega))) {
        return overflows(current, shaft_torque(in, current, omega), evaluation);
    }
    in->current = current;
    in->voltage = voltage;
    in->omega = omega;
    return h;
}

/* The current: what an FMU state keeps of the motor beyond its parameters, inputs and
 * their derivatives. */
static const fmu_model_state motor_states[] = {
    {"motor.current", "A", offsetof(fmu_motor_input, current)},
};

/* A start (from a finite parameter) and a step (refused where it would not) leave the
 * current finite; any finite current is a start. */
static int state_refused(const fmu_model* model, const void* input)
{
    (void)model;
    return isfinite(((const fmu_motor_input*)input)->current) ? -1 : 0;
}

static const fmu_states motor_state_table = {
    motor_states, sizeof motor_states / sizeof motor_states[0], state_refused};

/* The inputs followed as straight lines over a step (FMI 2's canInterpolateInputs). */
static const fmu_input_rate motor_input_rates[] = {
    {offsetof(fmu_motor_input, voltage), offsetof(fmu_motor_input, voltage_rate)},
    {offsetof(fmu_motor_input, omega), offsetof(fmu_motor_input, omega_rate)},
};

/* d(motor.current)/dt = (u - R i) / L, or u' / R without inductance, and
 * d(shaft.torque)/dt = r (k di/dt - c r omega'), at the current point. */
static void output_rates(const fmu_model* model, const void* input, void* output,
                         fmu_evaluation* evaluation)
{
    const fmu_motor_input* in = (const fmu_motor_input*)input;
    fmu_motor_output* rate = (fmu_motor_output*)output;
    (void)model;
    clear(evaluation);
    if (in->inductance == 0) {
        rate->current = driving_voltage(in, in->voltage_rate, in->omega_rate) / in->resistance;
    } else {
        const double u = driving_voltage(in, in->voltage, in->omega);
        rate->current = (u - in->resistance * in->current) / in->inductance;
    }
    rate->torque = shaft_torque(in, rate->current, in->omega_rate);
    rate->status = 0;
    if (!isfinite(rate->current) || !isfinite(rate->torque)) {
        evaluation->status = FMU_DISCARD;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "the current's derivative (%g A/s) or the torque's (%g N.m/s) overflows double",
                 rate->current, rate->torque);
        rate->current = (double)NAN;
        rate->torque = (double)NAN;
    }
}

static const fmu_interpolation motor_interpolation = {
    motor_input_rates, sizeof motor_input_rates / sizeof motor_input_rates[0], output_rates};

const fmu_behaviour fmu_motor_behaviour = {
    sizeof(fmu_motor_input), sizeof(fmu_motor_output), initialise, evaluate, start, advance, NULL,
    &motor_state_table,      &motor_interpolation,     NULL,       NULL};
