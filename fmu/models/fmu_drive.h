/* dyadfmu FMU layer: the drive of a crank, a DC motor with a linear
 * torque-speed characteristic on a rigid shaft, as a model with states. */
#ifndef DYADFMU_FMU_DRIVE_H
#define DYADFMU_FMU_DRIVE_H

#include "fmu_model.h"

/* The input block: inputs, parameters and the states. */
typedef struct fmu_drive_input {
    double load_torque;  /* N m: torque of the driven mechanism on the crank at zero acceleration */
    double load_inertia; /* kg m^2: inertia the mechanism adds at the crank */
    double load_demand;  /* N m: torque the mechanism needs at the crank at zero acceleration */
    double stall_torque; /* N m: motor torque at standstill */
    double no_load_speed; /* rad/s: speed where the motor torque vanishes */
    double inertia;       /* kg m^2: rotor and crank about the crank pivot O */
    double crank_mass;    /* kg */
    double crank_com_x;   /* m: crank's centre of mass in the crank frame */
    double crank_com_y;   /* m */
    double gravity_x;     /* m/s^2 */
    double gravity_y;     /* m/s^2 */
    double start_angle;   /* rad */
    double start_speed;   /* rad/s */
    double angle;         /* state: crank angle (rad) */
    double speed;         /* state: crank speed (rad/s) */
} fmu_drive_input;

typedef struct fmu_drive_output {
    double angle;        /* rad */
    double speed;        /* rad/s */
    double acceleration; /* rad/s^2, for the current state and inputs */
    double motor_torque; /* N m */
    int status;          /* 0 ok, 2 invalid input, 3 out of range */
} fmu_drive_output;

extern const fmu_behaviour fmu_drive_behaviour;

#endif /* DYADFMU_FMU_DRIVE_H */
