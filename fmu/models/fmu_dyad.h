/* dyadfmu FMU layer: the behaviour of a dyad model, the solver of one type on
 * dyad_input (input block) and dyad_result (output block). */
#ifndef DYADFMU_FMU_DYAD_H
#define DYADFMU_FMU_DYAD_H

#include "dyadfmu/dyad.h"
#include "fmu_model.h"

/* A core input field and the variable (input or parameter) that feeds it. */
typedef struct fmu_dyad_feed {
    dyad_field field;
    int variable; /* index into the model's variables */
} fmu_dyad_feed;

typedef struct fmu_dyad_data {
    dyad_solver solve;                /* this type's solver: the FMU links no other */
    dyad_solver solve_valid;          /* the same without the check of its input */
    const dyad_tangent_type* tangent; /* its directional derivative (&dyad_tangent_rrt, ...) */
    /* Which variable feeds which field, in the order of the variables: an
     * invalid input is blamed on the first variable that feeds its field. */
    const fmu_dyad_feed* feeds;
    size_t feed_count;
} fmu_dyad_data;

extern const fmu_behaviour fmu_dyad_behaviour;

#endif /* DYADFMU_FMU_DYAD_H */
