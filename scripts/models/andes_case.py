#!/usr/bin/env python3
"""Export a dynamic power-system case shipped with ANDES, linearised, as an (A, B, C, E) plant.

The cases
---------
Any dynamic case of ANDES (H. Cui, F. Li, K. Tomsovic, "Hybrid symbolic-numeric framework for
power system modeling and analysis", IEEE Trans. Power Systems 36(2), 2021;
https://pypi.org/project/andes/), located with ``andes.get_case``. Short names:

  kundur  kundur/kundur_full.xlsx   Kundur's two-area system: 4 GENROU, TGOV1, EXDC2
  ieee14  ieee14/ieee14_full.xlsx   IEEE 14-bus: 5 GENROU, TGOV1, EXST1 + ESST3A
  ieee39  ieee39/ieee39_full.xlsx   IEEE 39-bus (New England): 10 GENROU, TGOV1N, IEEEX1, IEEEST
  npcc    npcc/npcc.xlsx            NPCC 140-bus: 21 GENCLS + 27 GENROU, TGOV1, IEEEX1
  wecc    wecc/wecc_full.xlsx       WECC 179-bus: 29 GENROU, IEEEG1, ESDC2A + EXST1 + ESST3A,
                                    IEEEST, ST2CUT

(any other ANDES relative path, e.g. ``ieee14/ieee14_esst1a.xlsx``, is accepted as well).
``--set MODEL.PARAM=VALUE`` changes a parameter of every device of a model before the power flow
(recorded in meta.json); by default the cases are exported as ANDES ships them.

ANDES solves the power flow, initialises the dynamic models at that operating point and
linearises the DAE  Tf x' = f(x, y), 0 = g(x, y)  there; its small-signal routine ``EIG``
eliminates the algebraic variables y. Units are ANDES's: per unit on the 100 MVA system base,
angles in rad, speed in pu of the nominal frequency, time in s; the states are deviations from
the operating point.

How ANDES reduces the DAE, and how this script follows it
----------------------------------------------------------
A is ANDES's own ``EIG.As``. ``EIG.calc_As`` does, in order:
  1. fold the states with a zero time constant (Tf = 0, e.g. the LS lag of IEEEX1 with TR = 0)
     into the algebraic equations:  0 = f_z(x, y)  joins g, x_z joins y;
  2. drop "dead" algebraic variables, whose row of g_y is ~0 (row norm < EIG.config.gy_tol),
     rows and columns; a dead row with a nonzero g_x row is a state constraint 0 = C_s x;
  3. regularise algebraic variables whose column of g_y is ~0 (they appear in no algebraic
     equation) by setting their g_y diagonal to 1;
  4. A = Tf^-1 (f_x - f_y g_y^-1 g_x), then substitute the state constraints, if any.
This script redoes 1-4 in dense numpy on ANDES's Jacobians (dae.fx, fy, gx, gy, Tf), checks
that its A equals ``EIG.As`` (to 1e-9 relative) and that it keeps the same states, and applies
the same reduction to the input columns:  [B E] = Tf^-1 (f_u - f_y g_y^-1 g_u)  on the kept
states (a constraint's dependent states are dropped, as ANDES does).

The signals (as in scripts/models/kundur_andes.py)
-------------------------------------------------
  y (p = 2 n_gen)  the rotor angles delta_i (rad) of all synchronous generators (ANDES's SynGen
                   group, in its model order: GENCLS, then GENROU, each in case order), then their
                   speeds omega_i (pu): rows of I. Absolute angles, so the common-angle mode (the
                   eigenvalue at 0) stays observable.
  w (q = 2)        unknown mechanical-torque disturbances on two generators (pu torque, system
                   base): generators 2 and 3 of that order when both have a turbine governor,
                   else the first two that do; added to the governor's torque: tm_i = pout_i + w.
  u (m = n_exc)    known inputs: the voltage references vref of all exciters (Exciter group,
                   model order, then case order), pu. A case without exciters gets m = 0.

The input columns come from ANDES's residual evaluation: an input enters one algebraic
residual through a constant, and the residual sensitivities f_u, g_u are measured by a forward
difference through ``TDS.fg_update`` at the operating point, perturbing
  * the exciter's ``vref0`` by +eps (0 = vref0 - vref, the ExcBase reference equation) for B,
  * the governor's ``tm0`` by -eps (0 = ... + ue (pout - tm0), the TGBase torque interface to
    the generator's tm equation) for E: tm = pout + w, an added shaft torque.
Each perturbation must move exactly one algebraic residual, by 1 (the equations are affine in
these constants; the script checks it). E must come out as 1/M_i in the row of omega_i (swing
equation M omega' = tm - te - D (omega - 1), M = 2H on the system base); the script checks that.

Caveats (ANDES 2.0.0)
---------------------
ieee39 and wecc: their IEEEST stabilisers have A1 = ... = A6 = 0, so the filters
F1 (Lag2ndOrd) and F2 (LeadLag2ndOrd) have only zero time constants and the DAE has a higher
index there. ANDES's reduction regularises F1_x (step 3 above: F1_y' = F1_x, 0 = F1_x + u - F1_y
once the diagonal is 1), which puts an eigenvalue near +1 (+1.00..+1.03; it scales as 1/diagonal)
into A for some stabilisers, and, where a state constraint drops F1_y instead, leaves a mode at
exactly 0 (WO_x, F2_x2, LL2_x of the stabiliser) that the generators do not see. Both are
artefacts of the zero time constants, not power-system dynamics: they vanish with
``--set IEEEST.A1=0.01 --set IEEEST.A3=0.01 --set IEEEST.A4=2.5e-5`` (F1 a 10 ms lag, F2 a
double 5 ms lag), which is not the default. meta.json lists the regularised variables.

ieee14: the governor TGOV1_4 sits exactly at its lower limit VMIN at the operating point; ANDES's
Jacobian keeps its lag active (the linearisation ignores the limit), and so does A.

npcc: generators 2 and 3 (GENCLS) have no governor, so w acts on the first two governed ones,
GENCLS_11 and GENCLS_17 (the latter an equivalent machine with M = 2000); A has a slow real
unstable mode (exciters IEEEX1_3/4 with GENROU_25) that ANDES's own analysis reports as well.

Output (OUTDIR, default fixtures/andes/<name>/): A.npy, B.npy, C.npy, E.npy (float64, C order),
states.txt (ANDES's state names, spaces replaced by '_', one a line) and meta.json (case, ANDES
version, n, p, m, q, the measured states, the exciters of B's columns, the generators and
governors of E's columns, and what ANDES's reduction folded, dropped or regularised).

Run (ANDES 2.0.0, numpy 2.4.6, scipy 1.17.1 from PyPI; any working directory):

    python3 -m venv /work/andes-venv && /work/andes-venv/bin/pip install andes==2.0.0 scipy numpy
    /work/andes-venv/bin/python scripts/models/andes_case.py ieee39              # fixtures/andes/ieee39/
    /work/andes-venv/bin/python scripts/models/andes_case.py npcc /tmp/npcc --dt 0.01
    /work/andes-venv/bin/python scripts/models/andes_case.py all                 # every short name

scripts/models/andes_reference.py computes the reference values (eigenvalues, sampling, UIO
conditions, DARE) from the files written here.
"""

import argparse
import json
import os
import sys

import numpy as np
import scipy.linalg as sla

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
FIXTURES = os.path.join(ROOT, "fixtures", "andes")

CASES = {
    "kundur": "kundur/kundur_full.xlsx",
    "ieee14": "ieee14/ieee14_full.xlsx",
    "ieee39": "ieee39/ieee39_full.xlsx",
    "npcc": "npcc/npcc.xlsx",
    "wecc": "wecc/wecc_full.xlsx",
}
DISTURBED = (2, 3)   # preferred generators (1-based, SynGen order) for the unknown torques
FD_EPS = 1e-6        # forward-difference step of the residual sensitivities


def load_operating_point(case, changes=()):
    """ANDES system after power flow and small-signal analysis (which also initialises TDS).
    `changes`: (model, parameter, value) set on every device of the model (device base) first."""
    import andes

    andes.config_logger(stream_level=40)  # errors only: ANDES logs every step by default
    ss = andes.load(andes.get_case(CASES.get(case, case)), no_output=True, default_config=True)
    for model, param, value in changes:
        mdl = getattr(ss, model)
        mdl.set(param, list(mdl.idx.v), [value] * mdl.n, base="device")
    if not ss.PFlow.run():
        sys.exit(f"{case}: power flow did not converge")
    if not ss.EIG.run():
        sys.exit(f"{case}: ANDES's eigenvalue analysis failed")
    return ss, andes.__version__


def dense(m):
    import kvxopt  # ANDES's sparse matrices; a dependency of andes

    return np.array(kvxopt.matrix(m), dtype=float)


def residual_sensitivity(ss, service, index, step):
    """(f_u, g_u) of an input that shifts `service.v[index]` by `step`, by a forward difference
    through ANDES's residual evaluation at the operating point (then restored)."""
    dae = ss.dae
    ss.TDS.fg_update(ss.exist.tds)
    f0, g0 = dae.f.copy(), dae.g.copy()
    eps = FD_EPS
    service.v[index] += step * eps
    ss.TDS.fg_update(ss.exist.tds)
    fu, gu = (dae.f - f0) / eps, (dae.g - g0) / eps
    service.v[index] -= step * eps
    ss.TDS.fg_update(ss.exist.tds)
    return fu, gu


def one_residual(fu, gu, row):
    """True when the input moves exactly the algebraic residual `row`, by 1."""
    return np.abs(fu).max() < 1e-9 and np.isclose(gu[row], 1.0) and np.sum(np.abs(gu) > 1e-9) == 1


def group_members(ss, group):
    """(model, position) of every device of an ANDES group, in model order, then case order."""
    return [(mdl, i) for mdl in getattr(ss, group).models.values() for i in range(mdl.n)]


# ---------------------------------------------------------------------------------------------
# ANDES's reduction (EIG.calc_As), redone densely with input columns


class Reduction:
    """Steps 1-4 of the module docstring on dense copies of ANDES's Jacobians.

    `reduce(fu, gu)` maps residual sensitivities of the full DAE (length dae.n, dae.m) to the
    input columns of the kept states; `kept` indexes dae.x of the states A acts on."""

    def __init__(self, ss):
        dae, eig = ss.dae, ss.EIG
        tol = eig.config.gy_tol
        fx, fy, gx, gy = (dense(m) for m in (dae.fx, dae.fy, dae.gx, dae.gy))
        tf = np.asarray(dae.Tf, dtype=float).ravel()
        y_names = list(dae.y_name)

        # 1. fold the zero-Tf states into the algebraic system: rows [g; f_z], columns [y, x_z]
        zs, nz = np.flatnonzero(tf == 0), np.flatnonzero(tf != 0)
        if zs.size:
            fx, fy, gx, gy = (
                fx[np.ix_(nz, nz)],
                np.hstack([fy[nz], fx[np.ix_(nz, zs)]]),
                np.vstack([gx[:, nz], fx[np.ix_(zs, nz)]]),
                np.block([[gy, gx[:, zs]], [fy[zs], fx[np.ix_(zs, zs)]]]),
            )
            y_names += [dae.x_name[i] for i in zs]
        self.zs, self.nz = zs, nz

        # 2. dead algebraic variables: rows of g_y ~ 0; with g_x != 0 they constrain the states
        dead = np.flatnonzero(np.linalg.norm(gy, axis=1) < tol)
        coupled = dead[np.linalg.norm(gx[dead], axis=1) >= tol]
        alive = np.setdiff1d(np.arange(gy.shape[0]), dead)
        constraint = gx[coupled]
        if dead.size:
            fy, gx, gy = fy[:, alive], gx[alive], gy[np.ix_(alive, alive)]
        self.dead, self.alive = dead, alive

        # 3. regularise columns of g_y ~ 0 (variables in no algebraic equation)
        regular = np.flatnonzero(np.linalg.norm(gy, axis=0) < tol)
        gy[regular, regular] = 1.0

        self.fx, self.fy, self.gx, self.gy, self.tf = fx, fy, gx, gy, tf[nz]
        self.a_full = (fx - fy @ np.linalg.solve(gy, gx)) / self.tf[:, None]

        # 4. state constraints 0 = C_s x: ANDES's pivoting, x = R x_free
        free = np.arange(len(nz))
        self.dep = np.array([], dtype=int)
        self.a = self.a_full
        if coupled.size:
            dep, used = [], set()
            for row in np.abs(constraint):
                pivot = next(int(j) for j in np.argsort(-row) if j not in used and row[j] > 0)
                dep.append(pivot)
                used.add(pivot)
            free = np.setdiff1d(free, dep)
            r = np.zeros((len(nz), len(free)))
            r[free, np.arange(len(free))] = 1.0
            r[dep] = -np.linalg.solve(constraint[:, dep], constraint[:, free])
            self.a = self.a_full[free] @ r
        self.dep = nz[sorted(set(range(len(nz))) - set(free.tolist()))]
        self.free = free
        self.kept = nz[free]

        self.info = {
            "zero_tf_states_folded": [dae.x_name[i].replace(" ", "_") for i in zs],
            "dead_algebraic_dropped": [y_names[i].replace(" ", "_") for i in dead],
            "state_constraints": int(coupled.size),
            "constrained_states_dropped": [dae.x_name[i].replace(" ", "_") for i in self.dep],
            "regularised_columns": [y_names[alive[j]].replace(" ", "_") for j in regular],
        }
        self.y_names = y_names

    def reduce(self, fu, gu):
        if self.zs.size:
            fu, gu = fu[self.nz], np.concatenate([gu, fu[self.zs]])
        # an input acting on a dropped equation would be lost
        assert np.abs(gu[self.dead]).max(initial=0.0) < 1e-9, "input enters a dead equation"
        if self.dead.size:
            gu = gu[self.alive]
        return ((fu - self.fy @ np.linalg.solve(self.gy, gu)) / self.tf)[self.free]


# ---------------------------------------------------------------------------------------------


def choose_disturbed(gens, governor_of, wanted=DISTURBED):
    """Generator positions (0-based in `gens`) for the unknown torques: `wanted` when all have a
    governor, else the first len(wanted) that do."""
    picks = [g - 1 for g in wanted]
    if all(0 <= i < len(gens) and governor_of(i) is not None for i in picks):
        return picks
    governed = [i for i in range(len(gens)) if governor_of(i) is not None]
    if len(governed) < len(wanted):
        sys.exit(f"only {len(governed)} generators have a turbine governor")
    return governed[:len(wanted)]


def linearise(ss, wanted=DISTURBED):
    """A, B, C, E, state names and a description of the signals (for meta.json)."""
    dae, eig = ss.dae, ss.EIG
    red = Reduction(ss)

    a = np.array(eig.As, dtype=float)
    assert a.shape == red.a.shape, f"ANDES's As is {a.shape}, the reduction gives {red.a.shape}"
    err = np.abs(a - red.a).max() / np.abs(a).max()
    assert err <= 1e-9, f"ANDES's As differs from the dense reduction by {err:.2g} (relative)"
    assert list(eig.x_name) == [dae.x_name[i] for i in red.kept], "the kept states differ"
    row_of = {int(x): k for k, x in enumerate(red.kept)}   # dae.x address -> row of A

    gens = group_members(ss, "SynGen")
    gen_pos = {mdl.idx.v[i]: k for k, (mdl, i) in enumerate(gens)}
    govs = {}
    for mdl, i in group_members(ss, "TurbineGov"):
        govs.setdefault(gen_pos[mdl.syn.v[i]], (mdl, i))

    # B: exciter voltage references
    cols_b, exciters = [], []
    for mdl, i in group_members(ss, "Exciter"):
        fu, gu = residual_sensitivity(ss, mdl.vref0, i, +1.0)
        assert one_residual(fu, gu, mdl.vref.a[i]), f"{mdl.class_name} {mdl.idx.v[i]}: vref0 is not an offset of one equation"
        cols_b.append(red.reduce(fu, gu))
        exciters.append({"model": mdl.class_name, "idx": str(mdl.idx.v[i]), "generator": str(mdl.syn.v[i])})

    # E: torque added at the governor-generator interface
    cols_e, disturbed = [], []
    for k in choose_disturbed(gens, govs.get, wanted):
        gm, gi = gens[k]
        mdl, i = govs[k]
        fu, gu = residual_sensitivity(ss, mdl.tm0, i, -1.0)
        assert one_residual(fu, gu, gm.tm.a[gi]), f"{mdl.class_name} {mdl.idx.v[i]}: tm0 is not an offset of the torque equation"
        col = red.reduce(fu, gu)
        # the swing equation: 1/M in the row of omega, nothing elsewhere
        swing = np.zeros_like(col)
        swing[row_of[gm.omega.a[gi]]] = 1.0 / gm.M.v[gi]
        assert np.allclose(col, swing, rtol=1e-9, atol=1e-12), f"E column of {gm.idx.v[gi]} is not 1/M in the omega row"
        cols_e.append(col)
        disturbed.append({"generator": str(gm.idx.v[gi]), "position": k + 1, "model": gm.class_name,
                          "governor": f"{mdl.class_name} {mdl.idx.v[i]}",
                          "state": dae.x_name[gm.omega.a[gi]].replace(" ", "_"), "M": float(gm.M.v[gi])})

    n = a.shape[0]
    b = np.column_stack(cols_b) if cols_b else np.zeros((n, 0))
    e = np.column_stack(cols_e)
    names = [s.replace(" ", "_") for s in eig.x_name]
    rows = [row_of[mdl.delta.a[i]] for mdl, i in gens] + [row_of[mdl.omega.a[i]] for mdl, i in gens]
    c = np.eye(n)[rows]
    meta = {
        "n": n, "p": len(rows), "m": b.shape[1], "q": e.shape[1],
        "measured": [names[r] for r in rows],
        "measured_rows_of_x": rows,
        "generators": [f"{mdl.class_name} {mdl.idx.v[i]}" for mdl, i in gens],
        "known_inputs": exciters,
        "unknown_inputs": disturbed,
        "andes_reduction": red.info,
        "andes_states_full": int(dae.n),
        "andes_algebraic": int(dae.m),
    }
    return a, b, c, e, names, meta


def write(out, a, b, c, e, names, meta):
    os.makedirs(out, exist_ok=True)
    for key, m in dict(A=a, B=b, C=c, E=e).items():
        np.save(os.path.join(out, f"{key}.npy"), np.ascontiguousarray(m, dtype=np.float64))
    with open(os.path.join(out, "states.txt"), "w") as fh:
        fh.write("\n".join(names) + "\n")
    with open(os.path.join(out, "meta.json"), "w") as fh:
        json.dump(meta, fh, indent=1)
        fh.write("\n")


def summary(a, b, c, e, meta, dt):
    lam = np.linalg.eigvals(a)
    red = meta["andes_reduction"]
    print(f"  n = {meta['n']}, p = {meta['p']}, m = {meta['m']}, q = {meta['q']}; ANDES reduction: "
          f"{len(red['zero_tf_states_folded'])} zero-Tf states folded, {len(red['dead_algebraic_dropped'])} dead "
          f"algebraic dropped, {len(red['regularised_columns'])} columns regularised, {red['state_constraints']} constraints")
    print(f"  eig(A): Re in [{lam.real.min():.6g}, {lam.real.max():.6g}], "
          f"{np.sum(lam.real >= -1e-6)} with Re >= -1e-6, max |lambda| = {np.abs(lam).max():.6g}")
    if red["regularised_columns"]:
        print(f"  note: regularised (in no algebraic equation): {', '.join(red['regularised_columns'])}")
    n, q = a.shape[0], e.shape[1]
    big = np.zeros((n + q, n + q))
    big[:n, :n], big[:n, n:] = a, e
    ge = sla.expm(big * dt)[:n, n:]
    print(f"  dt = {dt}: rank(C Gamma_E) = {np.linalg.matrix_rank(c @ ge)} (q = {q})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("case", help=f"one of {', '.join(CASES)}, 'all', or an ANDES case path")
    ap.add_argument("outdir", nargs="?", help="output folder (default: fixtures/andes/<case>)")
    ap.add_argument("--dt", type=float, default=0.01, help="sample time of the printed check")
    ap.add_argument("--set", action="append", default=[], metavar="MODEL.PARAM=VALUE",
                    help="set a parameter of every device of a model before the power flow (repeatable)")
    args = ap.parse_args()
    try:
        changes = [(lhs.split(".")[0], lhs.split(".")[1], float(rhs))
                   for lhs, rhs in (item.split("=") for item in args.set)]
    except (ValueError, IndexError):
        ap.error("--set takes MODEL.PARAM=VALUE")
    if args.case == "all" and args.outdir:
        ap.error("'all' writes to fixtures/andes/<case>/; give no OUTDIR")
    for case in (CASES if args.case == "all" else [args.case]):
        ss, version = load_operating_point(case, changes)
        a, b, c, e, names, meta = linearise(ss)
        name = case if case in CASES else os.path.splitext(os.path.basename(case))[0]
        meta = {"case": CASES.get(case, case), "andes_version": version,
                "parameter_changes": [f"{m}.{p}={v!r}" for m, p, v in changes], **meta}
        out = args.outdir or os.path.join(FIXTURES, name)
        print(f"ANDES {version}, case {meta['case']}: {len(names)} states")
        summary(a, b, c, e, meta, args.dt)
        write(out, a, b, c, e, names, meta)
        print(f"  wrote A.npy, B.npy, C.npy, E.npy, states.txt, meta.json to {out}")


if __name__ == "__main__":
    main()
