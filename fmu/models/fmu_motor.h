/* dyadfmu FMU layer: a DC motor with a gear, supply voltage and shaft speed in, shaft
 * torque out, its armature current the state; for coupling a separate motor to a
 * mechanism plant. The rotor's inertia is not here: it belongs to the plant it drives. */
#ifndef DYADFMU_FMU_MOTOR_H
#define DYADFMU_FMU_MOTOR_H

#include "fmu_model.h"

/* The input block: inputs, their first derivatives, parameters and the state. */
typedef struct fmu_motor_input {
    double voltage;         /* V: supply voltage */
    double omega;           /* rad/s: speed of the driven shaft, after the gear */
    double voltage_rate;    /* V/s: first derivative of voltage over a step (FMI 2) */
    double omega_rate;      /* rad/s2: first derivative of omega over a step (FMI 2) */
    double resistance;      /* Ohm: armature resistance R */
    double inductance;      /* H: armature inductance L; 0: no circuit dynamics */
    double torque_constant; /* N.m/A = V.s/rad: k */
    double friction;        /* N.m.s/rad: viscous friction c at the rotor */
    double ratio;           /* gear ratio r: rotor speed = r x shaft speed */
    double current_start;   /* A: the current when initialization ends */
    double current;         /* state: armature current (A) */
} fmu_motor_input;

typedef struct fmu_motor_output {
    double torque;  /* N.m: on the shaft, r (k i - c r omega) */
    double current; /* A */
    int status;     /* 0 ok, 3 out of range */
} fmu_motor_output;

extern const fmu_behaviour fmu_motor_behaviour;

#endif /* DYADFMU_FMU_MOTOR_H */
