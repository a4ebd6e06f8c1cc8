/* dyadfmu FMU layer: the behaviour of a dyad model, the solver of one type on
 * dyad_input (input block) and dyad_result (output block). */
#ifndef DYADFMU_FMU_DYAD_H
#define DYADFMU_FMU_DYAD_H

#if defined(__clang__) /* no a * b + c fused, by default or not: the lanes' bits (dyad_lanes.h) */
#pragma clang fp contract(off)
#endif

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

/* The behaviour's functions: the input block dyad_input_default(), the outputs (the
 * solve that trusts its input, which the layer has checked, and where it has no answer the
 * checking solve, for the reason), and the outputs with their directional derivative. */
void fmu_dyad_initialise(const fmu_model* model, void* input);
void fmu_dyad_evaluate(const fmu_model* model, const void* input, void* output,
                       fmu_evaluation* evaluation);
void fmu_dyad_derivative(const fmu_model* model, const void* input, const void* seed, void* output,
                         void* rate, fmu_evaluation* evaluation);

/* The fmu_behaviour of a dyad whose many samples go through `lanes` (fmu_dyad_lanes.h). */
#define FMU_DYAD_BEHAVIOUR(lanes) \
    {sizeof(dyad_input),          \
     sizeof(dyad_result),         \
     fmu_dyad_initialise,         \
     fmu_dyad_evaluate,           \
     NULL,                        \
     NULL,                        \
     fmu_dyad_derivative,         \
     NULL,                        \
     NULL,                        \
     NULL,                        \
     lanes}

#endif /* DYADFMU_FMU_DYAD_H */
