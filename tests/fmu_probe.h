/* dyadfmu: what the C probes of the FMU binaries share (tests/fmu_api_tests.c,
 * tests/fmu_fuzz.c, tests/fmu_threads.c). A probe sees an FMU as an importer
 * does: an extracted FMU directory, its modelDescription.xml read here (a
 * minimal parser, enough for the elements FMI 2 and FMI 3 use for variables),
 * and its binary loaded with dlopen, every FMI entry point resolved by name.
 * Also: a logger that keeps what the FMU said, a seeded PRNG whose seed
 * replays a run, and a 64-bit hash for comparing runs bit for bit. */
#ifndef DYADFMU_FMU_PROBE_H
#define DYADFMU_FMU_PROBE_H

#include <stddef.h>
#include <stdint.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"

/* Format checking of printf-style helpers; MinGW builds use its C99 stdio
 * (__USE_MINGW_ANSI_STDIO), whose formats are GNU's. */
#if defined(__MINGW32__)
#define PROBE_PRINTF_FORMAT(fmt, first) __attribute__((format(gnu_printf, fmt, first)))
#elif defined(__GNUC__)
#define PROBE_PRINTF_FORMAT(fmt, first) __attribute__((format(printf, fmt, first)))
#else
#define PROBE_PRINTF_FORMAT(fmt, first)
#endif

/* ---- the model description ------------------------------------------------ */

typedef enum probe_causality {
    PROBE_PARAMETER = 0,
    PROBE_CALCULATED_PARAMETER,
    PROBE_STRUCTURAL_PARAMETER,
    PROBE_INPUT,
    PROBE_OUTPUT,
    PROBE_LOCAL,
    PROBE_INDEPENDENT
} probe_causality;

typedef enum probe_variability {
    PROBE_CONSTANT = 0,
    PROBE_FIXED,
    PROBE_TUNABLE,
    PROBE_DISCRETE,
    PROBE_CONTINUOUS
} probe_variability;

/* The types the FMUs of dyadfmu use; every other type is PROBE_OTHER. */
typedef enum probe_type {
    PROBE_REAL = 0,    /* fmi2Real, fmi3Float64 */
    PROBE_INTEGER,     /* fmi2Integer, fmi3Int32 */
    PROBE_ENUMERATION, /* through fmi2Integer, fmi3Int64 */
    PROBE_OTHER
} probe_type;

typedef struct probe_variable {
    char* name;
    unsigned vr;
    probe_causality causality;
    probe_variability variability;
    probe_type type;
    int is_array; /* an FMI 3 variable with <Dimension> */
    int has_start, has_min, has_max;
    double start, min, max; /* as declared (min and max are inclusive in FMI) */
} probe_variable;

typedef struct probe_model {
    int fmi_version;  /* 2 or 3 */
    char* identifier; /* modelIdentifier of <CoSimulation> */
    char* token;      /* guid (FMI 2) or instantiationToken (FMI 3) */
    int provides_directional_derivatives;
    int interpolates; /* maxOutputDerivativeOrder >= 1 (FMI 2: and canInterpolateInputs) */
    probe_variable* variables;
    size_t variable_count;
    char* directory;   /* the extracted FMU */
    char* binary_path; /* binaries/<platform>/<identifier>.so, or .dll on Windows */
} probe_model;

/* Reads DIR/modelDescription.xml. Returns 1, or 0 with the reason in `error`. */
int probe_read_model(const char* directory, probe_model* model, char* error, size_t error_size);
void probe_free_model(probe_model* model);
/* The variable of that name, or NULL. */
const probe_variable* probe_variable_named(const probe_model* model, const char* name);
/* The variable with that value reference, or NULL. */
const probe_variable* probe_variable_of_vr(const probe_model* model, unsigned vr);
/* Whether an importer may set v in each state, by the standard's rules. */
int probe_settable_before_initialization(const probe_variable* v); /* Instantiated, Init */
int probe_settable_in_step_mode(const probe_variable* v);
/* A value reference that no variable of the model has. */
unsigned probe_unused_vr(const probe_model* model);
/* The parameter that starts the state output v (a plant's `X_start` for its output X,
 * the drive's start.angle and start.speed), or NULL if v is not a state. */
const probe_variable* probe_state_start(const probe_model* model, const probe_variable* v);
/* Whether the model has states: a step carries them from where the last one ended. */
int probe_has_states(const probe_model* model);

/* ---- the entry points --------------------------------------------------------- */

/* The entry points, packed: one X each. */
/* clang-format off */
#define PROBE_FMI2_FUNCTIONS(X)                                                               \
    X(GetTypesPlatform) X(GetVersion) X(SetDebugLogging) X(Instantiate) X(FreeInstance)       \
    X(SetupExperiment) X(EnterInitializationMode) X(ExitInitializationMode) X(Terminate)      \
    X(Reset) X(GetReal) X(GetInteger) X(GetBoolean) X(GetString) X(SetReal) X(SetInteger)    \
    X(SetBoolean) X(SetString) X(GetFMUstate) X(SetFMUstate) X(FreeFMUstate)                 \
    X(SerializedFMUstateSize) X(SerializeFMUstate) X(DeSerializeFMUstate)                   \
    X(GetDirectionalDerivative) X(SetRealInputDerivatives) X(GetRealOutputDerivatives)      \
    X(DoStep) X(CancelStep) X(GetStatus) X(GetRealStatus) X(GetIntegerStatus)                \
    X(GetBooleanStatus) X(GetStringStatus)

#define PROBE_FMI3_FUNCTIONS(X)                                                               \
    X(GetVersion) X(SetDebugLogging) X(InstantiateModelExchange) X(InstantiateCoSimulation)  \
    X(InstantiateScheduledExecution) X(FreeInstance) X(EnterInitializationMode)             \
    X(ExitInitializationMode) X(EnterEventMode) X(Terminate) X(Reset) X(GetFloat32)          \
    X(GetFloat64) X(GetInt8) X(GetUInt8) X(GetInt16) X(GetUInt16) X(GetInt32) X(GetUInt32)   \
    X(GetInt64) X(GetUInt64) X(GetBoolean) X(GetString) X(GetBinary) X(GetClock)            \
    X(SetFloat32) X(SetFloat64) X(SetInt8) X(SetUInt8) X(SetInt16) X(SetUInt16) X(SetInt32)  \
    X(SetUInt32) X(SetInt64) X(SetUInt64) X(SetBoolean) X(SetString) X(SetBinary)            \
    X(SetClock) X(GetNumberOfVariableDependencies) X(GetVariableDependencies)               \
    X(GetFMUState) X(SetFMUState) X(FreeFMUState) X(SerializedFMUStateSize)                  \
    X(SerializeFMUState) X(DeserializeFMUState) X(GetDirectionalDerivative)                 \
    X(GetAdjointDerivative) X(EnterConfigurationMode) X(ExitConfigurationMode)              \
    X(GetIntervalDecimal) X(GetIntervalFraction) X(GetShiftDecimal) X(GetShiftFraction)     \
    X(SetIntervalDecimal) X(SetIntervalFraction) X(SetShiftDecimal) X(SetShiftFraction)     \
    X(EvaluateDiscreteStates) X(UpdateDiscreteStates) X(EnterContinuousTimeMode)            \
    X(CompletedIntegratorStep) X(SetTime) X(SetContinuousStates)                            \
    X(GetContinuousStateDerivatives) X(GetEventIndicators) X(GetContinuousStates)           \
    X(GetNominalsOfContinuousStates) X(GetNumberOfEventIndicators)                          \
    X(GetNumberOfContinuousStates) X(EnterStepMode) X(GetOutputDerivatives) X(DoStep)       \
    X(ActivateModelPartition)
/* clang-format on */

#define PROBE_FMI2_MEMBER(name) fmi2##name##TYPE* name;
#define PROBE_FMI3_MEMBER(name) fmi3##name##TYPE* name;

typedef struct probe_fmi2 {
    void* library;
    PROBE_FMI2_FUNCTIONS(PROBE_FMI2_MEMBER)
} probe_fmi2;

typedef struct probe_fmi3 {
    void* library;
    PROBE_FMI3_FUNCTIONS(PROBE_FMI3_MEMBER)
} probe_fmi3;

/* dlopen the model's binary and resolve every entry point of its FMI version.
 * Returns 1, or 0 with the reason (a missing symbol is named) in `error`. */
int probe_load_fmi2(const probe_model* model, probe_fmi2* api, char* error, size_t error_size);
int probe_load_fmi3(const probe_model* model, probe_fmi3* api, char* error, size_t error_size);
void probe_unload(void* library);
/* The loaded library's function `name` into *function_pointer: 1, or 0 with the reason in
 * `error`. */
int probe_resolve(void* library, const char* name, void* function_pointer, char* error,
                  size_t error_size);

/* ---- the importer's logger ------------------------------------------------------ */

/* What an instance logged; one book per instance, so loggers of instances in
 * different threads share nothing. */
typedef struct probe_log_book {
    long count;
    int last_status;
    char last[600];
    uint64_t hash; /* of every status and message, for comparing runs */
} probe_log_book;

void probe_log_book_clear(probe_log_book* book);
void probe_fmi2_logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                       fmi2Status status, fmi2String category, fmi2String message, ...);
void probe_fmi3_logger(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                       fmi3String message);
/* Callbacks for fmi2Instantiate that log into `book`. */
fmi2CallbackFunctions probe_fmi2_callbacks(probe_log_book* book);

/* ---- seeded random numbers and hashing --------------------------------------------- */

/* xoshiro256** seeded through splitmix64: the same seed gives the same
 * sequence on every machine. */
typedef struct probe_rng {
    uint64_t s[4];
} probe_rng;

uint64_t probe_splitmix64(uint64_t* state);
void probe_rng_seed(probe_rng* rng, uint64_t seed);
uint64_t probe_rng_next(probe_rng* rng);
/* Uniform in [0, 1). */
double probe_rng_uniform(probe_rng* rng);
/* Uniform integer in [0, n), n > 0. */
uint64_t probe_rng_below(probe_rng* rng, uint64_t n);

#define PROBE_HASH_START 0xcbf29ce484222325ULL
/* Folds v into h (FNV-1a over its 8 bytes). */
uint64_t probe_hash_u64(uint64_t h, uint64_t v);
/* Folds the bit pattern of x into h: -0 and 0, and NaN payloads, differ. */
uint64_t probe_hash_double(uint64_t h, double x);
uint64_t probe_hash_string(uint64_t h, const char* s);
uint64_t probe_bits(double x);

#endif /* DYADFMU_FMU_PROBE_H */
