/* dyadfmu FMU layer: the description of one dyad model as the FMU layer sees
 * it. The table of variables is generated from modelDescription/<model>.toml
 * (by modelDescription/generate.py) together with both model descriptions, so
 * the C side and the XML cannot drift apart. */
#ifndef DYADFMU_FMU_MODEL_H
#define DYADFMU_FMU_MODEL_H

#include <stddef.h>

#include "dyadfmu/dyad.h"

typedef enum fmu_causality {
    FMU_PARAMETER = 0, /* fixed: settable until initialization ends */
    FMU_INPUT,         /* continuous input: settable at any time */
    FMU_OUTPUT         /* computed: read only */
} fmu_causality;

typedef enum fmu_value_type {
    FMU_REAL = 0, /* fmi2Real / fmi3Float64 */
    FMU_INTEGER   /* fmi2Integer / fmi3Int32 */
} fmu_value_type;

/* Where a variable's value lives in the solver's structures. */
typedef enum fmu_target {
    FMU_TARGET_INPUT_REAL = 0, /* the dyad_real at `offset` in dyad_input */
    FMU_TARGET_INPUT_ANGLE,    /* the dyad_vec2 at `offset` in dyad_input, set to (cos, sin) */
    FMU_TARGET_RESULT_REAL,    /* the dyad_real at `offset` in dyad_result */
    FMU_TARGET_RESULT_STATUS   /* dyad_result.status, as an integer */
} fmu_target;

/* Bits of fmu_variable.bounds. */
enum {
    FMU_HAS_MIN = 1,
    FMU_HAS_MAX = 2,
    FMU_MIN_EXCLUSIVE = 4, /* the value must exceed min */
    FMU_MAX_EXCLUSIVE = 8  /* the value must stay below max */
};

typedef struct fmu_variable {
    unsigned int vr;        /* value reference */
    const char* name;       /* structured name, e.g. "link_m.mass" */
    const char* unit;       /* SI unit, "" if dimensionless */
    fmu_causality causality;
    fmu_value_type type;
    fmu_target target;
    size_t offset;          /* into dyad_input or dyad_result, see target */
    double start;           /* start value (inputs and parameters) */
    double min, max;        /* bounds, valid where `bounds` says so */
    unsigned bounds;        /* FMU_HAS_MIN | FMU_HAS_MAX | ..._EXCLUSIVE */
    dyad_field field;       /* the core's input field it feeds (inputs, parameters) */
} fmu_variable;

typedef struct fmu_model {
    const char* identifier; /* modelIdentifier, e.g. "dyad_rrt" */
    const char* token;      /* instantiation token (FMI 3) / GUID (FMI 2) */
    dyad_type type;
    dyad_solver solve;      /* this type's solver: the FMU links no other */
    const fmu_variable* variables;
    size_t variable_count;
    const short* index_of_vr; /* variable index for each vr < vr_limit, -1 where none */
    unsigned int vr_limit;
} fmu_model;

/* The model compiled into this FMU, defined by the generated <model>_model.c. */
extern const fmu_model fmu_this_model;

#endif /* DYADFMU_FMU_MODEL_H */
