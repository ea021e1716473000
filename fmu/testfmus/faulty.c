/* Test FMU faulty (issue 22): a first-order plant that misbehaves on request, for the
 * launcher's supervision of FMU plants.
 *
 *     x_{k+1} = x_k + h (u1 + w1 - x_k),    y1 = x1 = x
 *
 * From the first doStep that starts at t >= fail_at it does what `how` says:
 * 0 nothing, 1 returns an error (fmi2Error / fmi3Error, with a logged reason),
 * 2 crashes (SIGSEGV in its library), 3 hangs inside doStep (never returns). */
#include <math.h>
#include <signal.h>
#include <unistd.h>

#include "model.h"

const char MODEL_IDENTIFIER[] = "faulty";
const char MODEL_TOKEN[] = "{5d0c3b8e-7a51-4c7e-9b1e-22f0a1c3d003}";
const char MODEL_DESCRIPTION[] = "First-order plant that fails, crashes or hangs in doStep on request";
const int MODEL_VARIABLE_STEP = 1;

enum { FAIL_AT, HOW, U1, W1, Y1, X1, NV };

const ModelVar MODEL_VARS[] = {
    [FAIL_AT] = { "fail_at", PARAMETER, 1e300, "time from which doStep misbehaves [s]" },
    [HOW] = { "how", PARAMETER, 0, "0 nothing, 1 error, 2 crash, 3 hang" },
    [U1] = { "u1", INPUT, 0, "input" },
    [W1] = { "w1", INPUT, 0, "unknown input" },
    [Y1] = { "y1", OUTPUT, 0, "output, x" },
    [X1] = { "x1", OUTPUT, 0, "state" },
};
const size_t MODEL_NV = sizeof MODEL_VARS / sizeof MODEL_VARS[0];
_Static_assert(sizeof MODEL_VARS / sizeof MODEL_VARS[0] == NV, "variable table and enum");

/* The current time is not passed to model_step: count it. */
static double t_now;

const char *model_initialize(double *v) {
    v[X1] = v[Y1] = 0.0;
    t_now = 0.0;
    return NULL;
}

const char *model_step(double *v, double h, double h_first) {
    (void)h_first;
    if (t_now >= v[FAIL_AT]) {
        if (v[HOW] == 1) return "faulty: doStep fails on request (how = 1)";
        if (v[HOW] == 2) raise(SIGSEGV);
        if (v[HOW] == 3) for (;;) pause();
    }
    double x = v[X1] + h * (v[U1] + v[W1] - v[X1]);
    v[X1] = v[Y1] = x;
    t_now += h;
    return NULL;
}
