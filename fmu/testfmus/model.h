/* Test FMUs (issue 22, "FMI: plants from FMUs"): the interface between a model
 * (lti_plant.c, dc_motor.c) and the FMI glue (instance.c with fmi2.c or fmi3.c) and the
 * modelDescription.xml writer (describe.c).
 *
 * A model is a table of real scalar variables and two functions. The FMI value reference of
 * MODEL_VARS[k] is k + 1; value reference 0 is the independent variable `time`. All variables
 * are float64: parameters (variability "fixed", settable until exitInitializationMode),
 * inputs (settable at any time), outputs (calculated) and states: outputs whose start value
 * (initial "exact") is the state at t = 0, settable until exitInitializationMode, so that an
 * importer (the FMU plant's `[plant] x0`, `launcher linearize`) can start the model anywhere. */
#ifndef TESTFMUS_MODEL_H
#define TESTFMUS_MODEL_H

#include <stddef.h>

typedef enum { PARAMETER, INPUT, OUTPUT, STATE } Causality;

typedef struct {
    const char *name;
    Causality causality;
    double start;            /* parameters, inputs and states; ignored for outputs */
    const char *description; /* plain ASCII, no XML markup */
} ModelVar;

extern const char MODEL_IDENTIFIER[];   /* also the shared library's name */
extern const char MODEL_TOKEN[];        /* FMI 2 guid, FMI 3 instantiationToken */
extern const char MODEL_DESCRIPTION[];
extern const int MODEL_VARIABLE_STEP;   /* canHandleVariableCommunicationStepSize */
extern const ModelVar MODEL_VARS[];
extern const size_t MODEL_NV;

/* v[k] is the value of MODEL_VARS[k]. Both functions return NULL on success, else a static
 * message (the FMI call then fails with fmi2Error / fmi3Error and v is left unchanged).
 *
 * model_initialize: the states from the parameters, and the outputs (called when the
 * initialization mode ends, and for getters while in it); must be idempotent.
 * model_step: advance one communication step of length h from the inputs' current values
 * (held over the step); h_first is the first step size this instance was asked for (equal
 * to h on the first step). */
const char *model_initialize(double *v);
const char *model_step(double *v, double h, double h_first);

#endif
