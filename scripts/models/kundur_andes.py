#!/usr/bin/env python3
"""Export the Kundur two-area system, linearised by ANDES, as an (A, B, C, E) plant.

The model
---------
Kundur's two-area, four-machine test system (P. Kundur, "Power System Stability and Control",
McGraw-Hill 1994, Example 12.6) as the case ``kundur/kundur_full.xlsx`` shipped with ANDES
(H. Cui, F. Li, K. Tomsovic, "Hybrid symbolic-numeric framework for power system modeling and
analysis", IEEE Trans. Power Systems 36(2), 2021; https://pypi.org/project/andes/): 10 buses,
four sixth-order round-rotor generators (GENROU), a TGOV1 steam governor and an EXDC2 DC exciter
on each. ANDES solves the power flow, initialises the dynamic models at that operating point and
linearises the DAE  Tf x' = f(x, y), 0 = g(x, y)  there; its small-signal routine ``EIG``
eliminates the algebraic variables y:  A = Tf^-1 (f_x - f_y g_y^-1 g_x)  (52 states).

Units are ANDES's: per unit on the 100 MVA system base, angles in rad, speed in pu of 60 Hz,
time in s. The states are deviations from the operating point (absolute values - equilibrium).

The signals
-----------
  y (p = 8)  the four rotor angles delta_i (rad) and the four speeds omega_i (pu): rows of I.
             Absolute angles, not differences to generator 1: A has one eigenvalue at 0 whose
             eigenvector shifts all four angles together (ANDES keeps no angle reference once
             the dynamic generators replace the slack bus), so with angle differences that mode
             is unobservable and marginal, and (A, C) is not detectable. Absolute angles make it
             observable.
  w (q = 2)  unknown mechanical-torque disturbances on generators 2 and 3 (pu torque, system
             base), added to the torque the governor delivers to the shaft: tm_i = pout_i + w.
  u (l = 4)  known inputs: the voltage references vref of the four exciters (pu).

How B and E are obtained (from ANDES's own equations, no model data copied; the code is the
general one of scripts/models/andes_case.py, which exports the other ANDES cases the same way):
  An input enters one residual equation of the DAE. The residual sensitivities f_u, g_u are
  measured by a forward difference through ANDES's residual evaluation (``TDS.fg_update``) at
  the operating point, perturbing
    * ``EXDC2.vref0`` (the constant in the exciter's equation 0 = vref0 - vref) for B, and
    * ``TGOV1.tm0`` by -eps (the constant in the governor-to-generator torque interface
      0 = tm0_gen - tm + pout - tm0_gov) for E: this is tm = pout + w, an added shaft torque;
  then the algebraic variables are eliminated as for A:
    [B E] = Tf^-1 (f_u - f_y g_y^-1 g_u).
  Each perturbation moves exactly one algebraic residual by 1 (the equations are affine in
  these constants), so the difference is exact up to rounding; the script checks this. E must
  come out as 1/M_i (M = 2H on the system base, ANDES's GENROU.M) in the row of omega_i, from
  the swing equation M omega' = tm - te - D (omega - 1); the script checks that too.

Besides A, B, C, E (float64, C order) the script writes
  Qd.npy     the scenario's process-noise covariance per step (sigma_q^2 I, tiny: the
             comparison is about decoupling w, not about noise),
  Q_lqe.npy  the UIO's LQE process weight (I, n x n), a file because it is 52 x 52,
  states.txt the state names (ANDES's, spaces replaced by '_'), one a line,
and prints the checks: eigenvalues, detectability, rank(CE), invariant zeros of (A, E, C), and
the discrete Chen-Patton UIO with an LQE gain and a plain Kalman filter at --dt.

What it finds (ANDES 2.0.0): eig(A) has real parts in [-49.5, 0] (one eigenvalue at 0, the
common angle), max |Im| = 7.17; (A, C) is detectable (unobservable: the four exciter lead-lag
modes at -1, whose TB = TC cancel); rank CE = rank E = 2; the invariant zeros of (A, E, C) are
-1 (x4, those exciter modes) and -1/T1 = -2.04, -1/T3 = -0.143 (x2 each): the TGOV1 governors of
generators 2 and 3 reach the outputs only through the shaft torque, the channel w also uses, so
a UIO cannot see them and their 7 s lag is its slowest mode. In the sampled pair (T Phi, C) those
four governor modes are observable only at the 1e-9 level (PBH), so a rank-revealing test may
call them observable; either way an LQE gain leaves them where they are.

Run (ANDES 2.0.0, numpy 2.4.6, scipy 1.17.1 from PyPI; any working directory):

    python3 -m venv /work/andes-venv && /work/andes-venv/bin/pip install andes==2.0.0
    /work/andes-venv/bin/python scripts/models/kundur_andes.py            # writes scenarios/models/kundur/
    /work/andes-venv/bin/python scripts/models/kundur_andes.py --check    # prints the checks, writes nothing
"""

import argparse
import os

import numpy as np
import scipy.linalg as sla

from andes_case import linearise, load_operating_point   # the same folder: the general ANDES export

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.normpath(os.path.join(HERE, "..", "..", "scenarios", "models", "kundur"))

CASE = "kundur/kundur_full.xlsx"
DISTURBED = (2, 3)          # generators whose shaft torque carries the unknown inputs (1-based)
SIGMA_Q = 1e-9              # process noise per step and state, std (the scenario's [noise])
LQE_R = 0.01                # R = LQE_R I for the UIO's and the reference Kalman filter's design


# ---------------------------------------------------------------------------------------------
# Checks (scipy only)


def pbh_unobservable(a, c, lam, tol=1e-8):
    """True when the mode lam of (A, C) is unobservable: rank [A - lam I; C] < n."""
    n = a.shape[0]
    s = sla.svdvals(np.vstack([a - lam * np.eye(n), c]))
    return s[-1] <= tol * s[0]


def rosenbrock_sigma(a, e, c, s):
    """Smallest singular value of [[A - sI, E], [C, 0]] relative to its largest."""
    n, q, p = a.shape[0], e.shape[1], c.shape[0]
    m = np.block([[a - s * np.eye(n), e], [c, np.zeros((p, q))]])
    sv = sla.svdvals(m)
    return sv[n + q - 1] / sv[0]   # the (n+q)-th value: the pencil is (n+p) x (n+q), p > q


def invariant_zeros(a, e, c, rng, tol=1e-7):
    """Zeros of the tall pencil: finite generalised eigenvalues of two random square-downs
    [[A - sI, E], [K C, 0]] (K q x p), kept when both have them and the tall pencil loses rank."""
    n, q, p = a.shape[0], e.shape[1], c.shape[0]
    cands = []
    for _ in range(2):
        k = rng.standard_normal((q, p))
        m = np.block([[a, e], [k @ c, np.zeros((q, q))]])
        nn = np.zeros_like(m)
        nn[:n, :n] = np.eye(n)
        w = sla.eig(m, nn, right=False, homogeneous_eigvals=True)
        alpha, beta = w
        finite = np.abs(beta) > 1e-12 * np.abs(alpha).max()
        cands.append(alpha[finite] / beta[finite])
    scale = max(1.0, np.abs(np.linalg.eigvals(a)).max())
    common = [z for z in cands[0] if np.min(np.abs(cands[1] - z)) <= 1e-6 * scale]
    return [z for z in common if rosenbrock_sigma(a, e, c, z) <= tol]


def sample(a, b, e, dt):
    """Exact zero-order-hold sampling: Phi, Gamma_B, Gamma_E from expm([[A, B, E], [0, 0, 0]] dt)."""
    n, l, q = a.shape[0], b.shape[1], e.shape[1]
    big = np.zeros((n + l + q, n + l + q))
    big[:n, :n], big[:n, n:n + l], big[:n, n + l:] = a, b, e
    f = sla.expm(big * dt)
    return f[:n, :n], f[:n, n:n + l], f[:n, n + l:]


def predictor(phi, c, q, r):
    """Steady-state one-step predictor gain K = Phi P C' (C P C' + R)^-1 and rho(Phi - K C)."""
    p = sla.solve_discrete_are(phi.T, c.T, q, r)
    k = phi @ p @ c.T @ np.linalg.inv(c @ p @ c.T + r)
    lam = np.linalg.eigvals(phi - k @ c)
    return k, lam


def report(a, b, c, e, dt):
    n, p, q = a.shape[0], c.shape[0], e.shape[1]
    rng = np.random.default_rng(0)
    lam = np.linalg.eigvals(a)
    print(f"n = {n}, p = {p}, q = {q}, l = {b.shape[1]}   (p <= n/5: {p <= n / 5})")
    print(f"eig(A): Re in [{lam.real.min():.6g}, {lam.real.max():.3g}], max |Im| = {np.abs(lam.imag).max():.6g}, "
          f"max |lambda| = {np.abs(lam).max():.6g}")
    marginal = lam[lam.real > -1e-6]
    print(f"  eigenvalues with Re >= -1e-6: {np.round(marginal, 12)}")
    bad = [z for z in marginal if pbh_unobservable(a, c, z)]
    print(f"(A, C) detectable: {not bad}   (PBH on the modes with Re >= -1e-6)")
    # Exactly unobservable (the PBH matrix is singular to rounding) vs weakly observable: the
    # fast exciter modes (TA = 0.02 s) reach the angles and speeds only at ~1e-7 of their size.
    unobs = [z for z in lam if pbh_unobservable(a, c, z, tol=1e-12)]
    weak = [z for z in lam if pbh_unobservable(a, c, z, tol=1e-8) and not pbh_unobservable(a, c, z, tol=1e-12)]
    print(f"  unobservable modes of (A, C): {np.round(np.sort_complex(np.array(unobs)), 6)}")
    print(f"  weakly observable (PBH sigma_min/sigma_max in 1e-12..1e-8): {np.round(np.sort_complex(np.array(weak)), 3)}")
    rce, re_ = np.linalg.matrix_rank(c @ e), np.linalg.matrix_rank(e)
    print(f"rank(CE) = {rce}, rank(E) = {re_}: {'ok' if rce == re_ else 'FAILS'}")
    zeros = invariant_zeros(a, e, c, rng)
    print(f"invariant zeros of (A, E, C): {np.round(np.sort_complex(np.array(zeros)), 6) if zeros else 'none'}")
    at_eig = min(rosenbrock_sigma(a, e, c, z) for z in lam)
    at_rand = min(rosenbrock_sigma(a, e, c, complex(*rng.standard_normal(2) * 10)) for _ in range(5))
    print(f"  min sigma_(n+q)/sigma_1 of the pencil: at the eigenvalues of A {at_eig:.3g}, at 5 random s {at_rand:.3g}")

    # Discrete Chen-Patton UIO: e+ = (T Phi - K C) e, H = Gamma_E (C Gamma_E)^+, T = I - H C.
    phi, gb, ge = sample(a, b, e, dt)
    print(f"dt = {dt}: max |lambda| dt = {np.abs(lam).max() * dt:.3g}")
    h = ge @ np.linalg.pinv(c @ ge)
    t = np.eye(n) - h @ c
    print(f"  rank(C Gamma_E) = {np.linalg.matrix_rank(c @ ge)}, |T Gamma_E| = {np.abs(t @ ge).max():.2g}")
    tphi = t @ phi
    _, lam_uio = predictor(tphi, c, np.eye(n), LQE_R * np.eye(p))
    # The unobservable modes of (T Phi, C) are the sampled invariant zeros exp(z dt) (with the
    # sampled unobservable modes of (A, C)); no gain moves them, so they stay in T Phi - K C.
    zd = np.exp(np.array(zeros) * dt)
    gap = max((np.min(np.abs(lam_uio - z)) for z in zd), default=0.0)
    print(f"  every exp(z dt) of an invariant zero is an eigenvalue of T Phi - K C (to {gap:.1e})")
    rho = np.abs(lam_uio).max()
    print(f"  UIO, LQE Q = I, R = {LQE_R} I: rho(T Phi - K C) = {rho:.6g}, slowest time constant "
          f"{-dt / np.log(rho):.4g} s")
    _, lam_kf = predictor(phi, c, np.eye(n), LQE_R * np.eye(p))
    rho_kf = np.abs(lam_kf).max()
    print(f"  Kalman on (Phi, C), Q = I, R = {LQE_R} I: rho(Phi - K C) = {rho_kf:.6g}, slowest time constant "
          f"{-dt / np.log(rho_kf):.4g} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=DEFAULT_OUT, help="folder for the .npy files (default: %(default)s)")
    ap.add_argument("--dt", type=float, default=0.01, help="sample time of the discrete checks")
    ap.add_argument("--check", action="store_true", help="print the checks only, write nothing")
    args = ap.parse_args()

    ss, version = load_operating_point(CASE)
    a, b, c, e, names, _ = linearise(ss, DISTURBED)
    print(f"ANDES {version}, case {CASE}: {len(names)} states")
    report(a, b, c, e, args.dt)
    if args.check:
        return
    os.makedirs(args.out, exist_ok=True)
    n = a.shape[0]
    files = dict(A=a, B=b, C=c, E=e, Qd=SIGMA_Q**2 * np.eye(n), Q_lqe=np.eye(n))
    for key, m in files.items():
        np.save(os.path.join(args.out, f"{key}.npy"), np.ascontiguousarray(m, dtype=np.float64))
    with open(os.path.join(args.out, "states.txt"), "w") as fh:
        fh.write("\n".join(names) + "\n")
    print(f"wrote {', '.join(k + '.npy' for k in files)}, states.txt to {args.out}")


if __name__ == "__main__":
    main()
