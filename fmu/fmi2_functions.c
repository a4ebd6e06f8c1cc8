/* dyadfmu FMU layer: the FMI 2.0 co-simulation API on top of fmu_instance.
 * Each entry point translates types and names, nothing more. */
#include <stdlib.h>

#include "fmi2Functions.h"
#include "fmu_instance.h"

/* fmi2Integer carries Integer and Enumeration variables. */
#define INTEGER_TYPES (FMU_TYPE_BIT(FMU_INTEGER) | FMU_TYPE_BIT(FMU_ENUMERATION))

static fmi2Status to_fmi2(fmu_status status)
{
    return (fmi2Status)status;
}

/* The FMI 2 logger takes a format: the message goes through "%s" so that a
 * '%' in a name or value is never interpreted again. */
static void fmi2_sink(const fmu_logger* logger, fmu_status status, const char* category,
                      const char* message)
{
    const fmi2CallbackLogger log = (fmi2CallbackLogger)logger->callback;
    log(logger->environment, logger->instance_name, (fmi2Status)status, category, "%s", message);
}

const char* fmi2GetTypesPlatform(void)
{
    return fmi2TypesPlatform;
}

const char* fmi2GetVersion(void)
{
    return fmi2Version;
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    return to_fmi2(fmu_set_debug_logging((fmu_instance*)c, loggingOn, nCategories, categories));
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions* functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn)
{
    fmu_logger logger = {NULL, NULL, NULL, NULL};
    (void)fmuResourceLocation;
    (void)visible;
    if (functions == NULL) {
        return NULL;
    }
    if (functions->logger != NULL) {
        logger.sink = fmi2_sink;
        logger.callback = (void (*)(void))functions->logger;
        logger.environment = functions->componentEnvironment;
    }
    logger.instance_name = instanceName;
    if (fmuType != fmi2CoSimulation) {
        if (logger.sink != NULL) {
            logger.sink(&logger, FMU_ERROR, "logStatusError",
                        "fmi2Instantiate: this FMU supports co-simulation only");
        }
        return NULL;
    }
    return fmu_instantiate(&fmu_this_model, instanceName, fmuGUID, logger, loggingOn,
                           functions->allocateMemory, functions->freeMemory, 0);
}

void fmi2FreeInstance(fmi2Component c)
{
    fmu_free((fmu_instance*)c);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    const fmu_experiment experiment = {startTime, stopTimeDefined != fmi2False, stopTime};
    (void)toleranceDefined;
    (void)tolerance;
    return to_fmi2(fmu_setup_experiment((fmu_instance*)c, &experiment));
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    return to_fmi2(fmu_enter_initialization((fmu_instance*)c, NULL));
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    return to_fmi2(fmu_exit_initialization((fmu_instance*)c));
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    return to_fmi2(fmu_terminate((fmu_instance*)c));
}

fmi2Status fmi2Reset(fmi2Component c)
{
    return to_fmi2(fmu_reset((fmu_instance*)c));
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    return to_fmi2(fmu_get_real((fmu_instance*)c, vr, nvr, value, "fmi2GetReal"));
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[])
{
    return to_fmi2(
        fmu_get_integer((fmu_instance*)c, vr, nvr, value, INTEGER_TYPES, "fmi2GetInteger"));
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[])
{
    (void)value;
    return to_fmi2(
        fmu_no_variables_of_type((fmu_instance*)c, FMU_OP_GET, vr, nvr, "fmi2GetBoolean"));
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[])
{
    (void)value;
    return to_fmi2(
        fmu_no_variables_of_type((fmu_instance*)c, FMU_OP_GET, vr, nvr, "fmi2GetString"));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[])
{
    return to_fmi2(fmu_set_real((fmu_instance*)c, vr, nvr, value, "fmi2SetReal"));
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[])
{
    return to_fmi2(
        fmu_set_integer((fmu_instance*)c, vr, nvr, value, INTEGER_TYPES, "fmi2SetInteger"));
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[])
{
    (void)value;
    return to_fmi2(
        fmu_no_variables_of_type((fmu_instance*)c, FMU_OP_SET, vr, nvr, "fmi2SetBoolean"));
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[])
{
    (void)value;
    return to_fmi2(
        fmu_no_variables_of_type((fmu_instance*)c, FMU_OP_SET, vr, nvr, "fmi2SetString"));
}

/* FMU state: fmu_state.c. fmi2FMUstate is the layer's fmu_saved. */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* FMUstate)
{
    fmu_saved* saved = FMUstate != NULL ? (fmu_saved*)*FMUstate : NULL;
    fmu_status status =
        fmu_get_state((fmu_instance*)c, FMUstate != NULL ? &saved : NULL, "fmi2GetFMUstate");
    if (FMUstate != NULL) {
        *FMUstate = saved;
    }
    return to_fmi2(status);
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    return to_fmi2(fmu_set_state((fmu_instance*)c, (const fmu_saved*)FMUstate, "fmi2SetFMUstate"));
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* FMUstate)
{
    fmu_saved* saved = FMUstate != NULL ? (fmu_saved*)*FMUstate : NULL;
    fmu_status status =
        fmu_free_state((fmu_instance*)c, FMUstate != NULL ? &saved : NULL, "fmi2FreeFMUstate");
    if (FMUstate != NULL) {
        *FMUstate = saved;
    }
    return to_fmi2(status);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t* size)
{
    return to_fmi2(fmu_serialized_state_size((fmu_instance*)c, (const fmu_saved*)FMUstate, size,
                                             "fmi2SerializedFMUstateSize"));
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serialized[],
                                 size_t size)
{
    return to_fmi2(fmu_serialize_state((fmu_instance*)c, (const fmu_saved*)FMUstate,
                                       (unsigned char*)serialized, size, "fmi2SerializeFMUstate"));
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate* FMUstate)
{
    fmu_saved* saved = NULL;
    fmu_status status =
        fmu_deserialize_state((fmu_instance*)c, (const unsigned char*)serializedState, size,
                              FMUstate != NULL ? &saved : NULL, "fmi2DeSerializeFMUstate");
    if (status == FMU_OK) {
        *FMUstate = saved;
    }
    return to_fmi2(status);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    return to_fmi2(fmu_directional_derivative((fmu_instance*)c, vUnknown_ref, nUnknown, vKnown_ref,
                                              nKnown, dvKnown, dvUnknown,
                                              "fmi2GetDirectionalDerivative"));
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    return to_fmi2(fmu_set_input_rates((fmu_instance*)c, vr, nvr, order, value,
                                       "fmi2SetRealInputDerivatives"));
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    return to_fmi2(fmu_get_output_rates((fmu_instance*)c, vr, nvr, order, value,
                                        "fmi2GetRealOutputDerivatives"));
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    return to_fmi2(fmu_do_step((fmu_instance*)c, currentCommunicationPoint, communicationStepSize,
                               "fmi2DoStep"));
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    return to_fmi2(fmu_unsupported((fmu_instance*)c, "fmi2CancelStep",
                                   "fmi2DoStep never returns fmi2Pending"));
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status* value)
{
    (void)s;
    (void)value;
    return to_fmi2(
        fmu_unsupported((fmu_instance*)c, "fmi2GetStatus", "fmi2DoStep never returns fmi2Pending"));
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value)
{
    fmu_instance* instance = (fmu_instance*)c;
    fmu_status status = fmu_check_call(instance, FMU_OP_STEP_STATUS, "fmi2GetRealStatus");
    if (status != FMU_OK) {
        return to_fmi2(status);
    }
    if (s != fmi2LastSuccessfulTime || value == NULL) {
        return to_fmi2(fmu_unsupported(instance, "fmi2GetRealStatus",
                                       "only fmi2LastSuccessfulTime is a Real status"));
    }
    *value = instance->last_successful_time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer* value)
{
    (void)s;
    (void)value;
    return to_fmi2(
        fmu_unsupported((fmu_instance*)c, "fmi2GetIntegerStatus", "there is no Integer status"));
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value)
{
    fmu_instance* instance = (fmu_instance*)c;
    fmu_status status = fmu_check_call(instance, FMU_OP_STEP_STATUS, "fmi2GetBooleanStatus");
    if (status != FMU_OK) {
        return to_fmi2(status);
    }
    if (s != fmi2Terminated || value == NULL) {
        return to_fmi2(fmu_unsupported(instance, "fmi2GetBooleanStatus",
                                       "only fmi2Terminated is a Boolean status"));
    }
    *value = instance->terminate_requested ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String* value)
{
    (void)s;
    (void)value;
    return to_fmi2(
        fmu_unsupported((fmu_instance*)c, "fmi2GetStringStatus", "there is no String status"));
}

/* Not FMI: the model over many rows in one call, without an importer's instance
 * (fmu_evaluate_rows), for dyadfmu's design studies. Returns the fmu_status. */
FMI2_Export int dyadfmu_evaluate_rows(const char* token, const unsigned int vr_p[], size_t n_p,
                                      const double p[], const unsigned int vr_i[], size_t n_i,
                                      const double x[], const unsigned int vr_o[], size_t n_o,
                                      double y[], int status[], size_t rows);
FMI2_Export int dyadfmu_evaluate_rows(const char* token, const unsigned int vr_p[], size_t n_p,
                                      const double p[], const unsigned int vr_i[], size_t n_i,
                                      const double x[], const unsigned int vr_o[], size_t n_o,
                                      double y[], int status[], size_t rows)
{
    return (int)fmu_evaluate_rows(&fmu_this_model, token, 0, vr_p, n_p, p, vr_i, n_i, x, vr_o, n_o,
                                  y, status, rows);
}

/* Not FMI: the model at many samples in columns in one call, without an importer's
 * instance (fmu_evaluate_columns), for dyadfmu.evaluate. Returns the fmu_status. */
FMI2_Export int dyadfmu_evaluate_columns(const char* token, const unsigned int vr_x[], size_t n_x,
                                         const double* const x[], const ptrdiff_t x_step[],
                                         const unsigned int vr_y[], size_t n_y, double* const y[],
                                         const ptrdiff_t y_step[], int status[], size_t count);
FMI2_Export int dyadfmu_evaluate_columns(const char* token, const unsigned int vr_x[], size_t n_x,
                                         const double* const x[], const ptrdiff_t x_step[],
                                         const unsigned int vr_y[], size_t n_y, double* const y[],
                                         const ptrdiff_t y_step[], int status[], size_t count)
{
    return (int)fmu_evaluate_columns(&fmu_this_model, token, 0, vr_x, n_x, x, x_step, vr_y, n_y, y,
                                     y_step, status, count);
}
