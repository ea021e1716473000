"""FMUs as a third-party exporter makes them: pythonfmu (PyPI) builds
fmu/testfmus/python/three_tank.py into an FMI 2.0 co-simulation FMU whose library embeds Python
and leaves libpython's symbols to its host.

* It runs as the plant of a run, at its operating point, in absolute units: the FMU plant loads
  the libpython of the `python3` on PATH and hands it that python's sys.path (the model imports
  numpy from this virtual environment); FMPy, an importer that is not ours, steps the same FMU
  with the recorded inputs and reads the recorded levels back bit for bit; the UIO designed on
  the linearisation (central differences of the model's equations here, in numpy) follows the
  leak.
* `[plant] x0` sets the states' start values (the recorded x_0 is x0), and is refused, exit 2,
  for an FMU whose states take none.
* A Python exception inside doStep is named with the FMU's own log (exit 3, nothing left), and
  a python3 without a shared libpython is refused before anything runs (exit 2).
"""

import os
import shutil
import stat

import numpy as np
import pytest

from test_fmu_plant import columns, export_csv, nothing_left, num, run, table
from test_fmu_testfmus import Slave, fmu_dir  # noqa: F401 (fixture)

AREA, SN, AZ, G = 0.0154, 5e-5, 0.5, 9.81
H_OP = np.array([0.4, 0.2, 0.3])


def f(h, u, w):
    """three_tank.py's right-hand side, written again here (dh/dt in m/s)."""
    c = AZ * SN * np.sqrt(2 * G)
    q13 = c * np.sign(h[0] - h[2]) * np.sqrt(abs(h[0] - h[2]))
    q32 = c * np.sign(h[2] - h[1]) * np.sqrt(abs(h[2] - h[1]))
    q20 = c * np.sqrt(h[1])
    return np.array([u[0] - q13, u[1] + q32 - q20 - w[0], q13 - q32]) / AREA


def operating_point():
    """The pump flows that hold H_OP (f = 0 with no leak)."""
    c = AZ * SN * np.sqrt(2 * G)
    return np.array([c * np.sqrt(0.1), c * np.sqrt(0.2) - c * np.sqrt(0.1)])


def jac(fn, x, h=1e-7):
    return np.column_stack([(fn(x + h * e) - fn(x - h * e)) / (2 * h) for e in np.eye(len(x))])


def mat(m):
    return "[" + ", ".join("[" + ", ".join(num(v) for v in row) + "]" for row in np.atleast_2d(m)) + "]"


def scenario(path, x0="[0.41, 0.2, 0.3]", parameters="", duration=600.0):
    u_op, w_op = operating_point(), np.zeros(1)
    assert np.abs(f(H_OP, u_op, w_op)).max() < 1e-15  # an equilibrium
    A = jac(lambda h: f(h, u_op, w_op), H_OP)
    B = jac(lambda u: f(H_OP, u, w_op), u_op, 1e-9)
    E = jac(lambda w: f(H_OP, u_op, w), w_op, 1e-9)
    x0_line = f"x0 = {x0}\n" if x0 else ""
    return f"""name = "three-tank"
dt = 1.0
duration = {duration}

[plant]             # the linearisation at h = (0.4, 0.2, 0.3) m, in deviations
A = {mat(A)}
B = {mat(B)}
C = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
E = {mat(E)}
{x0_line}state_names = ["h1", "h2", "h3"]
state_units = ["m", "m", "m"]

[plant.operating_point]
x = [0.4, 0.2, 0.3]
u = [{num(u_op[0])}, {num(u_op[1])}]

[plant.fmu]
path = "{path}"
inputs = ["Q1", "Q2"]
disturbances = ["leak"]
outputs = ["y1", "y2", "y3"]
states = ["h1", "h2", "h3"]
{parameters}

[[input]]
kind = "constant"
value = {num(u_op[0])}

[[input]]
kind = "constant"
value = {num(u_op[1])}

[[disturbance]]     # a leak from tank 2 from t = 100 s, m3/s
kind = "step"
time = 100.0
after = 5e-6

[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [-0.05, -0.06, -0.07]
"""


@pytest.fixture(scope="module")
def tank_run(fmu_dir, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("three_tank")
    shutil.copy(os.path.join(fmu_dir, "three_tank.fmu"), tmp)
    (tmp / "tank.toml").write_text(scenario("three_tank.fmu"))
    p, seconds = run(tmp / "tank.toml", tmp / "out", tmp / "runs")
    print(f"three_tank: {seconds:.1f} s: {p.stdout_text}")
    assert p.returncode == 0, p.stderr_text
    return tmp, p


def test_a_pythonfmu_fmu_runs_as_the_plant_and_fmpy_reads_back_its_levels_bit_for_bit(tank_run, fmu_dir):
    tmp, _ = tank_run
    csvs = export_csv(tmp / "out" / "three-tank.rrd", tmp / "csv")
    X, Y, U, W = (table(csvs / f) for f in ("plant_x.csv", "plant_y.csv", "input.csv", "disturbance.csv"))
    assert X.shape == (600, 3) and U.shape == (600, 2) and W.shape == (600, 1)  # t = 0 … 599 s
    # x0 set the states' start values: the recorded x_0, which is not the FMU's own (0.4, …).
    assert list(X[0]) == [0.41, 0.2, 0.3]
    s = Slave(fmu_dir, "three_tank", tmp)
    s.initialize({"h1": 0.41, "h2": 0.2, "h3": 0.3})
    got_x, got_y = np.empty_like(X), np.empty_like(Y)
    for k in range(len(U)):
        got_x[k], got_y[k] = s.get(["h1", "h2", "h3"]), s.get(["y1", "y2", "y3"])
        s.set({"Q1": U[k, 0], "Q2": U[k, 1], "leak": W[k, 0]})
        s.fmu.doStep(currentCommunicationPoint=k * 1.0, communicationStepSize=1.0)
    s.close()
    assert np.array_equal(got_x, X) and np.array_equal(got_y, Y), (np.abs(got_x - X).max(), np.abs(got_y - Y).max())
    assert np.abs(X[-1] - H_OP).max() < 0.05 and np.abs(X[-1] - H_OP).max() > 1e-4  # absolute levels; the leak moved them


def test_the_uio_on_the_linearisation_follows_the_leak_of_the_python_fmu(tank_run):
    tmp, p = tank_run
    csvs = export_csv(tmp / "out" / "three-tank.rrd", tmp / "csv2")
    X, Xh = table(csvs / "plant_x.csv"), table(csvs / "observer_uio_xhat.csv")
    W, Wh = table(csvs / "disturbance.csv"), table(csvs / "observer_uio_what.csv")
    W = W[:len(Wh)]  # ŵ_k needs y_{k+1}: the last sample has none yet
    tail = slice(450, None)
    e, ew = np.abs(X[tail] - Xh[tail]).max(), np.abs(W[tail] - Wh[tail]).max()
    assert len(Wh) == len(X) - 1
    print(f"three_tank: tail max|x − x̂| {e:.3e} m, max|w − ŵ| {ew:.3e} m3/s against a leak of 5e-6")
    # x̂ in the plant's units (about 0.4 m, not a deviation), ŵ within 10 % of the leak: what
    # the linearisation's error leaves (the levels move by ~1 cm under the leak).
    assert np.abs(Xh[tail] - H_OP).max() < 0.05
    assert e < 1e-3 and ew < 0.1 * 5e-6


def test_x0_is_refused_for_an_fmu_whose_states_take_no_start_value(fmu_dir, tmp_path):
    from test_fmu_plant import faulty_scenario
    shutil.copy(os.path.join(fmu_dir, "faulty_fmi2.fmu"), tmp_path)
    text = faulty_scenario("faulty_fmi2.fmu", 0).replace("[plant.fmu]", "x0 = [0.5]\n[plant.fmu]")
    (tmp_path / "f.toml").write_text(text)
    p, _ = run(tmp_path / "f.toml", tmp_path / "out", tmp_path / "runs")
    assert p.returncode == 2, p.stderr_text
    assert "plant.x0[1]: the state 'x1' of faulty_fmi2.fmu takes no start value" in p.stderr_text
    nothing_left(p, tmp_path / "out", tmp_path / "runs")


def test_a_python_exception_in_dostep_is_named_with_the_fmus_log(fmu_dir, tmp_path):
    shutil.copy(os.path.join(fmu_dir, "three_tank.fmu"), tmp_path)
    (tmp_path / "t.toml").write_text(scenario("three_tank.fmu", parameters="parameters = { fail_at = 50.0 }"))
    p, _ = run(tmp_path / "t.toml", tmp_path / "out", tmp_path / "runs")
    err = p.stderr_text.strip().splitlines()[-1]
    assert p.returncode == 3, p.stderr_text
    assert "fmi2DoStep at t = 50 returned Fatal: the FMU logged:" in err and "ValueError" in err \
        and "the leak sensor broke at t = 50.0" in err, err
    assert not os.path.exists(tmp_path / "runs") or os.listdir(tmp_path / "runs") == []


def test_a_python3_without_a_shared_libpython_is_refused_before_anything_runs(fmu_dir, tmp_path):
    shutil.copy(os.path.join(fmu_dir, "three_tank.fmu"), tmp_path)
    (tmp_path / "t.toml").write_text(scenario("three_tank.fmu"))
    # A python3 that reports a static build (an empty INSTSONAME line), first on PATH.
    fake = tmp_path / "bin"
    fake.mkdir()
    (fake / "python3").write_text("#!/bin/sh\necho ''\necho /nowhere\n")
    (fake / "python3").chmod(stat.S_IRWXU)
    old = os.environ["PATH"]
    os.environ["PATH"] = f"{fake}:{old}"
    try:
        p, _ = run(tmp_path / "t.toml", tmp_path / "out", tmp_path / "runs")
    finally:
        os.environ["PATH"] = old
    assert p.returncode == 2, p.stderr_text
    assert "three_tank.fmu: its library embeds Python (it needs Py" in p.stderr_text
    assert "built without a shared libpython" in p.stderr_text
    nothing_left(p, tmp_path / "out", tmp_path / "runs")
