/* dyadfmu FMU layer: the behaviour of a dyad model, the solver of one type on
 * dyad_input (input block) and dyad_result (output block). */
#ifndef DYADFMU_FMU_DYAD_H
#define DYADFMU_FMU_DYAD_H

#include "fmu_model.h"

typedef struct fmu_dyad_data {
    dyad_type type;
    dyad_solver solve; /* this type's solver: the FMU links no other */
} fmu_dyad_data;

extern const fmu_behaviour fmu_dyad_behaviour;

#endif /* DYADFMU_FMU_DYAD_H */
