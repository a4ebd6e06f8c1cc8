/* dyadfmu FMU layer: one FMU instance, independent of the FMI version.
 *
 * The FMI 2 and FMI 3 shims (fmi2_functions.c, fmi3_functions.c) translate
 * their API onto these functions; everything that does not depend on the
 * version lives here: the call-sequence rules, the variable store, get/set by
 * value reference through the generated variable table, the (lazy) solve and
 * logging. An instance owns all its data: instances never share state. */
#ifndef DYADFMU_FMU_INSTANCE_H
#define DYADFMU_FMU_INSTANCE_H

#include <stddef.h>
#include <stdint.h>

#include "fmu_model.h"

/* Format checking of the printf-style loggers. MinGW builds use its C99 stdio
 * (__USE_MINGW_ANSI_STDIO), whose formats (%zu) are GNU's, not the Microsoft
 * runtime's. */
#if defined(__MINGW32__)
#define FMU_PRINTF_FORMAT(fmt, first) __attribute__((format(gnu_printf, fmt, first)))
#elif defined(__GNUC__)
#define FMU_PRINTF_FORMAT(fmt, first) __attribute__((format(printf, fmt, first)))
#else
#define FMU_PRINTF_FORMAT(fmt, first)
#endif

/* The states of the co-simulation state machine, as bits so that each entry
 * point can name the states it may be called in with one mask. */
typedef enum fmu_state {
    FMU_STATE_INSTANTIATED = 1 << 0,
    FMU_STATE_INITIALIZATION = 1 << 1,
    FMU_STATE_STEP = 1 << 2,
    FMU_STATE_TERMINATED = 1 << 3
} fmu_state;

/* The operations whose legal states fmu_check_call looks up. */
typedef enum fmu_operation {
    FMU_OP_SETUP_EXPERIMENT = 0,
    FMU_OP_ENTER_INITIALIZATION,
    FMU_OP_EXIT_INITIALIZATION,
    FMU_OP_DO_STEP,
    FMU_OP_TERMINATE,
    FMU_OP_RESET,
    FMU_OP_GET,
    FMU_OP_SET,
    FMU_OP_STEP_STATUS,
    FMU_OP_DEBUG_LOGGING,
    FMU_OP_UNSUPPORTED,
    FMU_OP_STATE, /* get, set, free, serialize and deserialize an FMU state */
    FMU_OP_COUNT
} fmu_operation;

struct fmu_logger;

/* Passes one formatted message to the importer's logger. Implemented by each
 * shim, which knows the importer's callback type. */
typedef void (*fmu_log_sink)(const struct fmu_logger* logger, fmu_status status,
                             const char* category, const char* message);

typedef struct fmu_logger {
    fmu_log_sink sink;      /* NULL: messages are dropped */
    void (*callback)(void); /* the importer's logger, cast back by the sink */
    void* environment;      /* the importer's environment pointer */
    const char* instance_name;
} fmu_logger;

/* What a value reference addresses, resolved when the instance is made (and when
 * its parameters close), so that a get or set of a Real finds the value's place
 * with one index and accepts a valid value with two comparisons. Whatever that
 * does not accept goes to the checks that name the problem. */
typedef struct fmu_slot {
    /* A Real set within [low, high] is valid now: inside the variable's bounds
     * and finite, and the variable may be set in this state. Empty (low > high)
     * for an output, a closed parameter, an Integer and no variable at all. */
    double low, high;
    double* write;      /* where a Real set stores the value */
    const double* read; /* where a Real get reads it; NULL: not a Real */
    int is_output;      /* the value is the model's: evaluate before reading */
    int later;          /* an output of the model's fmu_later: computed when first read */
} fmu_slot;

/* The places of the last Real set or get that the slots accepted, by position,
 * so that the same call again (the same value references: an importer repeats
 * its calls every step) is one vector check of the values and a copy. */
/* The count of a plan that matches no call. */
#define FMU_NO_PLAN ((size_t)-1)

typedef struct fmu_plan {
    size_t count;           /* of the call (never 0); FMU_NO_PLAN: none */
    unsigned int* vr;       /* its value references */
    size_t bounded_count;   /* set: the values with bounds tighter than finite, */
    unsigned int* position; /* their positions in the call, */
    double* low;            /* and their accepted intervals */
    double* high;
    double** write;      /* where a set stores each value */
    const double** read; /* where a get reads each value */
    /* The model's straight copy where the call is its every step's (fmu_copies);
     * NULL: by `write` or `read`. */
    void (*store)(void* input, double* values, const double* from);
    void (*load)(const void* output, double* to);
    int later; /* a get that reads an output of the model's fmu_later */
} fmu_plan;

/* An angle variable: kept as set, read by the model as its unit vector. */
typedef struct fmu_angle {
    const double* angle; /* as set (rad) */
    double* unit;        /* (cos, sin) in the input block */
    double converted;    /* the angle `unit` was computed from; NaN: none */
} fmu_angle;

typedef void* (*fmu_allocate)(size_t count, size_t size);
typedef void (*fmu_release)(void* memory);

/* A saved FMU state (fmu_state.c): the instance's state as serialized bytes. */
typedef struct fmu_saved fmu_saved;

typedef struct fmu_instance {
    const fmu_model* model;
    fmu_logger logger;
    fmu_allocate allocate;
    fmu_release release;
    fmu_saved* saved;        /* the FMU states saved from this instance, freed with it */
    unsigned log_categories; /* bit k: category k of fmu_log_category_names is on */
    fmu_state state;
    /* bit k: operation k may take its common path now (find_common_paths) */
    unsigned common_paths;
    double time; /* communication point reached (s) */
    double last_successful_time;
    /* the latest end of a step (s): the importer's stopTime, less the rounding of a
     * sum of steps that reaches it; +inf where none is defined */
    double stop_limit;
    int terminate_requested; /* set when a step cannot be completed */
    int dirty;               /* inputs changed since the last evaluation */
    int later_pending;       /* the model's fmu_later outputs not computed since it */
    /* The evaluation a step makes (choose_evaluation): the model's whole one, or where
     * the importer's gets read none of its fmu_later outputs, its first half; and whether
     * it leaves those outputs to their first read. */
    void (*evaluate_now)(const struct fmu_model* model, const void* input, void* output,
                         fmu_evaluation* evaluation);
    int leaves_later;
    fmu_evaluation evaluation; /* of the last evaluation */
    double* values;            /* one per variable, as set; outputs unused */
    fmu_slot* slots;           /* one per value reference below model->vr_limit */
    fmu_plan set_plan;         /* of at most model->vr_limit values each */
    fmu_plan get_plan;
    fmu_angle* angles; /* the angle variables, angle_count of them */
    size_t angle_count;
    int time_at_vr_0; /* value reference 0 reads the time (FMI 3) */
    /* The value of on_singular as set (FMU_ON_SINGULAR_...); NULL: the model has no
     * such setting, and doStep discards a step the model has no answer for. */
    const double* on_singular;
    /* The model's blocks (see fmu_behaviour), in the instance's own memory:
     * input kept up to date by every set, output of the last evaluation, and
     * scratch for directional derivatives. */
    void* input;
    void* output;
    void* seed;
    void* rate;
    void* value;
} fmu_instance;

/* Log categories declared in the model descriptions, in bit order. */
extern const char* const fmu_log_category_names[];
extern const size_t fmu_log_category_count;

/* Creates an instance with start values, or logs why not and returns NULL.
 * `time_at_vr_0`: value reference 0 reads the time (FMI 3). */
fmu_instance* fmu_instantiate(const fmu_model* model, const char* instance_name, const char* token,
                              fmu_logger logger, int logging_on, fmu_allocate allocate,
                              fmu_release release, int time_at_vr_0);
void fmu_free(fmu_instance* instance);

/* Error, with a logged reason, unless `operation` is legal in the current state. */
fmu_status fmu_check_call(fmu_instance* instance, fmu_operation operation, const char* function);

/* Logs printf-style through the instance's logger. Errors, discards and
 * warnings are always passed on; FMU_OK messages only with logCalls on. */
void fmu_log(const fmu_instance* instance, fmu_status status, const char* format, ...)
    FMU_PRINTF_FORMAT(3, 4);

fmu_status fmu_set_debug_logging(fmu_instance* instance, int logging_on, size_t count,
                                 const char* const categories[]);
/* The simulated interval an importer announces (s). */
typedef struct fmu_experiment {
    double start_time;
    int stop_defined; /* stop_time holds the end: a step past it is refused */
    double stop_time;
} fmu_experiment;

fmu_status fmu_setup_experiment(fmu_instance* instance, const fmu_experiment* experiment);
/* `experiment`: FMI 3's; NULL for FMI 2, which announced it by setupExperiment. */
fmu_status fmu_enter_initialization(fmu_instance* instance, const fmu_experiment* experiment);
fmu_status fmu_exit_initialization(fmu_instance* instance);
fmu_status fmu_do_step(fmu_instance* instance, double current_time, double step_size,
                       const char* function);
fmu_status fmu_terminate(fmu_instance* instance);
fmu_status fmu_reset(fmu_instance* instance);

/* Get and set by value reference, each function for the variable types its FMI
 * call addresses; a value reference of another type is an error. */
fmu_status fmu_get_real(fmu_instance* instance, const unsigned int vr[], size_t count,
                        double values[], const char* function);
fmu_status fmu_set_real(fmu_instance* instance, const unsigned int vr[], size_t count,
                        const double values[], const char* function);

/* The bit of a type in a set of types. */
#define FMU_TYPE_BIT(type) (1u << (unsigned)(type))

/* Values passed as int: `types` is what the call addresses, FMU_TYPE_BIT(FMU_INTEGER)
 * for fmi3Int32, and Enumerations too for fmi2Integer. */
fmu_status fmu_get_integer(fmu_instance* instance, const unsigned int vr[], size_t count,
                           int values[], unsigned types, const char* function);
fmu_status fmu_set_integer(fmu_instance* instance, const unsigned int vr[], size_t count,
                           const int values[], unsigned types, const char* function);
/* Enumerations passed as int64_t (fmi3Int64). */
fmu_status fmu_get_int64(fmu_instance* instance, const unsigned int vr[], size_t count,
                         int64_t values[], const char* function);
fmu_status fmu_set_int64(fmu_instance* instance, const unsigned int vr[], size_t count,
                         const int64_t values[], const char* function);

/* Exact directional derivative of Real outputs (unknowns) along a seed on Real
 * inputs (knowns), at the current inputs (dyad_solve_tangent_of). */
fmu_status fmu_directional_derivative(fmu_instance* instance, const unsigned int unknowns[],
                                      size_t n_unknowns, const unsigned int knowns[],
                                      size_t n_knowns, const double seed[], double derivative[],
                                      const char* function);

/* First derivatives of Real inputs (order[k] 1 each) that a model with states follows
 * over its next steps as straight lines, kept until set again (fmi2SetRealInputDerivatives);
 * and the first derivatives of Real outputs at the current point
 * (fmi2GetRealOutputDerivatives, fmi3GetOutputDerivatives). Error, "not supported", for a
 * model without fmu_behaviour.interpolation. */
fmu_status fmu_set_input_rates(fmu_instance* instance, const unsigned int vr[], size_t count,
                               const int order[], const double values[], const char* function);
fmu_status fmu_get_output_rates(fmu_instance* instance, const unsigned int vr[], size_t count,
                                const int order[], double values[], const char* function);

/* For variable types the model has none of: accepts an empty list, rejects
 * any value reference by number. */
fmu_status fmu_no_variables_of_type(fmu_instance* instance, fmu_operation operation,
                                    const unsigned int vr[], size_t count, const char* function);

/* The model evaluated on `rows` rows without an importer's instance: for each row,
 * the parameters p (rows x n_p, value references vr_p) and the inputs x (rows x n_i,
 * vr_i) set, the Real outputs vr_o read into y (rows x n_o), and that row's worst
 * status in status[row] (anything but FMU_OK: the row's outputs are NaN; the set or
 * the evaluation failed, as the same calls through FMI would). The instance is reset
 * and initialised again only where a row's parameters differ from the row before,
 * so rows sorted by their parameters cost one evaluation each. FMU_ERROR (no row
 * evaluated) where a value reference is unknown or of the wrong kind, or an array is
 * missing; FMU_FATAL where no instance could be made (a wrong token, no memory). Not part of FMI:
 * exported as dyadfmu_evaluate_rows for the design studies (scripts/dyadfmu/sweep). */
fmu_status fmu_evaluate_rows(const fmu_model* model, const char* token, int time_at_vr_0,
                             const unsigned int vr_p[], size_t n_p, const double p[],
                             const unsigned int vr_i[], size_t n_i, const double x[],
                             const unsigned int vr_o[], size_t n_o, double y[], int status[],
                             size_t rows);

/* The model at `count` samples given in columns, without an importer's instance: the
 * values of the inputs and tunable parameters vr_x (sample i of column k at
 * x[k][i * x_step[k]]; a step of 0 holds one value for every sample; a variable left
 * out keeps its start value) and the Real outputs vr_y read into y[k][i * y_step[k]]
 * (an input or parameter among them reads as set), with that sample's status in
 * status[i] as fmu_evaluate_rows gives it: each sample's values are what a set of its
 * x and a get of its y give, bit for bit. A sample's outputs are computed only as far
 * as y needs (a model's fmu_later outputs where one is read), in the model's own
 * blocks without an instance. No column may overlap another. FMU_ERROR (nothing
 * written) for a model with states, a value reference that is not of these kinds, or a
 * missing array; FMU_FATAL for a token that is not the model's, or no memory. Not part of FMI:
 * exported as dyadfmu_evaluate_columns for dyadfmu.evaluate. */
fmu_status fmu_evaluate_columns(const fmu_model* model, const char* token, int time_at_vr_0,
                                const unsigned int vr_x[], size_t n_x, const double* const x[],
                                const ptrdiff_t x_step[], const unsigned int vr_y[], size_t n_y,
                                double* const y[], const ptrdiff_t y_step[], int status[],
                                size_t count);

/* Error with a logged "not supported" for an entry point this FMU does not offer. */
fmu_status fmu_unsupported(fmu_instance* instance, const char* function, const char* why);

/* ---- FMU state (fmu_state.c) ----------------------------------------------------------------
 * Get (into *state, a new one where *state is NULL), set, free (NULL is nothing), and
 * serialize to and from bytes that name their FMU; legal in every state. A state
 * belongs to the instance that made it and is freed with it at the latest. */
fmu_status fmu_get_state(fmu_instance* instance, fmu_saved** state, const char* function);
fmu_status fmu_set_state(fmu_instance* instance, const fmu_saved* state, const char* function);
fmu_status fmu_free_state(fmu_instance* instance, fmu_saved** state, const char* function);
void fmu_free_states(fmu_instance* instance);
fmu_status fmu_serialized_state_size(fmu_instance* instance, const fmu_saved* state, size_t* size,
                                     const char* function);
fmu_status fmu_serialize_state(fmu_instance* instance, const fmu_saved* state, unsigned char* bytes,
                               size_t size, const char* function);
fmu_status fmu_deserialize_state(fmu_instance* instance, const unsigned char* bytes, size_t size,
                                 fmu_saved** state, const char* function);

/* Where the value of a parameter, input or setting (variable `index`) is kept as set:
 * where the model reads it, or for an angle or a setting in `values`. */
double* fmu_kept_value(fmu_instance* instance, size_t index);

/* 0 if `value` may be stored in the parameter, input or setting v, whatever the
 * state: a Real finite and within its bounds, an Integer a whole number of its type
 * within its bounds, an Enumeration one of its items. Else 1, with why not (naming
 * v, "on_singular = nan is not an item of its enumeration: ...") in `why`. */
int fmu_value_refused(const fmu_variable* v, double value, char* why, size_t size);

/* After a state's values were stored (fmu_kept_value) and its model states written
 * into the input block: the state machine in `state`, and the outputs to be evaluated
 * again before they are read (every angle's unit vector converted again). */
void fmu_restored(fmu_instance* instance, fmu_state state);

#endif /* DYADFMU_FMU_INSTANCE_H */
