/* Test FMU dc_motor (issue 22): a nonlinear DC motor with smoothed Coulomb friction,
 * states x = (i, omega, theta):
 *
 *     L di/dt     = -R i - K omega + u1
 *     J domega/dt =  K i - b omega - tau_c tanh(omega / omega_s) - w1
 *       dtheta/dt =  omega
 *
 * u1 is the voltage (known input), w1 the load torque (unknown input). Outputs y1 = omega,
 * y2 = theta, and the states x1 = i, x2 = omega, x3 = theta; x(0) = their start values
 * (0 unless set before initialisation).
 *
 * One doStep of length h integrates with `substeps` classical RK4 steps of length
 * h / substeps, the inputs held at their values at the step's start. Any h > 0 is accepted.
 * `substeps` is a real-valued parameter that must hold an integer in [1, 1e6].
 *
 * Default parameters: electrical time constant L/R = 0.25 s, mechanical J/b = 0.4 s;
 * 12 V gives about 10.7 rad/s without load. */
#include <math.h>
#include <string.h>

#include "model.h"

const char MODEL_IDENTIFIER[] = "dc_motor";
const char MODEL_TOKEN[] = "{5d0c3b8e-7a51-4c7e-9b1e-22f0a1c3d002}";
const char MODEL_DESCRIPTION[] =
    "DC motor with Coulomb friction (tanh-smoothed), RK4 with a fixed number of substeps";
const int MODEL_VARIABLE_STEP = 1;

enum { R, LL, K, J, B, TAU_C, OMEGA_S, SUBSTEPS, U1, W1, Y1, Y2, XI, XOMEGA, XTHETA, NV };

const ModelVar MODEL_VARS[] = {
    [R] = { "R", PARAMETER, 2.0, "armature resistance [Ohm]" },
    [LL] = { "L", PARAMETER, 0.5, "armature inductance [H]" },
    [K] = { "K", PARAMETER, 0.1, "torque and back-emf constant [N m/A]" },
    [J] = { "J", PARAMETER, 0.02, "rotor inertia [kg m2]" },
    [B] = { "b", PARAMETER, 0.05, "viscous friction [N m s]" },
    [TAU_C] = { "tau_c", PARAMETER, 0.01, "Coulomb friction torque [N m]" },
    [OMEGA_S] = { "omega_s", PARAMETER, 0.05, "speed scale of the tanh smoothing [rad/s]" },
    [SUBSTEPS] = { "substeps", PARAMETER, 10, "RK4 steps per communication step (an integer)" },
    [U1] = { "u1", INPUT, 0, "voltage [V]" },
    [W1] = { "w1", INPUT, 0, "load torque [N m]" },
    [Y1] = { "y1", OUTPUT, 0, "speed omega [rad/s]" },
    [Y2] = { "y2", OUTPUT, 0, "angle theta [rad]" },
    [XI] = { "x1", STATE, 0, "state: current i [A]" },
    [XOMEGA] = { "x2", STATE, 0, "state: speed omega [rad/s]" },
    [XTHETA] = { "x3", STATE, 0, "state: angle theta [rad]" },
};
const size_t MODEL_NV = sizeof MODEL_VARS / sizeof MODEL_VARS[0];
_Static_assert(sizeof MODEL_VARS / sizeof MODEL_VARS[0] == NV, "variable table and enum");

static void f(const double *v, const double x[3], double dx[3]) {
    double i = x[0], omega = x[1];
    dx[0] = (-v[R] * i - v[K] * omega + v[U1]) / v[LL];
    dx[1] = (v[K] * i - v[B] * omega - v[TAU_C] * tanh(omega / v[OMEGA_S]) - v[W1]) / v[J];
    dx[2] = omega;
}

static const char *check(const double *v) {
    if (!(v[LL] > 0 && v[J] > 0 && v[OMEGA_S] > 0))
        return "dc_motor: L, J and omega_s must be > 0";
    if (!(v[SUBSTEPS] >= 1 && v[SUBSTEPS] <= 1e6 && v[SUBSTEPS] == floor(v[SUBSTEPS])))
        return "dc_motor: substeps must be an integer in [1, 1e6]";
    return NULL;
}

const char *model_initialize(double *v) {
    const char *err = check(v);
    if (err) return err;
    v[Y1] = v[XOMEGA];
    v[Y2] = v[XTHETA];
    return NULL;
}

const char *model_step(double *v, double h, double h_first) {
    (void)h_first;
    const char *err = check(v);
    if (err) return err;
    int n = (int)v[SUBSTEPS];
    double dt = h / n;
    double x[3] = { v[XI], v[XOMEGA], v[XTHETA] };
    for (int s = 0; s < n; s++) {
        double k1[3], k2[3], k3[3], k4[3], xt[3];
        f(v, x, k1);
        for (int m = 0; m < 3; m++) xt[m] = x[m] + 0.5 * dt * k1[m];
        f(v, xt, k2);
        for (int m = 0; m < 3; m++) xt[m] = x[m] + 0.5 * dt * k2[m];
        f(v, xt, k3);
        for (int m = 0; m < 3; m++) xt[m] = x[m] + dt * k3[m];
        f(v, xt, k4);
        for (int m = 0; m < 3; m++) x[m] += dt / 6.0 * (k1[m] + 2.0 * k2[m] + 2.0 * k3[m] + k4[m]);
    }
    if (!(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2])))
        return "dc_motor: the state is no longer finite";
    v[XI] = x[0];
    v[XOMEGA] = v[Y1] = x[1];
    v[XTHETA] = v[Y2] = x[2];
    return NULL;
}
