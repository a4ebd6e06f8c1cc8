/* dyadfmu FMU layer: the description of one model as the FMU layer sees it.
 * The table of variables is generated from the model's one source (a scene file,
 * by modelDescription/scene.py; the drive's and the motor's variable tables,
 * modelDescription/interface/drive.toml and motor.toml, by modelDescription/generate.py)
 * together with both model descriptions, so the C side and the XML cannot drift apart. */
#ifndef DYADFMU_FMU_MODEL_H
#define DYADFMU_FMU_MODEL_H

#include <stddef.h>

/* fmu_status and fmu_evaluation, which a scene's generated code reports with too */
#include "dyadfmu/evaluation.h"
#include "dyadfmu/types.h"

/* A path that is rarely taken (a refusal, a log message) kept out of the function that
 * calls it, so that the common path saves and restores fewer registers. */
#if defined(__GNUC__)
#define FMU_COLD __attribute__((noinline, cold))
#else
#define FMU_COLD
#endif

/* A step of the common path, inlined into each of its callers even where the
 * compiler's size heuristics would call it: the call would cost more than it does. */
#if defined(__GNUC__)
#define FMU_INLINE static inline __attribute__((always_inline))
#else
#define FMU_INLINE static inline
#endif

typedef enum fmu_causality {
    FMU_PARAMETER = 0, /* fixed: settable until initialization ends */
    FMU_INPUT,         /* continuous input: settable at any time */
    FMU_OUTPUT         /* computed: read only */
} fmu_causality;

typedef enum fmu_value_type {
    FMU_REAL = 0,   /* fmi2Real / fmi3Float64 */
    FMU_INTEGER,    /* fmi2Integer / fmi3Int32 */
    FMU_ENUMERATION /* an item's value: fmi2Integer / fmi3Int64 */
} fmu_value_type;

/* Where a variable's value lives: in the model's input block (parameters and
 * inputs) or its output block, both structs of the model's behaviour (for a
 * dyad: dyad_input and dyad_result). */
typedef enum fmu_target {
    FMU_TARGET_INPUT_REAL = 0, /* the double at `offset` in the input block */
    FMU_TARGET_INPUT_ANGLE,    /* the two doubles at `offset` in the input block: (cos, sin) */
    FMU_TARGET_RESULT_REAL,    /* the double at `offset` in the output block */
    FMU_TARGET_RESULT_STATUS,  /* the int (enum) at `offset` in the output block */
    FMU_TARGET_SETTING         /* a setting of the FMU layer itself: `offset` is its fmu_setting */
} fmu_target;

/* What the FMU layer itself reads, not the model: the variables of target
 * FMU_TARGET_SETTING. */
typedef enum fmu_setting {
    /* What doStep does where the model has no answer (a singular position, a
     * mechanism that cannot assemble, reactions that overflow): the items of the
     * enumeration on_singular. */
    FMU_SETTING_ON_SINGULAR = 0
} fmu_setting;

enum {
    FMU_ON_SINGULAR_DISCARD = 1, /* doStep returns Discard (the default) */
    FMU_ON_SINGULAR_CONTINUE = 2 /* doStep returns OK: outputs NaN, status says why */
};

/* Bits of fmu_variable.bounds. */
enum {
    FMU_HAS_MIN = 1,
    FMU_HAS_MAX = 2,
    FMU_MIN_EXCLUSIVE = 4, /* the value must exceed min */
    FMU_MAX_EXCLUSIVE = 8  /* the value must stay below max */
};

typedef struct fmu_variable {
    unsigned int vr;  /* value reference */
    const char* name; /* structured name, e.g. "link_m.mass" */
    const char* unit; /* SI unit, "" if dimensionless */
    fmu_causality causality;
    fmu_value_type type;
    fmu_target target;
    size_t offset;   /* into dyad_input or dyad_result, or the fmu_setting; see target */
    double start;    /* start value (inputs and parameters) */
    double min, max; /* bounds, valid where `bounds` says so */
    unsigned bounds; /* FMU_HAS_MIN | FMU_HAS_MAX | ..._EXCLUSIVE */
} fmu_variable;

struct fmu_model;

/* One state of a model with states: a double of its input block that its start sets
 * and its steps advance (the drive: the crank's angle and speed). An FMU state keeps
 * it, since nothing else does. */
typedef struct fmu_model_state {
    const char* name; /* as its output shows it, e.g. "crank.angle" */
    const char* unit; /* SI unit, "" if dimensionless */
    size_t offset;    /* of the double in the input block */
} fmu_model_state;

/* The states of a model with states. */
typedef struct fmu_states {
    const fmu_model_state* states;
    size_t count;
    /* The index of the first state that no start or step could have left in the input
     * block `input` (its parameters and inputs set, their angles converted), or -1. */
    int (*refused)(const struct fmu_model* model, const void* input);
} fmu_states;

/* A Real input that a model with states follows over a step as a straight line from
 * its value at the step's start (canInterpolateInputs): the input's value and its first
 * time derivative as set, both doubles of the input block. */
typedef struct fmu_input_rate {
    size_t value_offset; /* the input's value (the variable's offset) */
    size_t rate_offset;  /* its first time derivative (unit/s) */
} fmu_input_rate;

/* What a model with states offers an importer that couples at higher order: the inputs
 * it interpolates and the first time derivatives of its outputs. */
typedef struct fmu_interpolation {
    const fmu_input_rate* inputs;
    size_t input_count;
    /* The first time derivative of every Real output at the current point, into the
     * output block `rate` (each output's at its own offset); NaN where it has none,
     * with the evaluation saying why. */
    void (*output_rates)(const struct fmu_model* model, const void* input, void* rate,
                         fmu_evaluation* evaluation);
} fmu_interpolation;

/* Outputs an evaluation may leave to their first read (a scene's effective inertia: a
 * kinematic pass of its own that an importer reading only torques and reactions need not
 * pay for at every step): fmu_behaviour.evaluate in two halves, which together give what
 * it gives, bit for bit. */
typedef struct fmu_later {
    const unsigned int* vrs; /* their value references */
    size_t count;
    /* Every output but those, which it leaves NaN. */
    void (*first)(const struct fmu_model* model, const void* input, void* output,
                  fmu_evaluation* evaluation);
    /* After `first` returned FMU_OK on these blocks: those outputs too; FMU_DISCARD
     * (every output NaN, the status output saying why) where they are not finite. */
    void (*later)(const struct fmu_model* model, const void* input, void* output,
                  fmu_evaluation* evaluation);
} fmu_later;

/* An algebraic model's evaluation at many samples at once, in columns (a scene's
 * <identifier>_lanes): lanes[j * lanes + i] is real j of sample i: the input
 * block's reals in its order (an angle as the x and y of its unit vector), then the
 * output block's before its status, then the count of the sample's failed checks, then
 * scratch; `columns` in all. Where the count is 0 the sample's outputs are what
 * `evaluate` (or `later->first`) gives, bit for bit, with FMU_OK; elsewhere they mean
 * nothing, and `evaluate` says what went wrong. The loop over samples vectorises. */
/* `wanted`: NULL, or a flag per real of the output block; an output not wanted may be left
 * out. `cap`: the widest instruction set the lanes may take (dyad_lanes_isa); they take the
 * widest this CPU runs up to it (to measure each: DYADFMU_LANES, fmu/README.md) */
typedef void (*fmu_lanes_fn)(dyad_lanes_isa cap, size_t count, double* lanes,
                             const unsigned char* wanted);
typedef struct fmu_lanes {
    size_t lanes;   /* samples per call, at most */
    size_t inputs;  /* reals of the input block */
    size_t outputs; /* reals of the output block, its status aside */
    size_t columns;
    fmu_lanes_fn whole;
    fmu_lanes_fn first; /* as later->first; NULL where the model has no fmu_later */
    /* as first (or whole where first is NULL) with the outputs flagged in `bounds` NaN and
     * the same statuses, for a call that reads none of those; NULL where there is none */
    fmu_lanes_fn bare;
    const unsigned char* bounds; /* a flag per real of the output block; NULL without bare */
} fmu_lanes;

/* What a kind of model computes, on its own input and output blocks. */
typedef struct fmu_behaviour {
    size_t input_size;  /* bytes of the input block */
    size_t output_size; /* bytes of the output block */
    /* The input block before any start value is applied. */
    void (*initialise)(const struct fmu_model* model, void* input);
    /* The outputs for the inputs. */
    void (*evaluate)(const struct fmu_model* model, const void* input, void* output,
                     fmu_evaluation* evaluation);
    /* A model with states: sets them from their start parameters when
     * initialization ends, and advances them over a communication step of h
     * seconds with the inputs held, returning how far they got: h. FMU_ERROR
     * refuses the step (the states left as they were, 0 returned); FMU_DISCARD
     * reports one that failed, the states left at the last point it could
     * reach, that many seconds into the step (0: where they were). NULL for an
     * algebraic model. */
    void (*start)(const struct fmu_model* model, void* input);
    double (*advance)(const struct fmu_model* model, void* input, double h,
                      fmu_evaluation* evaluation);
    /* Exact directional derivative of the outputs along `seed` (an input block of
     * rates; an angle's rate as the derivative of its (cos, sin)). NULL: none. */
    void (*derivative)(const struct fmu_model* model, const void* input, const void* seed,
                       void* output, void* rate, fmu_evaluation* evaluation);
    /* A model with states: what they are, for an FMU state (fmu_state.c). NULL for an
     * algebraic model. */
    const fmu_states* states;
    /* A model with states that interpolates its inputs and differentiates its outputs
     * (canInterpolateInputs, maxOutputDerivativeOrder 1). NULL: it does neither. */
    const fmu_interpolation* interpolation;
    /* Outputs computed when first read after an evaluation (an algebraic model only);
     * NULL: the evaluation computes every output. */
    const fmu_later* later;
    /* The evaluation at many samples at once (an algebraic model only); NULL: none. */
    const fmu_lanes* lanes;
} fmu_behaviour;

/* The calls an importer makes every step, set every Real input and get every Real
 * output, each with its value references in ascending order: generated with the
 * table as straight copies between the caller's array and where the values are
 * kept, every place a constant. The layer uses them for a call that names exactly
 * these references; any other goes by the slots. */
typedef struct fmu_copies {
    const unsigned int* input_vrs; /* NULL: the model has no Real input */
    size_t input_count;
    /* the inputs into the input block, an angle into `values` (per variable, as set) */
    void (*store_inputs)(void* input, double* values, const double* from);
    const unsigned int* output_vrs; /* NULL: no Real output */
    size_t output_count;
    void (*load_outputs)(const void* output, double* to);
} fmu_copies;

typedef struct fmu_model {
    const char* identifier; /* modelIdentifier, e.g. "dyad_rrt" */
    const char* token;      /* instantiation token (FMI 3) / GUID (FMI 2) */
    const fmu_variable* variables;
    size_t variable_count;
    const short* index_of_vr; /* variable index for each vr < vr_limit, -1 where none */
    unsigned int vr_limit;
    const fmu_behaviour* behaviour;
    const void* data; /* the behaviour's model data (a dyad: fmu_dyad_data) */
    const fmu_copies* copies;
} fmu_model;

/* The index of the variable called `name` in model's table, -1 if it has none (the
 * hand-written models name their bad variable by its FMU name). */
int fmu_variable_named(const fmu_model* model, const char* name);

/* The model compiled into this FMU, defined by the generated <model>_model.c. */
extern const fmu_model fmu_this_model;

#endif /* DYADFMU_FMU_MODEL_H */
