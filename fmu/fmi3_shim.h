/* dyadfmu FMU layer: what the FMI 3 shim files share. */
#ifndef DYADFMU_FMI3_SHIM_H
#define DYADFMU_FMI3_SHIM_H

#include "fmi3FunctionTypes.h"
#include "fmu_instance.h"

/* The layer's statuses are FMI's, in FMI's order (fmu_model.h). */
static inline fmi3Status to_fmi3(fmu_status status)
{
    return (fmi3Status)status;
}

#endif /* DYADFMU_FMI3_SHIM_H */
