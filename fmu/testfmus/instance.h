/* Test FMUs (issue 22): the FMI-version-independent part of an FMU instance — its state
 * machine, variable values and calls into the model (model.h). fmi2.c and fmi3.c translate
 * the FMI 2.0 and FMI 3.0 co-simulation APIs onto these functions. Each returns 0 on
 * success and -1 on failure, after reporting the reason through the instance's log. */
#ifndef TESTFMUS_INSTANCE_H
#define TESTFMUS_INSTANCE_H

#include <stddef.h>

typedef enum { ST_INSTANTIATED, ST_INITIALIZATION, ST_STEP, ST_TERMINATED } InstanceState;

typedef struct Instance Instance;
typedef void LogError(const Instance *inst, const char *message);

struct Instance {
    InstanceState state;
    double time;
    double h_first;  /* the first communication step size; NaN before the first doStep */
    double *v;       /* MODEL_NV values, indexed like MODEL_VARS */
    char *name;
    LogError *log;   /* provided by the FMI glue */
    void *glue;      /* the glue's callbacks and environment */
};

Instance *instance_new(const char *name, LogError *log, void *glue);
void instance_free(Instance *inst);
void instance_reset(Instance *inst); /* start values, time 0, state ST_INSTANTIATED */
int instance_fail(const Instance *inst, const char *fmt, ...);

int instance_enter_initialization(Instance *inst, double start_time);
int instance_exit_initialization(Instance *inst);
int instance_terminate(Instance *inst);
/* vr: value references (0 = time, k = MODEL_VARS[k - 1]). */
int instance_get(Instance *inst, const unsigned vr[], size_t nvr, double values[]);
int instance_set(Instance *inst, const unsigned vr[], size_t nvr, const double values[]);
int instance_do_step(Instance *inst, double t, double h);

#endif
