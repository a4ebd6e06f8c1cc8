/* dyadfmu FMU layer: the FMI 3.0 co-simulation API on top of fmu_instance.
 * Each entry point translates types and names, nothing more. The FMU has
 * Float64 and Int32 variables and Enumerations (through the Int64 getter and
 * setter) only; every other type's getters and setters reject any value reference. The entry points
 * it does not offer at all are in fmi3_unsupported.c. */
#include <stdio.h>
#include <stdlib.h>

#include "fmi3Functions.h"
#include "fmi3_shim.h"
#include "fmu_instance.h"

static void fmi3_sink(const fmu_logger* logger, fmu_status status, const char* category,
                      const char* message)
{
    const fmi3LogMessageCallback log = (fmi3LogMessageCallback)logger->callback;
    log(logger->environment, (fmi3Status)status, category, message);
}

static fmu_logger make_logger(fmi3String instance_name, fmi3InstanceEnvironment environment,
                              fmi3LogMessageCallback log_message)
{
    fmu_logger logger = {NULL, NULL, NULL, NULL};
    if (log_message != NULL) {
        logger.sink = fmi3_sink;
        logger.callback = (void (*)(void))log_message;
        logger.environment = environment;
    }
    logger.instance_name = instance_name;
    return logger;
}

static void refuse_interface(fmi3String instance_name, fmi3InstanceEnvironment environment,
                             fmi3LogMessageCallback log_message, const char* interface_name)
{
    fmu_logger logger = make_logger(instance_name, environment, log_message);
    if (logger.sink != NULL) {
        char message[160];
        snprintf(message, sizeof message, "this FMU supports co-simulation only, not %s",
                 interface_name);
        logger.sink(&logger, FMU_ERROR, "logStatusError", message);
    }
}

/* Every variable is a scalar: as many values as value references. */
static int scalar_counts(fmu_instance* instance, size_t n_value_references, size_t n_values,
                         const char* function)
{
    if (instance != NULL && n_values != n_value_references) {
        fmu_log(instance, FMU_ERROR,
                "%s: nValues = %zu but nValueReferences = %zu (all "
                "variables are scalars)",
                function, n_values, n_value_references);
        return 0;
    }
    return 1;
}

const char* fmi3GetVersion(void)
{
    return fmi3Version;
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    return to_fmi3(
        fmu_set_debug_logging((fmu_instance*)instance, loggingOn, nCategories, categories));
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    refuse_interface(instanceName, instanceEnvironment, logMessage, "model exchange");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate)
{
    fmu_logger logger = make_logger(instanceName, instanceEnvironment, logMessage);
    (void)resourcePath;
    (void)visible;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)intermediateUpdate;
    if (eventModeUsed) {
        if (logger.sink != NULL) {
            logger.sink(&logger, FMU_ERROR, "logStatusError",
                        "fmi3InstantiateCoSimulation: eventModeUsed is true, but this FMU has "
                        "no event mode (hasEventMode=\"false\")");
        }
        return NULL;
    }
    if (nRequiredIntermediateVariables > 0) {
        if (logger.sink != NULL) {
            logger.sink(&logger, FMU_ERROR, "logStatusError",
                        "fmi3InstantiateCoSimulation: this FMU provides no intermediate "
                        "variables");
        }
        return NULL;
    }
    return fmu_instantiate(&fmu_this_model, instanceName, instantiationToken, logger, loggingOn,
                           NULL, NULL, 1);
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lockPreemption, fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    refuse_interface(instanceName, instanceEnvironment, logMessage, "scheduled execution");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance)
{
    fmu_free((fmu_instance*)instance);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    const fmu_experiment experiment = {startTime, stopTimeDefined != fmi3False, stopTime};
    (void)toleranceDefined;
    (void)tolerance;
    return to_fmi3(fmu_enter_initialization((fmu_instance*)instance, &experiment));
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    return to_fmi3(fmu_exit_initialization((fmu_instance*)instance));
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    return to_fmi3(fmu_terminate((fmu_instance*)instance));
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    return to_fmi3(fmu_reset((fmu_instance*)instance));
}

fmi3Status fmi3GetFloat32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Float32 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetFloat32"));
}

/* The time at value reference 0 is served by the FMU layer (fmu_instantiate). */
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Float64 values[], size_t nValues)
{
    fmu_instance* fmu = (fmu_instance*)instance;
    if (!scalar_counts(fmu, nValueReferences, nValues, "fmi3GetFloat64")) {
        return fmi3Error;
    }
    return to_fmi3(fmu_get_real(fmu, valueReferences, nValueReferences, values, "fmi3GetFloat64"));
}

fmi3Status fmi3GetInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                       size_t nValueReferences, fmi3Int8 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetInt8"));
}

fmi3Status fmi3GetUInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3UInt8 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetUInt8"));
}

fmi3Status fmi3GetInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Int16 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetInt16"));
}

fmi3Status fmi3GetUInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, fmi3UInt16 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetUInt16"));
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Int32 values[], size_t nValues)
{
    if (!scalar_counts((fmu_instance*)instance, nValueReferences, nValues, "fmi3GetInt32")) {
        return fmi3Error;
    }
    return to_fmi3(fmu_get_integer((fmu_instance*)instance, valueReferences, nValueReferences,
                                   values, FMU_TYPE_BIT(FMU_INTEGER), "fmi3GetInt32"));
}

fmi3Status fmi3GetUInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, fmi3UInt32 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetUInt32"));
}

/* Enumerations (on_singular) are read and set as Int64. */
fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Int64 values[], size_t nValues)
{
    if (!scalar_counts((fmu_instance*)instance, nValueReferences, nValues, "fmi3GetInt64")) {
        return fmi3Error;
    }
    return to_fmi3(fmu_get_int64((fmu_instance*)instance, valueReferences, nValueReferences, values,
                                 "fmi3GetInt64"));
}

fmi3Status fmi3GetUInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, fmi3UInt64 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetUInt64"));
}

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Boolean values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetBoolean"));
}

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, fmi3String values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetString"));
}

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, size_t valueSizes[], fmi3Binary values[],
                         size_t nValues)
{
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetBinary"));
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Clock values[])
{
    (void)values;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_GET, valueReferences,
                                            nValueReferences, "fmi3GetClock"));
}

fmi3Status fmi3SetFloat32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Float32 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetFloat32"));
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Float64 values[], size_t nValues)
{
    fmu_instance* fmu = (fmu_instance*)instance;
    if (!scalar_counts(fmu, nValueReferences, nValues, "fmi3SetFloat64")) {
        return fmi3Error;
    }
    return to_fmi3(fmu_set_real(fmu, valueReferences, nValueReferences, values, "fmi3SetFloat64"));
}

fmi3Status fmi3SetInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                       size_t nValueReferences, const fmi3Int8 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetInt8"));
}

fmi3Status fmi3SetUInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3UInt8 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetUInt8"));
}

fmi3Status fmi3SetInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Int16 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetInt16"));
}

fmi3Status fmi3SetUInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const fmi3UInt16 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetUInt16"));
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Int32 values[], size_t nValues)
{
    if (!scalar_counts((fmu_instance*)instance, nValueReferences, nValues, "fmi3SetInt32")) {
        return fmi3Error;
    }
    return to_fmi3(fmu_set_integer((fmu_instance*)instance, valueReferences, nValueReferences,
                                   values, FMU_TYPE_BIT(FMU_INTEGER), "fmi3SetInt32"));
}

fmi3Status fmi3SetUInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const fmi3UInt32 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetUInt32"));
}

fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Int64 values[], size_t nValues)
{
    if (!scalar_counts((fmu_instance*)instance, nValueReferences, nValues, "fmi3SetInt64")) {
        return fmi3Error;
    }
    return to_fmi3(fmu_set_int64((fmu_instance*)instance, valueReferences, nValueReferences, values,
                                 "fmi3SetInt64"));
}

fmi3Status fmi3SetUInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const fmi3UInt64 values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetUInt64"));
}

fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Boolean values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetBoolean"));
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const fmi3String values[], size_t nValues)
{
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetString"));
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues)
{
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetBinary"));
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Clock values[])
{
    (void)values;
    return to_fmi3(fmu_no_variables_of_type((fmu_instance*)instance, FMU_OP_SET, valueReferences,
                                            nValueReferences, "fmi3SetClock"));
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                        size_t nUnknowns, const fmi3ValueReference knowns[],
                                        size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity)
{
    fmu_instance* fmu = (fmu_instance*)instance;
    if (fmu != NULL && (nSeed != nKnowns || nSensitivity != nUnknowns)) {
        fmu_log(fmu, FMU_ERROR,
                "fmi3GetDirectionalDerivative: nSeed = %zu and nSensitivity = "
                "%zu must equal nKnowns = %zu and nUnknowns = %zu (all variables are scalars)",
                nSeed, nSensitivity, nKnowns, nUnknowns);
        return fmi3Error;
    }
    return to_fmi3(fmu_directional_derivative(fmu, unknowns, nUnknowns, knowns, nKnowns, seed,
                                              sensitivity, "fmi3GetDirectionalDerivative"));
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[],
                                    fmi3Float64 values[], size_t nValues)
{
    fmu_instance* fmu = (fmu_instance*)instance;
    if (!scalar_counts(fmu, nValueReferences, nValues, "fmi3GetOutputDerivatives")) {
        return fmi3Error;
    }
    return to_fmi3(fmu_get_output_rates(fmu, valueReferences, nValueReferences, orders, values,
                                        "fmi3GetOutputDerivatives"));
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation,
                      fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime)
{
    fmu_instance* fmu = (fmu_instance*)instance;
    fmu_status status;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (fmu != NULL && (eventHandlingNeeded == NULL || terminateSimulation == NULL ||
                        earlyReturn == NULL || lastSuccessfulTime == NULL)) {
        fmu_log(fmu, FMU_ERROR, "fmi3DoStep: an output argument is NULL");
        return fmi3Error;
    }
    if (fmu != NULL) {
        /* before the step: fewer pointers kept across the call */
        *eventHandlingNeeded = fmi3False;
        *earlyReturn = fmi3False;
    }
    status = fmu_do_step(fmu, currentCommunicationPoint, communicationStepSize, "fmi3DoStep");
    if (fmu != NULL) {
        *terminateSimulation = fmu->terminate_requested ? fmi3True : fmi3False;
        *lastSuccessfulTime = fmu->last_successful_time;
    }
    return to_fmi3(status);
}

/* FMU state: fmu_state.c. fmi3FMUState is the layer's fmu_saved. */
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState* FMUState)
{
    fmu_saved* saved = FMUState != NULL ? (fmu_saved*)*FMUState : NULL;
    fmu_status status =
        fmu_get_state((fmu_instance*)instance, FMUState != NULL ? &saved : NULL, "fmi3GetFMUState");
    if (FMUState != NULL) {
        *FMUState = saved;
    }
    return to_fmi3(status);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    return to_fmi3(
        fmu_set_state((fmu_instance*)instance, (const fmu_saved*)FMUState, "fmi3SetFMUState"));
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState* FMUState)
{
    fmu_saved* saved = FMUState != NULL ? (fmu_saved*)*FMUState : NULL;
    fmu_status status = fmu_free_state((fmu_instance*)instance, FMUState != NULL ? &saved : NULL,
                                       "fmi3FreeFMUState");
    if (FMUState != NULL) {
        *FMUState = saved;
    }
    return to_fmi3(status);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t* size)
{
    return to_fmi3(fmu_serialized_state_size((fmu_instance*)instance, (const fmu_saved*)FMUState,
                                             size, "fmi3SerializedFMUStateSize"));
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState,
                                 fmi3Byte serializedState[], size_t size)
{
    return to_fmi3(fmu_serialize_state((fmu_instance*)instance, (const fmu_saved*)FMUState,
                                       (unsigned char*)serializedState, size,
                                       "fmi3SerializeFMUState"));
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[],
                                   size_t size, fmi3FMUState* FMUState)
{
    fmu_saved* saved = NULL;
    fmu_status status =
        fmu_deserialize_state((fmu_instance*)instance, (const unsigned char*)serializedState, size,
                              FMUState != NULL ? &saved : NULL, "fmi3DeserializeFMUState");
    if (status == FMU_OK) {
        *FMUState = saved;
    }
    return to_fmi3(status);
}

/* Not FMI: the model over many rows in one call, without an importer's instance
 * (fmu_evaluate_rows), for dyadfmu's design studies. Returns the fmu_status. */
FMI3_Export int dyadfmu_evaluate_rows(const char* token, const unsigned int vr_p[], size_t n_p,
                                      const double p[], const unsigned int vr_i[], size_t n_i,
                                      const double x[], const unsigned int vr_o[], size_t n_o,
                                      double y[], int status[], size_t rows);
FMI3_Export int dyadfmu_evaluate_rows(const char* token, const unsigned int vr_p[], size_t n_p,
                                      const double p[], const unsigned int vr_i[], size_t n_i,
                                      const double x[], const unsigned int vr_o[], size_t n_o,
                                      double y[], int status[], size_t rows)
{
    return (int)fmu_evaluate_rows(&fmu_this_model, token, 1, vr_p, n_p, p, vr_i, n_i, x, vr_o, n_o,
                                  y, status, rows);
}

/* Not FMI: the model at many samples in columns in one call, without an importer's
 * instance (fmu_evaluate_columns), for dyadfmu.evaluate. Returns the fmu_status. */
FMI3_Export int dyadfmu_evaluate_columns(const char* token, const unsigned int vr_x[], size_t n_x,
                                         const double* const x[], const ptrdiff_t x_step[],
                                         const unsigned int vr_y[], size_t n_y, double* const y[],
                                         const ptrdiff_t y_step[], int status[], size_t count);
FMI3_Export int dyadfmu_evaluate_columns(const char* token, const unsigned int vr_x[], size_t n_x,
                                         const double* const x[], const ptrdiff_t x_step[],
                                         const unsigned int vr_y[], size_t n_y, double* const y[],
                                         const ptrdiff_t y_step[], int status[], size_t count)
{
    return (int)fmu_evaluate_columns(&fmu_this_model, token, 1, vr_x, n_x, x, x_step, vr_y, n_y, y,
                                     y_step, status, count);
}
