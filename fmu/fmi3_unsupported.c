/* dyadfmu FMU layer: the FMI 3.0 entry points this co-simulation FMU does not
 * offer. Each one exists because an importer may look every symbol up; each
 * logs which capability flag or missing interface rules it out and returns
 * Error, changing nothing (fmu_unsupported). */
#include "fmi3Functions.h"
#include "fmi3_shim.h"
#include "fmu_instance.h"

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    return to_fmi3(
        fmu_unsupported((fmu_instance*)instance, "fmi3EnterEventMode", "hasEventMode is false"));
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance,
                                               fmi3ValueReference valueReference,
                                               size_t* nDependencies)
{
    (void)valueReference;
    (void)nDependencies;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetNumberOfVariableDependencies",
                                   "the dependencies are declared in modelDescription.xml"));
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[], size_t nDependencies)
{
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetVariableDependencies",
                                   "the dependencies are declared in modelDescription.xml"));
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[],
                                    size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetAdjointDerivative",
                                   "providesAdjointDerivatives is false"));
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3EnterConfigurationMode",
                                   "the FMU has no structural parameters"));
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3ExitConfigurationMode",
                                   "the FMU has no structural parameters"));
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)intervals;
    (void)qualifiers;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetIntervalDecimal",
                                   "the FMU has no clocks"));
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance,
                                   const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)counters;
    (void)resolutions;
    (void)qualifiers;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetIntervalFraction",
                                   "the FMU has no clocks"));
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)shifts;
    return to_fmi3(
        fmu_unsupported((fmu_instance*)instance, "fmi3GetShiftDecimal", "the FMU has no clocks"));
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)counters;
    (void)resolutions;
    return to_fmi3(
        fmu_unsupported((fmu_instance*)instance, "fmi3GetShiftFraction", "the FMU has no clocks"));
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)intervals;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3SetIntervalDecimal",
                                   "the FMU has no clocks"));
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance,
                                   const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)counters;
    (void)resolutions;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3SetIntervalFraction",
                                   "the FMU has no clocks"));
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)shifts;
    return to_fmi3(
        fmu_unsupported((fmu_instance*)instance, "fmi3SetShiftDecimal", "the FMU has no clocks"));
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[],
                                const fmi3UInt64 resolutions[])
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)counters;
    (void)resolutions;
    return to_fmi3(
        fmu_unsupported((fmu_instance*)instance, "fmi3SetShiftFraction", "the FMU has no clocks"));
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3EvaluateDiscreteStates",
                                   "hasEventMode is false"));
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean* discreteStatesNeedUpdate,
                                    fmi3Boolean* terminateSimulation,
                                    fmi3Boolean* nominalsOfContinuousStatesChanged,
                                    fmi3Boolean* valuesOfContinuousStatesChanged,
                                    fmi3Boolean* nextEventTimeDefined, fmi3Float64* nextEventTime)
{
    (void)discreteStatesNeedUpdate;
    (void)terminateSimulation;
    (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged;
    (void)nextEventTimeDefined;
    (void)nextEventTime;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3UpdateDiscreteStates",
                                   "hasEventMode is false"));
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3EnterContinuousTimeMode",
                                   "model exchange is not supported"));
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance,
                                       fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean* enterEventMode,
                                       fmi3Boolean* terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    (void)enterEventMode;
    (void)terminateSimulation;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3CompletedIntegratorStep",
                                   "model exchange is not supported"));
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    (void)time;
    return to_fmi3(
        fmu_unsupported((fmu_instance*)instance, "fmi3SetTime", "model exchange is not supported"));
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    (void)continuousStates;
    (void)nContinuousStates;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3SetContinuousStates",
                                   "model exchange is not supported"));
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    (void)derivatives;
    (void)nContinuousStates;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetContinuousStateDerivatives",
                                   "model exchange is not supported"));
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[],
                                  size_t nEventIndicators)
{
    (void)eventIndicators;
    (void)nEventIndicators;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetEventIndicators",
                                   "model exchange is not supported"));
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    (void)continuousStates;
    (void)nContinuousStates;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetContinuousStates",
                                   "model exchange is not supported"));
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                             size_t nContinuousStates)
{
    (void)nominals;
    (void)nContinuousStates;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetNominalsOfContinuousStates",
                                   "model exchange is not supported"));
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t* nEventIndicators)
{
    (void)nEventIndicators;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetNumberOfEventIndicators",
                                   "model exchange is not supported"));
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t* nContinuousStates)
{
    (void)nContinuousStates;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3GetNumberOfContinuousStates",
                                   "model exchange is not supported"));
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    return to_fmi3(
        fmu_unsupported((fmu_instance*)instance, "fmi3EnterStepMode", "hasEventMode is false"));
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference;
    (void)activationTime;
    return to_fmi3(fmu_unsupported((fmu_instance*)instance, "fmi3ActivateModelPartition",
                                   "scheduled execution is not supported"));
}
