/* Test FMU lti_plant (issue 22): a sampled linear plant, the dimensions of
 * scenarios/seed002-piecewise.toml (n = 3 states, l = 2 inputs, q = 1 unknown input,
 * p = 2 outputs):
 *
 *     x_{k+1} = Phi x_k + Gamma_B u_k + Gamma_E w_k,    y_k = C x_k,    x_0 = the start values of x.
 *
 * Phi_i_j, Gamma_B_i_j, Gamma_E_i_j and C_i_j (1-based indices) are fixed parameters; the
 * states x1..x3 take their start values (0 unless set before initialisation);
 * u1, u2, w1 inputs; y1, y2 and the states x1, x2, x3 outputs.
 *
 * One doStep advances exactly one sample, k -> k+1: the FMU assumes that the communication
 * step size h is the sample period of Phi, Gamma_B and Gamma_E. It has no step size of its
 * own; it takes the first h it is asked for and refuses (fmi2Error / fmi3Error) any later
 * step whose h differs from that one by more than 1e-9 relative.
 *
 * The arithmetic order is fixed, so that a reference with the same loops gives the same bits:
 * one double accumulator starting at 0.0, then
 *     x_new[i] = ((sum_j Phi[i][j] x[j]) + sum_j Gamma_B[i][j] u[j]) + sum_j Gamma_E[i][j] w[j]
 *     y[i]     = sum_j C[i][j] x[j]
 * each sum over j ascending, added term by term to the accumulator. Compile with
 * -ffp-contract=off (build.sh does) so that no multiply-add is fused. */
#include <math.h>
#include <string.h>

#include "model.h"

#define N 3 /* states */
#define L 2 /* known inputs */
#define Q 1 /* unknown inputs */
#define P 2 /* outputs */

const char MODEL_IDENTIFIER[] = "lti_plant";
const char MODEL_TOKEN[] = "{5d0c3b8e-7a51-4c7e-9b1e-22f0a1c3d001}";
const char MODEL_DESCRIPTION[] =
    "Sampled LTI plant x+ = Phi x + Gamma_B u + Gamma_E w, y = C x; one doStep is one sample";
const int MODEL_VARIABLE_STEP = 0;

/* Offsets into MODEL_VARS (row-major within each matrix). */
enum {
    PHI = 0,              /* Phi[i][j]     at PHI + i*N + j */
    GB = PHI + N * N,     /* Gamma_B[i][j] at GB + i*L + j */
    GE = GB + N * L,      /* Gamma_E[i][j] at GE + i*Q + j */
    CM = GE + N * Q,      /* C[i][j]       at CM + i*N + j */
    U = CM + P * N,       /* u1, u2 */
    W = U + L,            /* w1 */
    Y = W + Q,            /* y1, y2 */
    X = Y + P,            /* x1, x2, x3 */
    NV = X + N
};

#define PAR(name, start) { name, PARAMETER, start, "" }
const ModelVar MODEL_VARS[] = {
    PAR("Phi_1_1", 1), PAR("Phi_1_2", 0), PAR("Phi_1_3", 0),
    PAR("Phi_2_1", 0), PAR("Phi_2_2", 1), PAR("Phi_2_3", 0),
    PAR("Phi_3_1", 0), PAR("Phi_3_2", 0), PAR("Phi_3_3", 1),
    PAR("Gamma_B_1_1", 0), PAR("Gamma_B_1_2", 0),
    PAR("Gamma_B_2_1", 0), PAR("Gamma_B_2_2", 0),
    PAR("Gamma_B_3_1", 0), PAR("Gamma_B_3_2", 0),
    PAR("Gamma_E_1_1", 0), PAR("Gamma_E_2_1", 0), PAR("Gamma_E_3_1", 0),
    PAR("C_1_1", 1), PAR("C_1_2", 0), PAR("C_1_3", 0),
    PAR("C_2_1", 0), PAR("C_2_2", 0), PAR("C_2_3", 1),
    { "u1", INPUT, 0, "known input 1" },
    { "u2", INPUT, 0, "known input 2" },
    { "w1", INPUT, 0, "unknown input (disturbance) 1" },
    { "y1", OUTPUT, 0, "measured output 1, (C x)_1" },
    { "y2", OUTPUT, 0, "measured output 2, (C x)_2" },
    { "x1", STATE, 0, "state 1" },
    { "x2", STATE, 0, "state 2" },
    { "x3", STATE, 0, "state 3" },
};
const size_t MODEL_NV = sizeof MODEL_VARS / sizeof MODEL_VARS[0];
_Static_assert(sizeof MODEL_VARS / sizeof MODEL_VARS[0] == NV, "variable table and offsets");

static void outputs(double *v) {
    for (int i = 0; i < P; i++) {
        double acc = 0.0;
        for (int j = 0; j < N; j++) acc += v[CM + i * N + j] * v[X + j];
        v[Y + i] = acc;
    }
}

const char *model_initialize(double *v) {
    outputs(v);
    return NULL;
}

const char *model_step(double *v, double h, double h_first) {
    if (!(fabs(h - h_first) <= 1e-9 * fabs(h_first)))
        return "lti_plant: the communication step size must stay the sample period "
               "(the first step size it was given)";
    double x_new[N];
    for (int i = 0; i < N; i++) {
        double acc = 0.0;
        for (int j = 0; j < N; j++) acc += v[PHI + i * N + j] * v[X + j];
        for (int j = 0; j < L; j++) acc += v[GB + i * L + j] * v[U + j];
        for (int j = 0; j < Q; j++) acc += v[GE + i * Q + j] * v[W + j];
        x_new[i] = acc;
    }
    memcpy(&v[X], x_new, sizeof x_new);
    outputs(v);
    return NULL;
}
