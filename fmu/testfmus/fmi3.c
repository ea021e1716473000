/* Test FMUs (issue 22): the FMI 3.0 co-simulation API over instance.c. Linked with one model
 * (lti_plant.c or dc_motor.c) into binaries/x86_64-linux/<model>.so. Float64 variables only;
 * the other typed accessors accept empty requests and refuse others. Model exchange,
 * scheduled execution, event mode, clocks, FMU state, derivatives, dependencies and
 * configuration mode are not supported: all of those functions are exported (the standard
 * requires it; FMPy loads them all) and return fmi3Error. Every entry point checks its
 * instance pointer. */
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "instance.h"
#include "model.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Glue;

static void log_error(const Instance *inst, const char *message) {
    const Glue *g = inst->glue;
    if (g && g->log) g->log(g->env, fmi3Error, "logStatusError", message);
}

static fmi3Status status(int rc) { return rc ? fmi3Error : fmi3OK; }

#define INSTANCE(i) Instance *inst = (Instance *)(i); if (!inst) return fmi3Error

static fmi3Status unsupported(fmi3Instance i, const char *what) {
    INSTANCE(i);
    return status(instance_fail(inst, "%s is not supported", what));
}

static void refuse_instantiation(fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
                                 const char *why) {
    if (log) log(env, fmi3Error, "logStatusError", why);
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    (void)loggingOn; (void)nCategories; (void)categories;
    INSTANCE(i);
    return fmi3OK;  /* errors are always logged; there is nothing else to log */
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String token,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn, fmi3InstanceEnvironment env,
                                          fmi3LogMessageCallback logMessage) {
    (void)instanceName; (void)token; (void)resourcePath; (void)visible; (void)loggingOn;
    refuse_instantiation(env, logMessage, "model exchange is not supported");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String token, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath; (void)visible; (void)loggingOn; (void)eventModeUsed;
    (void)earlyReturnAllowed; (void)requiredIntermediateVariables; (void)intermediateUpdate;
    if (!token || strcmp(token, MODEL_TOKEN) != 0) {
        refuse_instantiation(env, logMessage, "the instantiationToken does not match");
        return NULL;
    }
    if (nRequiredIntermediateVariables > 0) {
        refuse_instantiation(env, logMessage, "intermediate variables are not supported");
        return NULL;
    }
    Glue *g = malloc(sizeof *g);
    Instance *inst = g ? instance_new(instanceName, log_error, g) : NULL;
    if (!inst) {
        free(g);
        refuse_instantiation(env, logMessage, "out of memory");
        return NULL;
    }
    g->env = env;
    g->log = logMessage;
    return inst;
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String token, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage,
    fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lockPreemption,
    fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName; (void)token; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    refuse_instantiation(env, logMessage, "scheduled execution is not supported");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance i) {
    Instance *inst = i;
    if (!inst) return;
    free(inst->glue);
    instance_free(inst);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance i, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    INSTANCE(i);
    return status(instance_enter_initialization(inst, startTime));
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance i) {
    INSTANCE(i);
    return status(instance_exit_initialization(inst));
}

fmi3Status fmi3Terminate(fmi3Instance i) {
    INSTANCE(i);
    return status(instance_terminate(inst));
}

fmi3Status fmi3Reset(fmi3Instance i) {
    INSTANCE(i);
    instance_reset(inst);
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Float64 values[], size_t nValues) {
    INSTANCE(i);
    if (nValues != nvr) return status(instance_fail(inst, "fmi3GetFloat64: nValues != nvr"));
    return status(instance_get(inst, vr, nvr, values));
}

fmi3Status fmi3SetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Float64 values[], size_t nValues) {
    INSTANCE(i);
    if (nValues != nvr) return status(instance_fail(inst, "fmi3SetFloat64: nValues != nvr"));
    return status(instance_set(inst, vr, nvr, values));
}

/* No variables of the other types: an empty request is fine, any other an error. */
#define NO_VARIABLES(T)                                                                      \
    fmi3Status fmi3Get##T(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,        \
                          fmi3##T values[], size_t nValues) {                               \
        (void)vr; (void)values; (void)nValues;                                              \
        return nvr == 0 ? (i ? fmi3OK : fmi3Error) : unsupported(i, "fmi3Get" #T);          \
    }                                                                                       \
    fmi3Status fmi3Set##T(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,        \
                          const fmi3##T values[], size_t nValues) {                         \
        (void)vr; (void)values; (void)nValues;                                              \
        return nvr == 0 ? (i ? fmi3OK : fmi3Error) : unsupported(i, "fmi3Set" #T);          \
    }
NO_VARIABLES(Float32)
NO_VARIABLES(Int8)
NO_VARIABLES(UInt8)
NO_VARIABLES(Int16)
NO_VARIABLES(UInt16)
NO_VARIABLES(Int32)
NO_VARIABLES(UInt32)
NO_VARIABLES(Int64)
NO_VARIABLES(UInt64)
NO_VARIABLES(Boolean)
NO_VARIABLES(String)

fmi3Status fmi3GetBinary(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)vr; (void)valueSizes; (void)values; (void)nValues;
    return nvr == 0 ? (i ? fmi3OK : fmi3Error) : unsupported(i, "fmi3GetBinary");
}
fmi3Status fmi3SetBinary(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    (void)vr; (void)valueSizes; (void)values; (void)nValues;
    return nvr == 0 ? (i ? fmi3OK : fmi3Error) : unsupported(i, "fmi3SetBinary");
}
fmi3Status fmi3GetClock(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                        fmi3Clock values[]) {
    (void)vr; (void)values;
    return nvr == 0 ? (i ? fmi3OK : fmi3Error) : unsupported(i, "fmi3GetClock");
}
fmi3Status fmi3SetClock(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                        const fmi3Clock values[]) {
    (void)vr; (void)values;
    return nvr == 0 ? (i ? fmi3OK : fmi3Error) : unsupported(i, "fmi3SetClock");
}

fmi3Status fmi3DoStep(fmi3Instance i, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    INSTANCE(i);
    int rc = instance_do_step(inst, currentCommunicationPoint, communicationStepSize);
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
    if (lastSuccessfulTime) *lastSuccessfulTime = inst->time;
    return status(rc);
}

fmi3Status fmi3EnterStepMode(fmi3Instance i) {
    INSTANCE(i);  /* no event mode: the instance is in step mode after initialization */
    return inst->state == ST_STEP ? fmi3OK
                                  : status(instance_fail(inst, "fmi3EnterStepMode: no event mode"));
}

/* ---- everything below is not supported ---- */

#define UNSUPPORTED(name, ...) \
    fmi3Status name(fmi3Instance i, __VA_ARGS__) { return unsupported(i, #name); }
#define UNSUPPORTED0(name) \
    fmi3Status name(fmi3Instance i) { return unsupported(i, #name); }

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
UNSUPPORTED0(fmi3EnterEventMode)
UNSUPPORTED(fmi3GetNumberOfVariableDependencies, fmi3ValueReference vr, size_t *n)
UNSUPPORTED(fmi3GetVariableDependencies, fmi3ValueReference dependent,
            size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
            size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
            size_t nDependencies)
UNSUPPORTED(fmi3GetFMUState, fmi3FMUState *s)
UNSUPPORTED(fmi3SetFMUState, fmi3FMUState s)
UNSUPPORTED(fmi3FreeFMUState, fmi3FMUState *s)
UNSUPPORTED(fmi3SerializedFMUStateSize, fmi3FMUState s, size_t *size)
UNSUPPORTED(fmi3SerializeFMUState, fmi3FMUState s, fmi3Byte bytes[], size_t size)
UNSUPPORTED(fmi3DeserializeFMUState, const fmi3Byte bytes[], size_t size, fmi3FMUState *s)
UNSUPPORTED(fmi3GetDirectionalDerivative, const fmi3ValueReference unknowns[], size_t nUnknowns,
            const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
            size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
UNSUPPORTED(fmi3GetAdjointDerivative, const fmi3ValueReference unknowns[], size_t nUnknowns,
            const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
            size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
UNSUPPORTED0(fmi3EnterConfigurationMode)
UNSUPPORTED0(fmi3ExitConfigurationMode)
UNSUPPORTED(fmi3GetIntervalDecimal, const fmi3ValueReference vr[], size_t nvr,
            fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
UNSUPPORTED(fmi3GetIntervalFraction, const fmi3ValueReference vr[], size_t nvr,
            fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
UNSUPPORTED(fmi3GetShiftDecimal, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 shifts[])
UNSUPPORTED(fmi3GetShiftFraction, const fmi3ValueReference vr[], size_t nvr,
            fmi3UInt64 counters[], fmi3UInt64 resolutions[])
UNSUPPORTED(fmi3SetIntervalDecimal, const fmi3ValueReference vr[], size_t nvr,
            const fmi3Float64 intervals[])
UNSUPPORTED(fmi3SetIntervalFraction, const fmi3ValueReference vr[], size_t nvr,
            const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
UNSUPPORTED(fmi3SetShiftDecimal, const fmi3ValueReference vr[], size_t nvr,
            const fmi3Float64 shifts[])
UNSUPPORTED(fmi3SetShiftFraction, const fmi3ValueReference vr[], size_t nvr,
            const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
UNSUPPORTED0(fmi3EvaluateDiscreteStates)
UNSUPPORTED(fmi3UpdateDiscreteStates, fmi3Boolean *discreteStatesNeedUpdate,
            fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
            fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
            fmi3Float64 *nextEventTime)
UNSUPPORTED0(fmi3EnterContinuousTimeMode)
UNSUPPORTED(fmi3CompletedIntegratorStep, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
            fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
UNSUPPORTED(fmi3SetTime, fmi3Float64 time)
UNSUPPORTED(fmi3SetContinuousStates, const fmi3Float64 x[], size_t nx)
UNSUPPORTED(fmi3GetContinuousStateDerivatives, fmi3Float64 derivatives[], size_t nx)
UNSUPPORTED(fmi3GetEventIndicators, fmi3Float64 eventIndicators[], size_t ni)
UNSUPPORTED(fmi3GetContinuousStates, fmi3Float64 x[], size_t nx)
UNSUPPORTED(fmi3GetNominalsOfContinuousStates, fmi3Float64 nominals[], size_t nx)
UNSUPPORTED(fmi3GetNumberOfEventIndicators, size_t *n)
UNSUPPORTED(fmi3GetNumberOfContinuousStates, size_t *n)
UNSUPPORTED(fmi3GetOutputDerivatives, const fmi3ValueReference vr[], size_t nvr,
            const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues)
UNSUPPORTED(fmi3ActivateModelPartition, fmi3ValueReference clockReference,
            fmi3Float64 activationTime)
#pragma GCC diagnostic pop
