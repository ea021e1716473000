"""The test FMUs of fmu/testfmus, run by FMPy — an FMI
importer independent of this repository — against references computed here with numpy/scipy.

* lti_plant (FMI 2.0 and 3.0 co-simulation): Φ, Γ_B, Γ_E from one `scipy.linalg.expm` of
  [[A, B, E], [0, 0, 0]]·dt for scenarios/seed002-piecewise.toml, C and x0 from the scenario;
  a few hundred doSteps with piecewise-constant u and w must give x and y bit for bit equal to
  a Python loop with the FMU's documented summation order, and FMI 2 and FMI 3 the same bits.
  A doStep with another step size than the first is refused (fmi2Error / fmi3Error).
* dc_motor (FMI 2.0 and 3.0): a voltage step and a load torque step; the states at the
  communication points within 1e-6 of `scipy.integrate.solve_ivp` (rtol 1e-10, atol 1e-12) of
  the same ODE, and FMI 2 and FMI 3 the same bits.

The FMUs come from $UIO_TEST_FMUS (scripts/test.sh builds them there) when all four are there
and newer than their sources; otherwise this module builds them with fmu/testfmus/build.sh into
a temporary directory.
"""

import os
import subprocess
import sys
import tomllib

import fmpy
import numpy as np
import pytest
import scipy.linalg as sla
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from scipy.integrate import solve_ivp

from conftest import REPO

SOURCES = os.path.join(REPO, "fmu", "testfmus")
NAMES = [f"{model}_fmi{v}" for model in ("lti_plant", "dc_motor", "faulty") for v in (2, 3)] + ["three_tank"]
SCENARIO = os.path.join(REPO, "scenarios", "seed002-piecewise.toml")


@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory):
    """A directory with the up-to-date test FMUs (each model in FMI 2.0 and 3.0)."""
    built = os.environ.get("UIO_TEST_FMUS")
    newest_source = max(os.path.getmtime(os.path.join(SOURCES, f)) for f in os.listdir(SOURCES))
    if built and all(
        os.path.isfile(p := os.path.join(built, f"{n}.fmu")) and os.path.getmtime(p) >= newest_source
        for n in NAMES
    ):
        return built
    out = tmp_path_factory.mktemp("testfmus")
    done = subprocess.run(
        ["bash", os.path.join(SOURCES, "build.sh"), str(out)],
        env={**os.environ, "PYTHON": sys.executable},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, f"build.sh exited {done.returncode}: {done.stdout}{done.stderr}"
    return str(out)


class Slave:
    """One instance of an FMU through FMPy's FMU2Slave / FMU3Slave, by variable name."""

    def __init__(self, fmu_dir, name, unzip_dir):
        path = os.path.join(fmu_dir, f"{name}.fmu")
        self.md = fmpy.read_model_description(path, validate=True)
        self.fmi = int(self.md.fmiVersion[0])
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.start = {v.name: float(v.start) for v in self.md.modelVariables if v.start is not None}
        unzip = fmpy.extract(path, unzipdir=str(unzip_dir / name))
        common = dict(unzipDirectory=unzip, modelIdentifier=self.md.coSimulation.modelIdentifier,
                      instanceName=name)
        if self.fmi == 2:
            self.fmu = FMU2Slave(guid=self.md.guid, **common)
        else:
            self.fmu = FMU3Slave(guid=self.md.instantiationToken, **common)
        self.fmu.instantiate()

    def initialize(self, parameters):
        self.set(parameters)
        if self.fmi == 2:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=0.0)
        self.fmu.exitInitializationMode()

    def set(self, values):
        vrs, vals = [self.vr[n] for n in values], [float(v) for v in values.values()]
        (self.fmu.setReal if self.fmi == 2 else self.fmu.setFloat64)(vrs, vals)

    def get(self, names):
        vrs = [self.vr[n] for n in names]
        return (self.fmu.getReal if self.fmi == 2 else self.fmu.getFloat64)(vrs)

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


# ---- lti_plant ----------------------------------------------------------------------------


def seed002_zoh():
    """Φ, Γ_B, Γ_E (exact ZOH), C, x0 and dt of scenarios/seed002-piecewise.toml."""
    with open(SCENARIO, "rb") as f:
        sc = tomllib.load(f)
    plant = sc["plant"]
    A, B, C, E = (np.array(plant[k], dtype=float) for k in ("A", "B", "C", "E"))
    n, l, q = A.shape[0], B.shape[1], E.shape[1]
    assert (n, l, q, C.shape[0]) == (3, 2, 1, 2)
    M = np.zeros((n + l + q, n + l + q))
    M[:n, :n], M[:n, n:n + l], M[:n, n + l:] = A, B, E
    F = sla.expm(M * sc["dt"])
    return F[:n, :n], F[:n, n:n + l], F[:n, n + l:], C, np.array(plant["x0"], dtype=float), sc["dt"]


def lti_parameters(Phi, GB, GE, C, x0=None):
    """lti_plant's parameters and, with `x0`, its states' start values (x1..x3, initial exact)."""
    p = {}
    for name, m in (("Phi", Phi), ("Gamma_B", GB), ("Gamma_E", GE), ("C", C)):
        p.update({f"{name}_{i + 1}_{j + 1}": m[i, j] for i in range(m.shape[0]) for j in range(m.shape[1])})
    if x0 is not None:
        p.update({f"x{i + 1}": v for i, v in enumerate(x0)})
    return p


def lti_inputs(steps):
    """Piecewise-constant u (2 channels) and w (1 channel), new values every 37 samples."""
    rng = np.random.default_rng(22)
    levels = rng.uniform(-2.0, 2.0, size=(steps // 37 + 1, 3))
    return np.repeat(levels, 37, axis=0)[:steps]


def lti_reference(Phi, GB, GE, C, x0, inputs):
    """x_k and y_k = C x_k, k = 0..steps, with lti_plant.c's summation order, in Python floats
    (IEEE double, no fused multiply-add)."""
    n, l = Phi.shape[0], GB.shape[1]
    Phi, GB, GE, C = Phi.tolist(), GB.tolist(), GE.tolist(), C.tolist()

    def output(x):
        ys = []
        for row in C:
            acc = 0.0
            for j in range(n):
                acc += row[j] * x[j]
            ys.append(acc)
        return ys

    x = [float(v) for v in x0]
    xs, ys = [x], [output(x)]
    for uw in inputs.tolist():
        u, w = uw[:l], uw[l:]
        new = []
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Phi[i][j] * x[j]
            for j in range(l):
                acc += GB[i][j] * u[j]
            for j in range(len(w)):
                acc += GE[i][j] * w[j]
            new.append(acc)
        x = new
        xs.append(x)
        ys.append(output(x))
    return np.array(xs), np.array(ys)


def run_lti(fmu_dir, name, tmp_path, inputs):
    Phi, GB, GE, C, x0, dt = seed002_zoh()
    s = Slave(fmu_dir, name, tmp_path)
    s.initialize(lti_parameters(Phi, GB, GE, C, x0))
    xs, ys = [s.get(["x1", "x2", "x3"])], [s.get(["y1", "y2"])]
    for k, (u1, u2, w1) in enumerate(inputs):
        s.set({"u1": u1, "u2": u2, "w1": w1})
        s.fmu.doStep(k * dt, dt)
        xs.append(s.get(["x1", "x2", "x3"]))
        ys.append(s.get(["y1", "y2"]))
    s.close()
    return np.array(xs), np.array(ys)


def test_lti_plant_bit_for_bit(fmu_dir, tmp_path):
    inputs = lti_inputs(400)
    Phi, GB, GE, C, x0, _ = seed002_zoh()
    x_ref, y_ref = lti_reference(Phi, GB, GE, C, x0, inputs)
    assert np.ptp(x_ref, axis=0).min() > 1e-3  # every state moves: the check is not vacuous
    runs = {}
    for name in ("lti_plant_fmi2", "lti_plant_fmi3"):
        x, y = runs[name] = run_lti(fmu_dir, name, tmp_path, inputs)
        assert x.shape == x_ref.shape and y.shape == y_ref.shape
        assert np.array_equal(x, x_ref), f"{name}: x differs, max {np.abs(x - x_ref).max():.3g}"
        assert np.array_equal(y, y_ref), f"{name}: y differs, max {np.abs(y - y_ref).max():.3g}"
    (x2, y2), (x3, y3) = runs["lti_plant_fmi2"], runs["lti_plant_fmi3"]
    assert np.array_equal(x2, x3) and np.array_equal(y2, y3), "FMI 2 and FMI 3 builds differ"


@pytest.mark.parametrize("name", ["lti_plant_fmi2", "lti_plant_fmi3"])
def test_lti_plant_refuses_another_step_size(fmu_dir, tmp_path, name):
    Phi, GB, GE, C, x0, dt = seed002_zoh()
    s = Slave(fmu_dir, name, tmp_path)
    s.initialize(lti_parameters(Phi, GB, GE, C, x0))
    s.set({"u1": 1.0, "u2": -1.0, "w1": 0.5})
    s.fmu.doStep(0.0, dt)
    after_one = s.get(["x1", "x2", "x3"])
    with pytest.raises(FMICallException) as refused:
        s.fmu.doStep(dt, 2 * dt)
    assert refused.value.status == 3  # fmi2Error / fmi3Error
    assert refused.value.function == f"fmi{s.fmi}DoStep"
    assert s.get(["x1", "x2", "x3"]) == after_one  # the refused step changed nothing
    s.fmu.doStep(dt, dt)  # the sample period still works
    assert s.get(["x1", "x2", "x3"]) != after_one
    s.close()


# ---- dc_motor -----------------------------------------------------------------------------

DC_DT, DC_STEPS = 0.01, 300
VOLTAGE_ON, LOAD_ON = 10, 150  # sample indices of the voltage step (12 V) and load step (0.2 N m)


def dc_inputs(k):
    return 12.0 if k >= VOLTAGE_ON else 0.0, 0.2 if k >= LOAD_ON else 0.0


def dc_reference(p):
    """(i, ω, θ) at the communication points: solve_ivp of the motor ODE, one solve per
    stretch of constant inputs."""

    def f(_t, x, u1, w1):
        i, omega, _theta = x
        return [
            (-p["R"] * i - p["K"] * omega + u1) / p["L"],
            (p["K"] * i - p["b"] * omega - p["tau_c"] * np.tanh(omega / p["omega_s"]) - w1) / p["J"],
            omega,
        ]

    xs, x = [np.zeros(3)], np.zeros(3)
    for a, b in ((0, VOLTAGE_ON), (VOLTAGE_ON, LOAD_ON), (LOAD_ON, DC_STEPS)):
        t = np.arange(a, b + 1) * DC_DT
        sol = solve_ivp(f, (t[0], t[-1]), x, method="DOP853", t_eval=t, args=dc_inputs(a),
                        rtol=1e-10, atol=1e-12)
        assert sol.success, sol.message
        xs.extend(sol.y.T[1:])
        x = sol.y[:, -1]
    return np.array(xs)


def run_dc(fmu_dir, name, tmp_path):
    s = Slave(fmu_dir, name, tmp_path)
    params = {n: s.start[n] for n in ("R", "L", "K", "J", "b", "tau_c", "omega_s", "substeps")}
    assert params["substeps"] == 10
    s.initialize({})  # the defaults of modelDescription.xml
    xs = [s.get(["x1", "x2", "x3"])]
    y_is_state = []
    for k in range(DC_STEPS):
        u1, w1 = dc_inputs(k)
        s.set({"u1": u1, "w1": w1})
        s.fmu.doStep(k * DC_DT, DC_DT)
        xs.append(s.get(["x1", "x2", "x3"]))
        y_is_state.append(s.get(["y1", "y2"]) == xs[-1][1:])
    s.close()
    assert all(y_is_state), "y = (omega, theta) must be x2, x3"
    return params, np.array(xs)


def test_dc_motor_against_solve_ivp(fmu_dir, tmp_path):
    runs = {name: run_dc(fmu_dir, name, tmp_path) for name in ("dc_motor_fmi2", "dc_motor_fmi3")}
    params, x2 = runs["dc_motor_fmi2"]
    ref = dc_reference(params)
    # Not vacuous: the motor spins up, and the load torque slows it down.
    assert ref[LOAD_ON, 1] > 8.0 and ref[-1, 1] < ref[LOAD_ON, 1] - 2.0
    for name, (_, x) in runs.items():
        diff = np.abs(x - ref).max(axis=0)
        print(f"{name}: max |FMU - solve_ivp| for (i, omega, theta) = {diff}")
        assert diff[1] < 1e-6, f"{name}: omega differs from solve_ivp by {diff[1]:.3g}"
        assert diff.max() < 1e-6, f"{name}: a state differs from solve_ivp by {diff.max():.3g}"
    assert np.array_equal(x2, runs["dc_motor_fmi3"][1]), "FMI 2 and FMI 3 builds differ"
