"""`uio-launcher linearize`: the sampled model of an FMU plant at an operating
point, made from the FMU itself (trim by Newton's method on the one-sample map, central
differences with Richardson's extrapolation), checked against independent numbers:

* on the linear test FMU (FMI 2.0 and 3.0) it returns the Φ, Γ_B, Γ_E and C the FMU was given,
  to 1e-9 relative, at random operating points;
* on the nonlinear DC-motor FMU at a non-zero operating point it matches scipy's exact
  discretisation of the analytic Jacobian of the motor's equations to 1e-6, and the trim finds
  the speed and current the voltage holds and names the shaft angle as a free integrator;
* on the pythonfmu three-tank FMU it trims to the levels a numpy root finder gives, and the
  scenario it writes runs as is: a UIO designed from it follows the leak, in absolute units.
"""

import os
import shutil
import subprocess

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.optimize as so

from conftest import REPO
from test_diagnosis_scipy import launcher
from test_fmu_plant import num, run, table, export_csv
from test_fmu_pythonfmu import AREA, AZ, G, SN, f as tank_f  # noqa: F401
from test_fmu_testfmus import fmu_dir, lti_parameters  # noqa: F401 (fixture)


def linearize(scenario, out, *extra):
    done = subprocess.run([launcher(), "linearize", str(scenario), "--out", str(out), *extra],
                          capture_output=True, text=True, timeout=300)
    return done


def vec(v):
    return "[" + ", ".join(num(x) for x in v) + "]"


@pytest.mark.parametrize("v", [2, 3])
def test_the_linear_fmu_gives_back_its_own_matrices(fmu_dir, tmp_path, v):
    rng = np.random.default_rng(31 + v)
    Phi = rng.normal(size=(3, 3)) * 0.4
    GB, GE, C = rng.normal(size=(3, 2)), rng.normal(size=(3, 1)), rng.normal(size=(2, 3))
    params = ", ".join(f"{k} = {num(x)}" for k, x in lti_parameters(Phi, GB, GE, C).items())
    x, u, w = rng.uniform(-3, 3, 3), rng.uniform(-3, 3, 2), rng.uniform(-3, 3, 1)
    (tmp_path / "lti.toml").write_text(f"""name = "lti"
dt = 0.1
[plant.operating_point]
x = {vec(x)}
u = {vec(u)}
w = {vec(w)}
[plant.fmu]
path = "{os.path.join(fmu_dir, f'lti_plant_fmi{v}.fmu')}"
inputs = ["u1", "u2"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]
parameters = {{ {params} }}
""")
    done = linearize(tmp_path / "lti.toml", tmp_path / "out")
    assert done.returncode == 0, done.stderr
    print(done.stdout)
    got = {k: np.load(tmp_path / "out" / f"{k}.npy") for k in ("Phi", "Gamma_B", "Gamma_E", "C")}
    for k, want in (("Phi", Phi), ("Gamma_B", GB), ("Gamma_E", GE), ("C", C)):
        rel = np.abs(got[k] - want).max() / np.abs(want).max()
        print(f"FMI {v}: {k} relative error {rel:.2e}")
        assert got[k].shape == want.shape and rel <= 1e-9, (k, rel)


def test_the_dc_motor_fmu_matches_the_analytic_jacobian_at_a_nonzero_operating_point(fmu_dir, tmp_path):
    R, L, K, J, b, tau_c, omega_s = 2.0, 0.5, 0.1, 0.02, 0.05, 0.01, 0.05  # dc_motor.c's defaults
    u, w, dt = 12.0, 0.02, 0.01
    (tmp_path / "dc.toml").write_text(f"""name = "dc"
dt = {dt}
[plant.operating_point]
x = [1.0, 5.0, 0.3]     # the trim's first guess
u = [{u}]
w = [{w}]
[plant.fmu]
path = "{os.path.join(fmu_dir, 'dc_motor_fmi2.fmu')}"
inputs = ["u1"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]
""")
    done = linearize(tmp_path / "dc.toml", tmp_path / "out", "--trim")
    assert done.returncode == 0, done.stderr
    print(done.stdout)
    # The equilibrium of (i, ω) for this voltage and load, by scipy; θ turns freely.
    def f2(v):
        i, om = v
        return [(-R * i - K * om + u) / L, (K * i - b * om - tau_c * np.tanh(om / omega_s) - w) / J]
    i_op, om_op = so.fsolve(f2, [1.0, 5.0], xtol=1e-14)
    import tomllib
    sc = tomllib.loads((tmp_path / "out" / "dc.toml").read_text())
    x_op = np.array(sc["plant"]["operating_point"]["x"])
    assert abs(x_op[0] - i_op) < 1e-9 and abs(x_op[1] - om_op) < 1e-9 and x_op[2] == 0.3, (x_op, i_op, om_op)
    assert "not unique: Φ − I is singular along x3" in done.stdout
    # The analytic Jacobian there, discretised exactly (ZOH) by scipy.
    sech2 = 1.0 / np.cosh(om_op / omega_s) ** 2
    A = np.array([[-R / L, -K / L, 0.0], [K / J, (-b - tau_c * sech2 / omega_s) / J, 0.0], [0.0, 1.0, 0.0]])
    B, E = np.array([[1 / L], [0.0], [0.0]]), np.array([[0.0], [-1 / J], [0.0]])
    M = np.zeros((5, 5))
    M[:3, :3], M[:3, 3:4], M[:3, 4:5] = A, B, E
    F = sla.expm(M * dt)
    for k, want in (("Phi", F[:3, :3]), ("Gamma_B", F[:3, 3:4]), ("Gamma_E", F[:3, 4:5])):
        got = np.load(tmp_path / "out" / f"{k}.npy")
        rel = np.abs(got - want).max() / np.abs(want).max()
        print(f"dc_motor: {k} relative to the analytic model {rel:.2e}")
        assert rel <= 1e-6, (k, rel)
    assert np.array_equal(np.load(tmp_path / "out" / "C.npy"), [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def test_the_c_dc_motor_fmu_linearised_runs_under_a_uio_whose_load_estimate_follows(fmu_dir, tmp_path):
    """This repository's C DC-motor FMU (Coulomb friction τ_c tanh(ω/ω_s), steepest at rest)
    trimmed where it holds a 0.02 N·m load at stall (u_op = R w_op/K = 0.4 V, i_op = 0.2 A,
    ω_op = 0), linearised, and the scenario linearize writes run as is: after a load step to
    0.025 N·m its Chen–Patton UIO's ŵ settles where the linear model puts it — the w that
    explains the measured speed, w_op − (K²/R + b + τ_c/ω_s) δω (numpy, from the run's ω) — to
    1e-6 of the step. How far that is from the true load is the linearisation's error: the
    friction saturates over the speed the step costs; both are printed."""
    R, K, b, tau_c, omega_s = 2.0, 0.1, 0.05, 0.01, 0.05  # dc_motor.c's defaults
    w0, w1, dt = 0.02, 0.025, 0.01
    u = R * w0 / K
    (tmp_path / "dc.toml").write_text(f"""name = "dc"
dt = {dt}
duration = 30.0
[plant.operating_point]
x = [0.25, 0.01, 0.0]    # the trim's first guess
u = [{u}]
w = [{w0}]
[plant.fmu]
path = "{os.path.join(fmu_dir, 'dc_motor_fmi2.fmu')}"
inputs = ["u1"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]

[[input]]
kind = "constant"
value = {u}

[[disturbance]]
kind = "step"
time = 5.0
before = {w0}
after = {w1}

[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [-20.0, -30.0, -40.0]   # the written scenario is discrete: (TΦ, C) takes all three
""")
    done = linearize(tmp_path / "dc.toml", tmp_path / "lin", "--trim")
    assert done.returncode == 0, done.stderr
    import tomllib
    x_op = np.array(tomllib.loads((tmp_path / "lin" / "dc.toml").read_text())["plant"]["operating_point"]["x"])
    assert abs(x_op[0] - w0 / K) < 1e-9 and abs(x_op[1]) < 1e-9, x_op
    # No x0 in the source: the written scenario starts at rest at the point, not at the FMU's 0.
    assert tomllib.loads((tmp_path / "lin" / "dc.toml").read_text())["plant"]["x0"] == list(x_op)
    p, _ = run(tmp_path / "lin" / "dc.toml", tmp_path / "out", tmp_path / "runs")
    assert p.returncode == 0, p.stderr_text
    csvs = export_csv(tmp_path / "out" / "dc.rrd", tmp_path / "csv")
    W, Wh, X = table(csvs / "disturbance.csv"), table(csvs / "observer_uio_what.csv"), table(csvs / "plant_x.csv")
    before, tail = slice(100, 500), slice(2500, len(Wh))
    e_before = np.abs(Wh[before] - w0).max()
    # The linear model's steady state: δi = −K δω / R, 0 = K δi − (b + τ_c/ω_s) δω − δw.
    w_linear = w0 - (K * K / R + b + tau_c / omega_s) * X[tail, 1]
    gap = np.abs(Wh[tail, 0] - w_linear).max()
    off = np.abs(Wh[tail, 0] - w1).max()
    print(f"dc_motor from launcher linearize: ŵ at rest off by {e_before:.2e}; after the step ŵ − the linear model's w "
          f"{gap:.2e}, ŵ − the true load {off:.2e} N·m of a {w1 - w0} step (ω settles at {X[-1, 1]:.3e} rad/s, ω_s = {omega_s})")
    assert e_before <= 1e-9 and gap <= 1e-6 * (w1 - w0), (e_before, gap)


def test_the_python_fmu_is_trimmed_linearised_and_its_scenario_runs_under_a_uio(fmu_dir, tmp_path):
    shutil.copy(os.path.join(fmu_dir, "three_tank.fmu"), tmp_path)
    Q1, Q2 = 3.5e-5, 1.45e-5
    # The README's worked example: the scenario shipped beside the FMU's source.
    shutil.copy(os.path.join(REPO, "fmu", "testfmus", "python", "three-tank.toml"), tmp_path / "tank.toml")
    done = linearize(tmp_path / "tank.toml", tmp_path / "lin", "--trim")
    assert done.returncode == 0, done.stderr
    print(done.stdout)
    h_op = so.fsolve(lambda h: tank_f(h, [Q1, Q2], [0.0]), [0.45, 0.25, 0.33], xtol=1e-14)
    import tomllib
    sc = tomllib.loads((tmp_path / "lin" / "three-tank.toml").read_text())
    x_op = np.array(sc["plant"]["operating_point"]["x"])
    print(f"trim {x_op} against scipy {h_op}")
    # RK4 with 20 substeps of 50 ms holds the levels where the exact equilibrium is, to ~1e-9.
    assert np.abs(x_op - h_op).max() < 1e-8
    p, _ = run(tmp_path / "lin" / "three-tank.toml", tmp_path / "out", tmp_path / "runs")
    assert p.returncode == 0, p.stderr_text
    csvs = export_csv(tmp_path / "out" / "three-tank.rrd", tmp_path / "csv")
    X, Xh = table(csvs / "plant_x.csv"), table(csvs / "observer_uio_xhat.csv")
    W, Wh = table(csvs / "disturbance.csv"), table(csvs / "observer_uio_what.csv")
    W = W[:len(Wh)]
    tail = slice(450, None)
    e, ew = np.abs(X[tail] - Xh[tail]).max(), np.abs(W[tail] - Wh[tail]).max()
    print(f"three_tank from launcher linearize: tail max|x − x̂| {e:.3e} m, max|w − ŵ| {ew:.3e} m3/s (leak 5e-6)")
    assert np.abs(Xh[tail] - x_op).max() < 0.05 and e < 1e-3 and ew < 0.1 * 5e-6


def test_the_python_fmus_run_and_the_same_run_in_deviations_by_hand_give_the_same_observer(fmu_dir, tmp_path):
    """The pythonfmu three-tank run at its operating point (the scenario `uio-launcher linearize`
    wrote, absolute levels recorded) and the same data written in deviations by hand — every
    recorded u, w, x and y less its value at the point, replayed through the same (Φ, Γ_B, Γ_E,
    C) without an operating point — give the same observer: x̂ − x_op and ŵ − w_op equal the
    by-hand x̂ and ŵ to rounding."""
    import tomllib
    shutil.copy(os.path.join(fmu_dir, "three_tank.fmu"), tmp_path)
    shutil.copy(os.path.join(REPO, "fmu", "testfmus", "python", "three-tank.toml"), tmp_path / "tank.toml")
    assert linearize(tmp_path / "tank.toml", tmp_path / "lin", "--trim").returncode == 0
    written = tmp_path / "lin" / "three-tank.toml"
    p, _ = run(written, tmp_path / "out", tmp_path / "runs")
    assert p.returncode == 0, p.stderr_text
    csvs = export_csv(tmp_path / "out" / "three-tank.rrd", tmp_path / "csv")
    sc = tomllib.loads(written.read_text())
    op = sc["plant"]["operating_point"]
    x_op, u_op, w_op, y_op = (np.array(op[k]) for k in "xuwy")
    X, Y, U, W = (table(csvs / f) for f in ("plant_x.csv", "plant_y.csv", "input.csv", "disturbance.csv"))
    k = min(map(len, (X, Y, U, W)))
    log = tmp_path / "lin" / "deviations.csv"
    with open(log, "w") as f:
        f.write("t,Q1,Q2,leak,h1,h2,h3,y1,y2,y3\n")
        for i in range(k):
            row = (i * sc["dt"], *(U[i] - u_op), *(W[i] - w_op), *(X[i] - x_op), *(Y[i] - y_op))
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    text = "".join(line for line in written.read_text().splitlines(keepends=True) if not line.startswith("#"))
    text = text[:text.index("[[disturbance]]")] + text[text.index("[[observer]]"):]
    text = text[:text.index("[plant.fmu]")] + """[plant.replay]
path = "deviations.csv"
time = "t"
inputs = ["Q1", "Q2"]
disturbances = ["leak"]
states = ["h1", "h2", "h3"]
outputs = ["y1", "y2", "y3"]
"""
    text = text.replace('name = "three-tank"', 'name = "by-hand"').replace(f"duration = {sc['duration']}", f"duration = {(k - 1) * sc['dt']}")
    text = text.replace("x0 = " + repr(sc["plant"]["x0"]).replace("'", ""), "x0 = " + vec(np.array(sc["plant"]["x0"]) - x_op))
    assert "operating_point" not in text and "[plant.fmu]" not in text and "x0 = [0.4, 0.2, 0.3]" not in text
    hand = tmp_path / "lin" / "by-hand.toml"
    hand.write_text(text)
    p, _ = run(hand, tmp_path / "hand", tmp_path / "runs")
    assert p.returncode == 0, p.stderr_text
    hcsv = export_csv(tmp_path / "hand" / "by-hand.rrd", tmp_path / "hcsv")
    Xh, Wh = table(csvs / "observer_uio_xhat.csv"), table(csvs / "observer_uio_what.csv")
    Dh, DWh = table(hcsv / "observer_uio_xhat.csv"), table(hcsv / "observer_uio_what.csv")
    n, m = min(len(Xh), len(Dh)), min(len(Wh), len(DWh))
    gx = np.abs(Xh[:n] - x_op - Dh[:n]).max()
    gw = np.abs(Wh[:m] - w_op - DWh[:m]).max()
    print(f"three_tank at its point vs in deviations by hand: max|Δx̂| {gx:.2e} m (levels ~0.4 m), max|Δŵ| {gw:.2e} m3/s (leak 5e-6)")
    assert n >= 590 and gx <= 1e-13 and gw <= 1e-9 * 5e-6, (gx, gw)


def test_a_scenario_name_that_is_not_a_file_stem_is_refused_before_anything_is_written(fmu_dir, tmp_path):
    (tmp_path / "bad.toml").write_text(f"""name = "../../escaped"
dt = 0.1
[plant.operating_point]
x = [0.0, 0.0, 0.0]
[plant.fmu]
path = "{os.path.join(fmu_dir, 'dc_motor_fmi2.fmu')}"
inputs = ["u1"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]
""")
    done = linearize(tmp_path / "bad.toml", tmp_path / "out")
    assert done.returncode == 2, done.stderr
    assert "name" in done.stderr and "letters, digits" in done.stderr, done.stderr
    assert not (tmp_path / "out").exists() and not (tmp_path.parent / "escaped.toml").exists()
