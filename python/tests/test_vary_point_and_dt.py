"""`uio-launcher sweep --vary` of the plant's operating point, initial state and sampling interval,
with every observer still designed on the nominal model at the nominal dt.

- `dt`: checked against an independent simulation in NumPy/SciPy — the plant sampled exactly at
  dt′ with its sinusoidal unknown input (the generator augmented, `expm`), round(duration/dt′)
  steps, the observers' sampled matrices at the design's dt from `uio-launcher design --json` —
  the tail max |x − x̂| of every observer at every point to 1e-9.
- `plant.operating_point.u[i]` / `w[i]` and `x0[i]`: each point is the single run of the scenario
  written by hand with the shifted `[[input]]` / `[[disturbance]]` signal or the initial state,
  bit for bit — on the built-in plant at a real operating point (a scaling of u_op) and on the
  nonlinear DC-motor FMU (values set); on the linear plant the observers' errors do not move
  with the point (they are exact there), the ŵ of the UIO neither.
- The refusals name the cause, one line, exit 2, nothing written.
"""

import csv
import json
import os
import shutil
import subprocess

import numpy as np
import pytest

from test_diagnosis_scipy import launcher
from test_fmu_plant import DC_MOTOR
from test_fmu_testfmus import fmu_dir  # noqa: F401 (a fixture)
from test_vary_oracle import A, DT, SCENARIO, oracle_tail_errors


def run(args):
    return subprocess.run([launcher(), *args], capture_output=True, text=True, timeout=600)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def write(tmp_path, name, text):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


def test_a_plant_sampled_at_another_dt_follows_an_independent_simulation(tmp_path):
    path = write(tmp_path, "mismatch", SCENARIO)
    design = run(["design", "--json", str(path)])
    assert design.returncode == 0, design.stderr
    observers = {o["name"]: o["sampled"] for o in json.loads(design.stdout)["observers"]}
    vary = "dt *= [0.5, 0.8, 1.25, 2]"
    done = run(["sweep", str(path), "--vary", vary, "--out", str(tmp_path / "v")])
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "v" / "mismatch.vary.csv")
    assert [float(r[vary]) for r in rows] == [1.0, 0.5, 0.8, 1.25, 2.0]
    errors = {}
    for r in rows:
        want = oracle_tail_errors(np.array(A), observers, DT * float(r[vary]))
        for name, value in want.items():
            got = float(r[f"tail max|e| {name}"])
            assert abs(got - value) <= 1e-9 * value, (r[vary], name, got, value)
            errors.setdefault(name, []).append(got)
    # Gains made for dt applied at another: the UIO's decoupling of w holds only at its own dt,
    # and less the farther dt′ is (here 2.5–9.5 × the nominal tail error, the sine's sampling).
    nominal, half, near_lo, near_hi, double = errors["uio"]
    assert min(half, near_lo, near_hi, double) > 2 * nominal, errors["uio"]
    assert min(half, double) > max(near_lo, near_hi), errors["uio"]


OP_SCENARIO = SCENARIO.replace("x0 = [1.0, -1.0, 2.0]", "x0 = [1.5, -1.0, 2.0]").replace(
    "[[disturbance]]",
    # A x + B u = 0 at u = 1: x2 = 0, x1 = u/2.
    "[plant.operating_point]\nx = [0.5, 0.0, 0.0]\nu = [1.0]\n\n[[disturbance]]",
).replace('kind = "constant"\nvalue = 0.0', 'kind = "constant"\nvalue = 1.0')


def test_the_built_in_plant_at_another_point_is_the_single_run_there_and_its_observers_hold(tmp_path):
    assert OP_SCENARIO.count("value = 1.0") == 1 and "[plant.operating_point]" in OP_SCENARIO
    path = write(tmp_path, "mismatch", OP_SCENARIO)
    varies = ["plant.operating_point.u[1] *= [0.5, 3]", "x0[3] = [2, -1]"]
    done = run(["sweep", str(path), *sum((["--vary", v] for v in varies), []), "--out", str(tmp_path / "v")])
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "v" / "mismatch.vary.csv")
    assert [(float(r[varies[0]]), float(r[varies[1]])) for r in rows] == [
        (1.0, 2.0), (0.5, 2.0), (0.5, -1.0), (3.0, 2.0), (3.0, -1.0)]
    for r in rows:
        u, x3 = float(r[varies[0]]), float(r[varies[1]])
        text = OP_SCENARIO.replace("kind = \"constant\"\nvalue = 1.0", f"kind = \"constant\"\nvalue = {u!r}")
        text = text.replace("x0 = [1.5, -1.0, 2.0]", f"x0 = [1.5, -1.0, {x3!r}]")
        single = write(tmp_path, f"single-{r['point']}", text)
        ran = run(["run", str(single), "--mode", "in-process", "--out", str(tmp_path / f"r{r['point']}")])
        assert ran.returncode == 0, ran.stderr
        summary = json.loads((tmp_path / f"r{r['point']}" / "mismatch.summary.json").read_text())
        for o in summary["observers"]:
            assert float(r[f"tail max|e| {o['name']}"]) == o["tail_max_abs_error"], (r, o)
            assert float(r[f"tail max|y−Cx̂| {o['name']}"]) == o["tail_max_abs_residual"], (r, o)
        # Linear plant, linear observers that see u: another point moves x, not the error (its
        # dynamics do not hold u); another start does, through the transient left at the tail.
        if x3 == 2.0:
            for name in ("uio", "luenberger"):
                nominal = float(rows[0][f"tail max|e| {name}"])
                assert abs(float(r[f"tail max|e| {name}"]) - nominal) <= 1e-9 * nominal, (r, name)


def test_the_nonlinear_fmu_at_other_inputs_is_the_single_run_of_the_shifted_signals(fmu_dir, tmp_path):  # noqa: F811
    shutil.copy(os.path.join(fmu_dir, "dc_motor_fmi3.fmu"), tmp_path)
    base = DC_MOTOR.format(path="dc_motor_fmi3.fmu").replace("duration = 10.0", "duration = 3.0")
    path = write(tmp_path, "motor", base)
    varies = ["plant.operating_point.u[1] = [-4, 2]", "plant.operating_point.w[1] = [0.01]"]
    done = run(["sweep", str(path), *sum((["--vary", v] for v in varies), []), "--out", str(tmp_path / "v")])
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "v" / "dc-motor-fmu.vary.csv")
    assert [(float(r[varies[0]]), float(r[varies[1]])) for r in rows] == [(0.0, 0.0), (-4.0, 0.01), (2.0, 0.01)]
    assert all(r["status"] == "completed" for r in rows), rows
    step = 'kind = "step"\ntime = 0.5\nafter = 12.0'
    load = 'kind = "piecewise"\ntimes = [2.0, 6.0]\nvalues = [0.05, 0.02]'
    assert step in base and load in base
    for r in rows[1:]:
        du, dw = float(r[varies[0]]), float(r[varies[1]])
        # The shifted signals as an engineer writes them: the step about du, the load about dw
        # from t = 0 (a piecewise signal is 0 before its first time).
        text = base.replace(step, f'kind = "step"\ntime = 0.5\nbefore = {du!r}\nafter = {12.0 + du!r}')
        text = text.replace(load, f'kind = "piecewise"\ntimes = [0.0, 2.0, 6.0]\n'
                                  f'values = [{dw!r}, {0.05 + dw!r}, {0.02 + dw!r}]')
        single = write(tmp_path, f"single-{r['point']}", text)
        ran = run(["run", str(single), "--out", str(tmp_path / f"r{r['point']}")])
        assert ran.returncode == 0, ran.stderr
        summary = json.loads((tmp_path / f"r{r['point']}" / "dc-motor-fmu.summary.json").read_text())
        for o in summary["observers"]:
            assert float(r[f"tail max|e| {o['name']}"]) == o["tail_max_abs_error"], (r, o)
        uio = next(o for o in summary["observers"] if o["name"] == "uio")
        assert float(r["tail max|ŵ−w| uio"]) == uio["tail_max_abs_input_error"], (r, uio)


def test_a_drawn_dt_that_is_no_interval_fails_its_point_and_names_it(tmp_path):
    path = write(tmp_path, "mismatch", SCENARIO)
    done = run(["sweep", str(path), "--vary", "dt = N(0.01, 0.02)", "--points", "12", "--out", str(tmp_path / "v")])
    assert done.returncode == 0, done.stderr
    rows = read_csv(tmp_path / "v" / "mismatch.vary.csv")
    bad = [r for r in rows if float(r["dt = N(0.01, 0.02)"]) <= 0]
    assert bad, "12 draws of N(0.01, 0.02) hold a value ≤ 0 (p ≈ 0.31 each): change --points"
    assert all(r["status"] == "failed" for r in bad), bad
    assert all(r["status"] == "completed" for r in rows if r not in bad), rows
    assert "gives no run of" in done.stdout, done.stdout


DISCRETE = """name = "per-step"
dt = 0.1
duration = 2.0

[plant]
time = "discrete"
A = [[0.9, 0.1], [0.0, 0.8]]
B = [[0.0], [0.1]]
C = [[1.0, 0.0]]
x0 = [1.0, 0.0]

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-2.0, -3.0]
"""


@pytest.mark.parametrize("text,vary,says", [
    (SCENARIO, "dt *= [0, 1]", "dt must stay > 0"),
    (SCENARIO, "dt *= U(-1, 2)", "dt must stay > 0"),
    (SCENARIO, "plant.operating_point.u[1] *= [2]", "is 0 in this scenario, a scaling keeps it 0"),
    (SCENARIO, "plant.operating_point.u[2] = [1]", "the plant has 1 known inputs, there is no entry 2"),
    (SCENARIO, "plant.operating_point.w[3] = [1]", "the plant has 1 unknown inputs, there is no entry 3"),
    (SCENARIO, "x0[4] = [1]", "the plant has 3 states, there is no entry 4"),
    (SCENARIO, "plant.operating_point.y[1] = [1]", "u[i] (a known input) or"),
    (DISCRETE, "dt *= [2]", "is given per step"),
])
def test_a_vary_of_the_point_or_dt_the_scenario_cannot_take_is_refused(tmp_path, text, vary, says):
    path = write(tmp_path, "s", text)
    done = run(["sweep", str(path), "--vary", vary, "--out", str(tmp_path / "bad")])
    assert done.returncode == 2, done.stderr
    assert says in done.stderr.splitlines()[0], done.stderr
    assert not list((tmp_path / "bad").glob("*.vary.csv"))


def test_a_commanded_input_of_a_closed_loop_is_not_moved(tmp_path):
    from conftest import REPO
    path = os.path.join(REPO, "scenarios", "seed000-missile-closed-loop.toml")
    done = run(["sweep", path, "--vary", "plant.operating_point.u[1] = [1]", "--out", str(tmp_path / "bad")])
    assert done.returncode == 2, done.stderr
    assert "the controller commands input 1" in done.stderr.splitlines()[0], done.stderr
