"""The ```python blocks of python/README.md, checked for real.

* Every block compiles, and runs as a module (the `Signals` snippet's asserts run; the
  components' files import and define their functions).
* The README's three components — `zoh_plant.py` as `[plant.process]`, `estimator.py` and
  `perfect.py` as `kind = "process"` observers — run in a scenario launched by
  `uio-launcher run`, closed loop (the built-in controller on the estimator's x̂, the other observers
  then trailing with `lag` 4096) and open loop (no controller: u = r). The same scenario is run
  again with the built-in exact plant in place of `zoh_plant.py`, and:
  - w, v, r of the two runs are equal bit for bit (`Signals` samples as the built-in plant,
    switching times compared as decimals: dt = 0.03 puts them where 15 × 0.03 < 0.45 in binary);
  - x, y, u and every estimate agree to rounding (the README plant is the built-in plant);
  - `estimator.py`'s recorded x̂ is recomputed here from the recorded y and u, with Φ, Γ_B of
    one block exponential and u_{−1} = 0 (what `u_prev` holds in sample 0);
  - `perfect.py`'s error x − x̂ is 0 at every step.

The launcher is `$CARGO_TARGET_DIR/release/uio-launcher`, or `target/release/uio-launcher` of this
checkout (`test_diagnosis_scipy.launcher`). The components run with this interpreter's `python3`
first in PATH and this checkout's kit on PYTHONPATH; everything is written to a temporary
directory that is removed afterwards.
"""

import csv
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile

import numpy as np
import pytest
from scipy.linalg import expm

from conftest import PYTHON_DIR
from test_diagnosis_scipy import launcher

README = os.path.join(PYTHON_DIR, "README.md")
COMPONENTS = ("perfect.py", "zoh_plant.py", "estimator.py")

DT, STEPS = 0.03, 200
A = np.array([[0.0, 1.0, 0.0], [-2.0, -3.0, 1.0], [0.0, 0.0, -5.0]])
B = np.array([[0.0], [1.0], [1.0]])
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
L_GAIN = [[0.5, 0.0], [0.3, 0.0], [0.0, 0.5]]


def mat(m):
    return "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in np.atleast_2d(m)) + "]"


def scenario(builtin_plant, closed_loop):
    plant = "" if builtin_plant else '[plant.process]\ncommand = ["python3", "zoh_plant.py"]\n'
    controller = (
        '[controller]\nkind = "state-feedback"\nobserver = "estimator"\npoles = [-3.0, -4.0, -5.0]\n'
        "track = [[1.0, 0.0, 0.0]]\n" if closed_loop else ""
    )
    return f"""name = "readme"
dt = {DT}
duration = {DT * STEPS:.1f}
[plant]
A = {mat(A)}
B = {mat(B)}
E = [[0.0], [0.0], [1.0]]
C = {mat(C)}
D = [[0.0], [0.5]]
x0 = [1.0, -0.5, 0.2]
{plant}
[[disturbance]]
kind = "piecewise"
times = [0.45, 1.32]
values = [1.0, -0.5]

[[measurement_disturbance]]
kind = "sine"
amplitude = 0.01
frequency_hz = 3.0
phase = 0.2

[[input]]
kind = "step"
time = 0.33
after = 0.5

[[observer]]
name = "estimator"
kind = "process"
command = ["python3", "estimator.py"]
params = {{ L = {mat(L_GAIN)} }}

[[observer]]
name = "perfect"
kind = "process"
command = ["python3", "perfect.py"]

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-4.0, -5.0, -6.0]

{controller}"""


def blocks():
    """The ```python blocks of the README, in order."""
    with open(README, encoding="utf-8") as f:
        return re.findall(r"^```python\n(.*?)^```[ \t]*$", f.read(), flags=re.S | re.M)


def component(name):
    """The block whose first line is `# <name>: …`."""
    found = [b for b in blocks() if b.startswith(f"# {name}:")]
    assert len(found) == 1, f"README.md has {len(found)} blocks for {name}"
    return found[0]


def test_every_python_block_compiles_and_runs_as_a_module():
    found = blocks()
    assert len(found) == len(COMPONENTS) + 1, f"{len(found)} python blocks"
    for name in COMPONENTS:
        component(name)
    for i, text in enumerate(found):
        code = compile(text, f"python/README.md, python block {i + 1}", "exec")
        namespace = {"__name__": f"readme_block_{i + 1}"}
        exec(code, namespace)  # the snippet's asserts; a component only defines step (and setup)
        if text.startswith("# "):
            assert callable(namespace.get("step")), f"block {i + 1} defines no step"


def table(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    values = np.array([[float(v) for v in r] for r in rows[1:]])
    assert values.shape[0] == STEPS and values[:, 0].tolist() == list(range(STEPS)), path
    return values[:, 2:]


def run(scratch, label, builtin_plant, closed_loop):
    """`uio-launcher run` of the scenario in its own folder with the README's components; the
    summary and the CSV export."""
    folder = scratch / label
    folder.mkdir()
    for name in COMPONENTS:
        (folder / name).write_text(component(name), encoding="utf-8")
    (folder / "readme.toml").write_text(scenario(builtin_plant, closed_loop), encoding="utf-8")
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env.get("PATH", "")
    env["PYTHONPATH"] = PYTHON_DIR + os.pathsep + env.get("PYTHONPATH", "")
    out = folder / "out"
    done = subprocess.run([launcher(), "run", str(folder / "readme.toml"), "--out", str(out)],
                          capture_output=True, text=True, timeout=300, env=env, cwd=folder)
    assert done.returncode == 0, f"uio-launcher run ({label}) exited {done.returncode}:\n{done.stdout}\n{done.stderr}"
    csv_dir = folder / "csv"
    done = subprocess.run([launcher(), "export", "--csv", str(csv_dir), str(out / "readme.rrd")],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "readme.summary.json").read_text())
    return summary, csv_dir


def estimate(y, u_prev):
    """estimator.py's x̂, recomputed: x̂⁻_k = Φx̂_{k−1} + Γ_B u_{k−1}, x̂_k = x̂⁻_k + L(y_k − Cx̂⁻_k)."""
    n, l = B.shape
    big = np.zeros((n + l, n + l))
    big[:n, :n], big[:n, n:] = A, B
    g = expm(big * DT)
    phi, gb, gain = g[:n, :n], g[:n, n:], np.array(L_GAIN)
    xhat, out = np.zeros(n), []
    for k in range(len(y)):
        if k > 0:
            xhat = phi @ xhat + gb @ u_prev[k]
        xhat = xhat + gain @ (y[k] - C @ xhat)
        out.append(xhat)
    return np.array(out)


@pytest.fixture
def scratch():
    with tempfile.TemporaryDirectory(prefix="uio-readme-") as d:
        yield pathlib.Path(d)


@pytest.mark.parametrize("closed_loop", [True, False], ids=["closed-loop", "open-loop"])
def test_the_readme_components_run_a_scenario_as_the_builtin_plant_does(scratch, closed_loop):
    mine, mine_csv = run(scratch, "readme-plant", builtin_plant=False, closed_loop=closed_loop)
    ours, ours_csv = run(scratch, "builtin-plant", builtin_plant=True, closed_loop=closed_loop)
    for summary in (mine, ours):
        assert summary["steps"] == STEPS
        (perfect,) = [o for o in summary["observers"] if o["name"] == "perfect"]
        assert perfect["max_abs_error"] == 0.0  # x̂_k = x_k at every step

    # The signals the README plant samples with `Signals` are the built-in plant's, bit for bit.
    for name in ("disturbance", "measurement_disturbance", "input"):
        np.testing.assert_array_equal(table(mine_csv / f"{name}.csv"), table(ours_csv / f"{name}.csv"), err_msg=name)
    w = table(mine_csv / "disturbance.csv")[:, 0]
    assert w[14] == 0.0 and w[15] == 1.0 and w[44] == -0.5  # 0.45 s and 1.32 s as written

    # The README plant is the built-in exact plant: the same run, to rounding.
    files = ["plant_x", "plant_y", "observer_estimator_xhat", "observer_perfect_xhat", "observer_luenberger_xhat"]
    if closed_loop:
        files.append("controller_u")
    for name in files:
        a, b = table(mine_csv / f"{name}.csv"), table(ours_csv / f"{name}.csv")
        scale = max(1.0, np.abs(b).max())
        assert np.abs(a - b).max() <= 1e-11 * scale, (name, np.abs(a - b).max())
    x = table(mine_csv / "plant_x.csv")
    assert np.abs(x[-1] - x[0]).max() > 0.1  # the plant moved

    # estimator.py publishes what its README formula gives from the recorded y and u_{k−1}
    # (the controller's u, or r without one; 0 before step 0), with either plant.
    for folder in (mine_csv, ours_csv):
        y = table(folder / "plant_y.csv")
        u = table(folder / ("controller_u.csv" if closed_loop else "input.csv"))
        u_prev = np.vstack([np.zeros((1, u.shape[1])), u[:-1]])
        expected = estimate(y, u_prev)
        recorded = table(folder / "observer_estimator_xhat.csv")
        assert np.abs(recorded - expected).max() <= 1e-12 * max(1.0, np.abs(expected).max())
