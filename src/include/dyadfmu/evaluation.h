/* dyadfmu: how one evaluation of a model went, as a scene's generated code
 * (<id>_scene.h: <id>_evaluate, <id>_derivative) and the FMU layer (fmu/fmu_model.h)
 * both report it. Here, in the core's headers, so that a scene's code builds with
 * the core alone and nothing of FMI: in firmware, against the installed core, or
 * from a bundle (scripts/build-scene --bundle). */
#ifndef DYADFMU_EVALUATION_H
#define DYADFMU_EVALUATION_H

/* Same numbering as fmi2Status and fmi3Status. */
typedef enum fmu_status {
    FMU_OK = 0,
    FMU_WARNING = 1,
    FMU_DISCARD = 2,
    FMU_ERROR = 3,
    FMU_FATAL = 4
} fmu_status;

/* How an evaluation went: FMU_OK; FMU_DISCARD where the model has no answer
 * for these inputs (outputs NaN, e.g. a singular dyad); FMU_ERROR for an input
 * the model rejects, naming the variable. `reason` says why in one line (the FMU
 * layer logs it). */
typedef struct fmu_evaluation {
    fmu_status status;
    int bad_variable; /* index of the variable to blame, or -1 */
    char reason[320];
} fmu_evaluation;

#endif /* DYADFMU_EVALUATION_H */
