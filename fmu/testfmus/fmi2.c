/* Test FMUs (issue 22): the FMI 2.0 co-simulation API over instance.c. Linked with one model
 * (lti_plant.c or dc_motor.c) into binaries/linux64/<model>.so. Real variables only; Integer,
 * Boolean and String accessors accept empty requests and refuse others; FMU state,
 * directional derivatives, input derivatives and asynchronous steps are not supported
 * (fmi2Error). Every entry point checks its instance pointer. */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "instance.h"
#include "model.h"

static void log_error(const Instance *inst, const char *message) {
    const fmi2CallbackFunctions *cb = inst->glue;
    if (cb && cb->logger)
        cb->logger(cb->componentEnvironment, inst->name, fmi2Error, "logStatusError", "%s", message);
}

static fmi2Status status(int rc) { return rc ? fmi2Error : fmi2OK; }

#define INSTANCE(c) Instance *inst = (Instance *)(c); if (!inst) return fmi2Error

static fmi2Status unsupported(fmi2Component c, const char *what) {
    INSTANCE(c);
    return status(instance_fail(inst, "%s is not supported", what));
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    (void)loggingOn; (void)nCategories; (void)categories;
    INSTANCE(c);
    return fmi2OK;  /* errors are always logged; there is nothing else to log */
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    (void)fmuResourceLocation; (void)visible; (void)loggingOn;
    if (!functions) return NULL;
    fmi2CallbackFunctions *cb = malloc(sizeof *cb);
    if (!cb) return NULL;
    *cb = *functions;
    Instance tmp = { .name = (char *)(instanceName ? instanceName : MODEL_IDENTIFIER),
                     .log = log_error, .glue = cb };
    const char *err = NULL;
    if (fmuType != fmi2CoSimulation) err = "only co-simulation is supported";
    else if (!fmuGUID || strcmp(fmuGUID, MODEL_TOKEN) != 0) err = "the GUID does not match";
    Instance *inst = err ? NULL : instance_new(instanceName, log_error, cb);
    if (!inst) {
        instance_fail(&tmp, "fmi2Instantiate: %s", err ? err : "out of memory");
        free(cb);
    }
    return inst;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *inst = c;
    if (!inst) return;
    free(inst->glue);
    instance_free(inst);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime) {
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    INSTANCE(c);
    if (inst->state != ST_INSTANTIATED)
        return status(instance_fail(inst, "fmi2SetupExperiment: only after instantiation"));
    inst->time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    INSTANCE(c);
    return status(instance_enter_initialization(inst, inst->time));
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    INSTANCE(c);
    return status(instance_exit_initialization(inst));
}

fmi2Status fmi2Terminate(fmi2Component c) {
    INSTANCE(c);
    return status(instance_terminate(inst));
}

fmi2Status fmi2Reset(fmi2Component c) {
    INSTANCE(c);
    instance_reset(inst);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    INSTANCE(c);
    return status(instance_get(inst, vr, nvr, value));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    INSTANCE(c);
    return status(instance_set(inst, vr, nvr, value));
}

/* No Integer, Boolean or String variables: an empty request is fine, any other an error. */
#define NO_VARIABLES(T)                                                                      \
    fmi2Status fmi2Get##T(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,       \
                          fmi2##T value[]) {                                                \
        (void)vr; (void)value;                                                              \
        return nvr == 0 ? (c ? fmi2OK : fmi2Error) : unsupported(c, "fmi2Get" #T);          \
    }                                                                                       \
    fmi2Status fmi2Set##T(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,       \
                          const fmi2##T value[]) {                                          \
        (void)vr; (void)value;                                                              \
        return nvr == 0 ? (c ? fmi2OK : fmi2Error) : unsupported(c, "fmi2Set" #T);          \
    }
NO_VARIABLES(Integer)
NO_VARIABLES(Boolean)
NO_VARIABLES(String)

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s; return unsupported(c, "fmi2GetFMUstate");
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    (void)s; return unsupported(c, "fmi2SetFMUstate");
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s; return unsupported(c, "fmi2FreeFMUstate");
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size) {
    (void)s; (void)size; return unsupported(c, "fmi2SerializedFMUstateSize");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte bytes[], size_t size) {
    (void)s; (void)bytes; (void)size; return unsupported(c, "fmi2SerializeFMUstate");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size,
                                   fmi2FMUstate *s) {
    (void)bytes; (void)size; (void)s; return unsupported(c, "fmi2DeSerializeFMUstate");
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown[],
                                        size_t nUnknown, const fmi2ValueReference vKnown[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    (void)vUnknown; (void)nUnknown; (void)vKnown; (void)nKnown; (void)dvKnown; (void)dvUnknown;
    return unsupported(c, "fmi2GetDirectionalDerivative");
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    INSTANCE(c);
    return status(instance_do_step(inst, currentCommunicationPoint, communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c) { return unsupported(c, "fmi2CancelStep"); }

/* doStep always completes synchronously, so there is no pending status to ask for. */
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s; (void)value; return unsupported(c, "fmi2GetStatus");
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    INSTANCE(c);
    if (s == fmi2LastSuccessfulTime && value) {
        *value = inst->time;
        return fmi2OK;
    }
    return unsupported(c, "fmi2GetRealStatus (other than fmi2LastSuccessfulTime)");
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s; (void)value; return unsupported(c, "fmi2GetIntegerStatus");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)s; (void)value; return unsupported(c, "fmi2GetBooleanStatus");
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s; (void)value; return unsupported(c, "fmi2GetStringStatus");
}
