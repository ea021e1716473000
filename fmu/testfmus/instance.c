/* Test FMUs (issue 22): FMI-version-independent instance logic; see instance.h. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "instance.h"
#include "model.h"

Instance *instance_new(const char *name, LogError *log, void *glue) {
    Instance *inst = calloc(1, sizeof *inst);
    if (!inst) return NULL;
    inst->v = calloc(MODEL_NV, sizeof *inst->v);
    inst->name = strdup(name ? name : MODEL_IDENTIFIER);
    if (!inst->v || !inst->name) {
        instance_free(inst);
        return NULL;
    }
    inst->log = log;
    inst->glue = glue;
    instance_reset(inst);
    return inst;
}

void instance_free(Instance *inst) {
    if (!inst) return;
    free(inst->v);
    free(inst->name);
    free(inst);
}

void instance_reset(Instance *inst) {
    for (size_t k = 0; k < MODEL_NV; k++)
        inst->v[k] = MODEL_VARS[k].causality == OUTPUT ? 0.0 : MODEL_VARS[k].start;
    inst->time = 0.0;
    inst->h_first = NAN;
    inst->state = ST_INSTANTIATED;
}

int instance_fail(const Instance *inst, const char *fmt, ...) {
    char message[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    if (inst && inst->log) inst->log(inst, message);
    return -1;
}

/* The model's initial states and outputs from the current parameters, on a copy: a failure
 * leaves the values as they were. */
static int initialize(Instance *inst) {
    double *w = malloc(MODEL_NV * sizeof *w);
    if (!w) return instance_fail(inst, "out of memory");
    memcpy(w, inst->v, MODEL_NV * sizeof *w);
    const char *err = model_initialize(w);
    if (!err) memcpy(inst->v, w, MODEL_NV * sizeof *w);
    free(w);
    return err ? instance_fail(inst, "%s", err) : 0;
}

int instance_enter_initialization(Instance *inst, double start_time) {
    if (inst->state != ST_INSTANTIATED)
        return instance_fail(inst, "enter initialization mode: only right after instantiation");
    if (!isfinite(start_time)) return instance_fail(inst, "the start time must be finite");
    inst->time = start_time;
    inst->state = ST_INITIALIZATION;
    return 0;
}

int instance_exit_initialization(Instance *inst) {
    if (inst->state != ST_INITIALIZATION)
        return instance_fail(inst, "exit initialization mode: not in initialization mode");
    if (initialize(inst)) return -1;
    inst->state = ST_STEP;
    return 0;
}

int instance_terminate(Instance *inst) {
    if (inst->state != ST_STEP) return instance_fail(inst, "terminate: not in step mode");
    inst->state = ST_TERMINATED;
    return 0;
}

static int check_refs(const Instance *inst, const unsigned vr[], size_t nvr, const void *values) {
    if (nvr > 0 && (!vr || !values))
        return instance_fail(inst, "null value reference or value array");
    for (size_t k = 0; k < nvr; k++)
        if (vr[k] > MODEL_NV)
            return instance_fail(inst, "unknown value reference %u", vr[k]);
    return 0;
}

int instance_get(Instance *inst, const unsigned vr[], size_t nvr, double values[]) {
    if (check_refs(inst, vr, nvr, values)) return -1;
    if (inst->state == ST_INITIALIZATION && initialize(inst)) return -1;
    for (size_t k = 0; k < nvr; k++) values[k] = vr[k] == 0 ? inst->time : inst->v[vr[k] - 1];
    return 0;
}

int instance_set(Instance *inst, const unsigned vr[], size_t nvr, const double values[]) {
    if (check_refs(inst, vr, nvr, values)) return -1;
    for (size_t k = 0; k < nvr; k++) {  /* check all before setting any */
        if (vr[k] == 0) return instance_fail(inst, "time cannot be set");
        const ModelVar *var = &MODEL_VARS[vr[k] - 1];
        if (var->causality == OUTPUT) return instance_fail(inst, "%s is an output", var->name);
        if ((var->causality == PARAMETER || var->causality == STATE) && inst->state != ST_INSTANTIATED
            && inst->state != ST_INITIALIZATION)
            return instance_fail(inst, "%s is a %s: set it before exitInitializationMode",
                                 var->name, var->causality == STATE ? "state's start value" : "fixed parameter");
        if (var->causality == INPUT && inst->state == ST_TERMINATED)
            return instance_fail(inst, "%s: the instance is terminated", var->name);
    }
    for (size_t k = 0; k < nvr; k++) inst->v[vr[k] - 1] = values[k];
    return 0;
}

int instance_do_step(Instance *inst, double t, double h) {
    (void)t; /* the instance keeps its own time */
    if (inst->state != ST_STEP) return instance_fail(inst, "doStep: not in step mode");
    if (!(h > 0) || !isfinite(h))
        return instance_fail(inst, "doStep: the step size must be finite and > 0");
    double h_first = isnan(inst->h_first) ? h : inst->h_first;
    double *w = malloc(MODEL_NV * sizeof *w);
    if (!w) return instance_fail(inst, "out of memory");
    memcpy(w, inst->v, MODEL_NV * sizeof *w);
    const char *err = model_step(w, h, h_first);
    if (!err) {
        memcpy(inst->v, w, MODEL_NV * sizeof *w);
        inst->h_first = h_first;
        inst->time += h;
    }
    free(w);
    return err ? instance_fail(inst, "doStep(t = %.17g, h = %.17g): %s", t, h, err) : 0;
}
