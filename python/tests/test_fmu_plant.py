"""FMUs as the plant of a run (`[plant.fmu]`), checked against independent numbers:

* the linear test FMU (lti_plant, the exact ZOH step of seed 002 as parameters) gives a recording
  equal, bit for bit, to the built-in plant's on the same discrete model (`uio-launcher compare`),
  in FMI 2.0 and 3.0;
* FMPy, an importer that is not ours, drives the same FMU with the recorded u and w and reads
  the recorded x and y back, bit for bit;
* the nonlinear DC motor FMU (Coulomb friction) runs under the built-in UIO and Luenberger
  observers, whose errors are taken against the FMU's true state;
* a bad FMU is refused with exit 2 before anything runs, and one that fails, crashes or hangs
  inside doStep is named (exit 3): in every case nothing is left behind.
"""

import csv
import glob
import json
import os
import re
import shutil
import subprocess
import time
import zipfile

import numpy as np
import pytest

from conftest import REPO
from test_diagnosis_scipy import launcher
from test_fmu_testfmus import Slave, fmu_dir, lti_parameters, seed002_zoh  # noqa: F401 (fixture)

SEED002 = os.path.join(REPO, "scenarios", "seed002-piecewise.toml")


def num(v):
    return repr(float(v))


def mat(m):
    return "[" + ", ".join("[" + ", ".join(num(v) for v in row) + "]" for row in np.atleast_2d(m)) + "]"


def discrete_seed002(fmu_table=""):
    """seed002-piecewise as the discrete plant (Φ, Γ_B, Γ_E of scipy's exact ZOH) that the
    lti_plant FMU also gets as parameters; with `fmu_table`, that FMU simulates it."""
    Phi, GB, GE, C, x0, _ = seed002_zoh()
    text = open(SEED002).read()
    text = re.sub(r"^A = .*$", 'time = "discrete"\nPhi = ' + mat(Phi), text, flags=re.M)
    text = re.sub(r"^B = .*$", "Gamma_B = " + mat(GB), text, flags=re.M)
    text = re.sub(r"^E = .*$", "Gamma_E = " + mat(GE), text, flags=re.M)
    text = re.sub(r"^\[expect\].*", "", text, flags=re.M | re.S)
    return text + fmu_table


def lti_table(path):
    Phi, GB, GE, C, x0, _ = seed002_zoh()
    # x(0): the scenario's [plant] x0, which sets the states' start values
    params = ", ".join(f"{k} = {num(v)}" for k, v in lti_parameters(Phi, GB, GE, C).items())
    return f"""
[plant.fmu]
path = "{path}"
inputs = ["u1", "u2"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]
parameters = {{ {params} }}
"""


def run(scenario, out, runs_dir, *extra, timeout=300):
    """`uio-launcher run` in its own runs directory; returns (process, seconds, launcher pid)."""
    env = {**os.environ, "UIO_RUNS_DIR": str(runs_dir)}
    start = time.monotonic()
    p = subprocess.Popen([launcher(), "run", str(scenario), "--out", str(out), *extra], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stdout, stderr = p.communicate(timeout=timeout)
    p.stdout_text, p.stderr_text = stdout, stderr
    return p, time.monotonic() - start


def nothing_left(p, out, runs_dir, recorded=False):
    """No recording or summary (with `recorded`, a failed run's closed recording and summary
    but no partial file); no run directory; no shared memory of this run's launcher (its pid
    leads the run id, PROTOCOL.md §1)."""
    left = sorted(os.listdir(out)) if os.path.exists(out) else []
    if recorded:
        assert left == ["faulty.rrd", "faulty.summary.json"], left
    else:
        assert left == [], left
    assert not os.path.exists(runs_dir) or os.listdir(runs_dir) == [], os.listdir(runs_dir)
    assert glob.glob(f"/dev/shm/uio{p.pid}x*") == []
    assert glob.glob(f"/tmp/uio-iox2-{os.geteuid()}/{p.pid}x*") == []


def export_csv(rrd, to):
    # From another folder: the recorded scenario's relative FMU path must not cost its names.
    done = subprocess.run([launcher(), "export", "--csv", str(to), str(rrd)], capture_output=True, text=True, timeout=120, cwd="/")
    assert done.returncode == 0, done.stderr
    return to


def columns(path):
    """A CSV export as {header: values}, the floats parsed back to the recorded bits."""
    with open(path) as f:
        rows = list(csv.reader(f))
    return {h: np.array([float(r[i]) for r in rows[1:]]) for i, h in enumerate(rows[0])}


@pytest.fixture(scope="module", params=[2, 3])
def lti_runs(request, fmu_dir, tmp_path_factory):
    """The discrete seed 002 run twice across processes: by the built-in plant and by the
    lti_plant FMU of FMI version `param`."""
    v = request.param
    tmp = tmp_path_factory.mktemp(f"lti{v}")
    fmu = os.path.join(fmu_dir, f"lti_plant_fmi{v}.fmu")
    (tmp / "builtin.toml").write_text(discrete_seed002())
    (tmp / "fmu.toml").write_text(discrete_seed002(lti_table(fmu)))
    rrds = {}
    for name in ("builtin", "fmu"):
        p, _ = run(tmp / f"{name}.toml", tmp / f"out-{name}", tmp / f"runs-{name}")
        assert p.returncode == 0, p.stderr_text
        rrds[name] = tmp / f"out-{name}" / "seed002-piecewise.rrd"
    return v, fmu, rrds, tmp


def test_the_linear_fmu_plant_records_the_builtin_plant_bit_for_bit(lti_runs):
    v, _, rrds, _ = lti_runs
    done = subprocess.run([launcher(), "compare", str(rrds["builtin"]), str(rrds["fmu"])], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "bit for bit" in done.stdout
    n = int(re.search(r"same: (\d+) values", done.stdout).group(1))
    assert n >= 20000 * 10, done.stdout  # x, y, w, u, every estimate and error over 20000 steps
    print(f"FMI {v}: {done.stdout.strip()}")


def table(path):
    """The values of a CSV export (without step and sim_time), one row per step."""
    c = columns(path)
    return np.column_stack([c[h] for h in list(c)[2:]])


def replay(fmu, tmp_path, parameters, U, W, dt):
    """FMPy steps `fmu` from its start with u_k = U[k] and w_k = W[k] held over each step and
    returns the (x_k, y_k) it reads at every t_k."""
    name = os.path.basename(fmu)[:-len(".fmu")]
    s = Slave(os.path.dirname(fmu), name, tmp_path)
    s.initialize(parameters)
    n = len([v for v in s.vr if re.fullmatch(r"x\d+", v)])
    p = len([v for v in s.vr if re.fullmatch(r"y\d+", v)])
    got_x, got_y = np.empty((len(U), n)), np.empty((len(U), p))
    for k in range(len(U)):
        got_x[k], got_y[k] = s.get([f"x{i + 1}" for i in range(n)]), s.get([f"y{j + 1}" for j in range(p)])
        s.set({**{f"u{i + 1}": U[k, i] for i in range(U.shape[1])}, **{f"w{i + 1}": W[k, i] for i in range(W.shape[1])}})
        s.fmu.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
    s.close()
    return got_x, got_y


def test_fmpy_reproduces_the_fmu_run_bit_for_bit(lti_runs, tmp_path):
    """FMPy steps the same FMU with the recorded u_k and w(t_k) and reads x_k and y_k: the
    values our plant recorded."""
    v, fmu, rrds, _ = lti_runs
    csvs = export_csv(rrds["fmu"], tmp_path / "csv")
    X, Y, U, W = (table(csvs / f) for f in ("plant_x.csv", "plant_y.csv", "controller_u.csv", "disturbance.csv"))
    assert X.shape == (len(U), 3) and Y.shape == (len(U), 2) and len(W) == len(U) > 10000
    Phi, GB, GE, C, x0, dt = seed002_zoh()
    got_x, got_y = replay(fmu, tmp_path, lti_parameters(Phi, GB, GE, C, x0), U, W, dt)
    assert np.array_equal(got_x, X) and np.array_equal(got_y, Y), (np.abs(got_x - X).max(), np.abs(got_y - Y).max())


DC_MOTOR = """name = "dc-motor-fmu"
description = "The DC motor FMU with Coulomb friction under the built-in UIO and Luenberger observer"
dt = 0.001
duration = 10.0

[plant]             # the FMU's linearisation without friction: R = 1, L = 0.5, K = 0.01, J = 0.01, b = 0.1
A = [[-2.0, -0.02, 0.0], [1.0, -10.0, 0.0], [0.0, 1.0, 0.0]]
B = [[2.0], [0.0], [0.0]]
C = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
E = [[0.0], [-100.0], [0.0]]
x0 = [0.0, 0.0, 0.0]
state_names = ["i", "omega", "theta"]
state_units = ["A", "rad/s", "rad"]

[plant.fmu]
path = "{path}"
inputs = ["u1"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]
parameters = {{ R = 1.0, L = 0.5, K = 0.01, J = 0.01, b = 0.1, tau_c = 0.01, omega_s = 0.05, substeps = 4.0 }}

[[disturbance]]
kind = "piecewise"
times = [2.0, 6.0]
values = [0.05, 0.02]

[[input]]
kind = "step"
time = 0.5
after = 12.0

[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [-20.0, -30.0]

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-20.0, -30.0, -40.0]
"""


@pytest.mark.parametrize("v", [2, 3])
def test_the_nonlinear_fmu_plant_runs_under_the_builtin_observers(fmu_dir, tmp_path, v):
    """Friction acts where the load torque does (through E): the UIO rejects it, the
    Luenberger observer does not; both errors are against the FMU's own states."""
    # The FMU beside the scenario, named relative to it.
    shutil.copy(os.path.join(fmu_dir, f"dc_motor_fmi{v}.fmu"), tmp_path)
    path = tmp_path / "dc.toml"
    path.write_text(DC_MOTOR.format(path=f"dc_motor_fmi{v}.fmu"))
    p, _ = run(path, tmp_path / "out", tmp_path / "runs")
    assert p.returncode == 0, p.stderr_text
    summary = json.loads((tmp_path / "out" / "dc-motor-fmu.summary.json").read_text())
    obs = {o["name"]: o for o in summary["observers"]}
    uio, lue = obs["uio"]["tail_max_abs_error"], obs["luenberger"]["tail_max_abs_error"]
    print(f"FMI {v}: tail max|e| uio {uio:.3e}, luenberger {lue:.3e}")
    assert uio < 1e-5 and lue > 1e-2 and uio < 1e-4 * lue
    # The recorded true state is the FMU's: FMPy, stepping the same FMU with the recorded
    # inputs (open loop: u_k = r(t_k)), reads back the recorded x and y bit for bit.
    csvs = export_csv(tmp_path / "out" / "dc-motor-fmu.rrd", tmp_path / "csv")
    X, Y, U, W = (table(csvs / f) for f in ("plant_x.csv", "plant_y.csv", "input.csv", "disturbance.csv"))
    params = {"R": 1.0, "L": 0.5, "K": 0.01, "J": 0.01, "b": 0.1, "tau_c": 0.01, "omega_s": 0.05, "substeps": 4.0}
    got_x, got_y = replay(os.path.join(fmu_dir, f"dc_motor_fmi{v}.fmu"), tmp_path, params, U, W, 0.001)
    assert np.array_equal(got_x, X) and np.array_equal(got_y, Y), (np.abs(got_x - X).max(), np.abs(got_y - Y).max())
    assert np.abs(X[:, 1]).max() > 1.0  # the motor turned (ω in rad/s)
    assert list(columns(csvs / "plant_x.csv"))[2:] == ["i [A]", "omega [rad/s]", "theta [rad]"]


def edit_fmu(src, dst, xml=None, rename=None):
    """A copy of an FMU with its modelDescription.xml changed by `xml` and entries renamed."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            name = item.filename
            if name == "modelDescription.xml" and xml:
                data = xml(data.decode()).encode()
            if rename:
                name = rename(name)
            if name:
                zout.writestr(name, data)
    return dst


BAD = {
    "not-a-zip": (lambda src, dst: (dst.write_bytes(b"this is not a zip archive\n"), dst)[1], {}, r"not an FMU: not a zip archive"),
    "no-description": (lambda src, dst: edit_fmu(src, dst, rename=lambda n: None if n == "modelDescription.xml" else n), {}, r"no modelDescription\.xml"),
    "model-exchange-only": (
        lambda src, dst: edit_fmu(src, dst, xml=lambda x: re.sub(r"<CoSimulation[^>]*/>", '<ModelExchange modelIdentifier="lti_plant"/>', x)),
        {},
        r"model exchange only",
    ),
    "no-binary": (lambda src, dst: edit_fmu(src, dst, rename=lambda n: n.replace("/x86_64-linux/", "/x86_64-windows/").replace(".so", ".dll")), {}, r"no binary for this platform: binaries/x86_64-linux/lti_plant\.so"),
    "fmi-version": (lambda src, dst: edit_fmu(src, dst, xml=lambda x: x.replace('fmiVersion="3.0"', 'fmiVersion="1.0"')), {}, r"FMI version 1\.0 is not supported"),
    # Hostile: a description that deflates to 65 MiB is refused by its length, not read whole.
    "huge-description": (lambda src, dst: edit_fmu(src, dst, xml=lambda x: x + " " * (65 << 20)), {}, r"modelDescription\.xml is longer than 67108864 bytes"),
    "no-such-variable": (None, {"outputs": '["y1", "y9"]'}, r"plant\.fmu\.outputs\[2\]: lti_plant_fmi3\.fmu has no variable named 'y9' \(did you mean"),
    "wrong-causality": (None, {"inputs": '["u1", "y1"]'}, r"plant\.fmu\.inputs\[2\]: 'y1' of lti_plant_fmi3\.fmu is an output, not an input"),
    "wrong-type": (None, {"parameters": "{ Phi_1_1 = true }"}, r"plant\.fmu\.parameters\.Phi_1_1: 'Phi_1_1' of lti_plant_fmi3\.fmu is of type Float64; true is not a value of it"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_fmu_is_refused_before_anything_runs(fmu_dir, tmp_path, case):
    make, keys, message = BAD[case]
    src = os.path.join(fmu_dir, "lti_plant_fmi3.fmu")
    path = make(src, tmp_path / "lti_plant_fmi3.fmu") if make else src
    text = discrete_seed002(lti_table(path))
    for key, value in keys.items():
        text = re.sub(rf"^{key} = .*$", f"{key} = {value}", text, count=1, flags=re.M)
    (tmp_path / "bad.toml").write_text(text)
    p, _ = run(tmp_path / "bad.toml", tmp_path / "out", tmp_path / "runs")
    err = p.stderr_text.strip()
    assert p.returncode == 2, err
    assert re.search(message, err), err
    assert len(err.splitlines()) == 1 and "bad.toml" in err, err
    nothing_left(p, tmp_path / "out", tmp_path / "runs")


def faulty_scenario(path, how):
    return f"""name = "faulty"
dt = 0.01
duration = 20.0
[plant]
A = [[-1.0]]
B = [[1.0]]
C = [[1.0]]
E = [[1.0]]
[plant.fmu]
path = "{path}"
inputs = ["u1"]
disturbances = ["w1"]
outputs = ["y1"]
states = ["x1"]
parameters = {{ fail_at = 1.0, how = {how}.0 }}
[[disturbance]]
kind = "constant"
value = 0.5
[[input]]
kind = "constant"
value = 1.0
[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-3.0]
"""


@pytest.mark.parametrize("v", [2, 3])
@pytest.mark.parametrize("how,said", [(1, r"fmi[23]DoStep at t = 1 returned Error: .*faulty: doStep fails on request"),
                                      (2, r"plant.*(signal 11|SIGSEGV)"),
                                      (3, r"plant")])
def test_an_fmu_that_fails_crashes_or_hangs_is_named(fmu_dir, tmp_path, v, how, said):
    path = tmp_path / "faulty.toml"
    path.write_text(faulty_scenario(os.path.join(fmu_dir, f"faulty_fmi{v}.fmu"), how))
    p, seconds = run(path, tmp_path / "out", tmp_path / "runs", timeout=120)
    err = p.stderr_text.strip()
    print(f"FMI {v}, how = {how}: {seconds:.1f} s: {err}")
    assert p.returncode == 3, err
    assert re.search(said, err), err
    if how == 3:
        assert re.search(r"stopped or blocked|asleep|no step", err), err
        assert seconds < 30, seconds
    nothing_left(p, tmp_path / "out", tmp_path / "runs", recorded=True)


def test_in_process_mode_refuses_an_fmu_plant(fmu_dir, tmp_path):
    path = tmp_path / "fmu.toml"
    path.write_text(discrete_seed002(lti_table(os.path.join(fmu_dir, "lti_plant_fmi3.fmu"))))
    p, _ = run(path, tmp_path / "out", tmp_path / "runs", "--mode", "in-process")
    assert p.returncode == 2
    assert "the plant is an FMU: it runs in its own process" in p.stderr_text
    nothing_left(p, tmp_path / "out", tmp_path / "runs")
