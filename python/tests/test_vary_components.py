"""`uio-launcher sweep --vary` on plants that are not the built-in one. An FMU plant: the DC motor test FMU (nonlinear, Coulomb
friction) with its inertia J scaled and its friction torque τ_c set, the observers designed
once on the scenario's linear model. Each point is checked against a single run of the same
scenario with those parameter values written into `[plant.fmu] parameters`: every observer's
tail max|e| and tail max|ŵ − w| equal bit for bit; the nominal point is the plain run; one PNG
per figure and varied parameter; the refusals name the cause.

J and τ_c both act in the ω row, which is E's column: the UIO's estimate stays put while ŵ takes
up the friction; the Luenberger observer's error moves with it.

A kit component plant: the shipped cart-pole in Python (`components/cartpole.py`) with its pole
mass scaled through `plant.process.params`, each point against the single run of that mass.
"""

import csv
import json
import os
import pathlib
import shutil
import subprocess

import pytest

from conftest import REPO as REPO_DIR

from test_diagnosis_scipy import launcher
from test_fmu_plant import DC_MOTOR
from test_fmu_testfmus import fmu_dir  # noqa: F401 (a fixture)

J, TAU_C = 0.01, 0.01  # DC_MOTOR's nominal parameters
VARIES = ["plant.fmu.parameters.J *= [0.5, 2]", "plant.fmu.parameters.tau_c = [0, 0.05]"]


def run(args):
    return subprocess.run([launcher(), *args], capture_output=True, text=True, timeout=600)


def scenario_text(path, j=J, tau_c=TAU_C):
    text = DC_MOTOR.format(path=path).replace("duration = 10.0", "duration = 3.0")
    nominal = f"J = {J}, b = 0.1, tau_c = {TAU_C},"
    assert nominal in text
    return text.replace(nominal, f"J = {j!r}, b = 0.1, tau_c = {tau_c!r},")


@pytest.fixture
def motor(fmu_dir, tmp_path):  # noqa: F811
    shutil.copy(os.path.join(fmu_dir, "dc_motor_fmi3.fmu"), tmp_path)
    path = tmp_path / "motor.toml"
    path.write_text(scenario_text("dc_motor_fmi3.fmu"))
    return path


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def single_run(tmp_path, folder, j, tau_c):
    path = tmp_path / f"{folder}.toml"
    path.write_text(scenario_text("dc_motor_fmi3.fmu", j, tau_c))
    done = run(["run", str(path), "--out", str(tmp_path / folder)])
    assert done.returncode == 0, done.stderr
    return json.loads((tmp_path / folder / "dc-motor-fmu.summary.json").read_text())


def test_every_point_is_the_single_run_of_its_parameters_bit_for_bit(motor, tmp_path):
    out = tmp_path / "vary"
    args = ["sweep", str(motor), *sum((["--vary", v] for v in VARIES), []), "--out", str(out)]
    done = run(args)
    assert done.returncode == 0, done.stderr
    rows = read_csv(out / "dc-motor-fmu.vary.csv")
    assert len(rows) == 1 + 2 * 2
    assert rows[0]["nominal"] == "true"
    assert (float(rows[0][VARIES[0]]), float(rows[0][VARIES[1]])) == (1.0, TAU_C)
    assert all(r["status"] == "completed" for r in rows), rows
    # The nominal point, and two varied ones, against single runs.
    for r in (rows[0], rows[1], rows[4]):
        j, tau_c = J * float(r[VARIES[0]]), float(r[VARIES[1]])
        summary = single_run(tmp_path, f"single-{r['point']}", j, tau_c)
        for o in summary["observers"]:
            assert float(r[f"tail max|e| {o['name']}"]) == o["tail_max_abs_error"], (r, o)
        uio = next(o for o in summary["observers"] if o["name"] == "uio")
        assert float(r["tail max|ŵ−w| uio"]) == uio["tail_max_abs_input_error"], (r, uio)
    # The mismatch lies in E's row: the UIO's estimate holds where the Luenberger observer's
    # error and the UIO's ŵ move with it.
    uio = [float(r["tail max|e| uio"]) for r in rows]
    lue = [float(r["tail max|e| luenberger"]) for r in rows]
    what = [float(r["tail max|ŵ−w| uio"]) for r in rows]
    assert max(uio) - min(uio) <= 1e-3 * (max(lue) - min(lue)), (uio, lue)
    # ŵ − w is mostly the friction torque no model term carries (|ŵ − w| ≈ τ_c once |ω| ≫ ω_s):
    # 0.01 at the nominal point, far below it without friction, five times it at τ_c = 0.05.
    for r, e in zip(rows[1:], what[1:]):
        tau_c = float(r[VARIES[1]])
        assert (e >= 4 * what[0]) if tau_c > TAU_C else (e <= what[0]), (r, what)
    summary = json.loads((out / "dc-motor-fmu.vary.json").read_text())
    pngs = sorted(out.glob("dc-motor-fmu.vary_*.png"))
    # A plot per figure and parameter, and a 2-D map per figure over the two parameters.
    assert len(pngs) == len(summary["columns"]) * 3, pngs
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)


@pytest.mark.parametrize("vary,says", [
    ("A[1,1] *= [1]", "a matrix is varied in the built-in plant"),
    ("plant.fmu.parameters.nosuch *= [1, 2]", "gives no number for nosuch"),
    ("plant.fmu.parameters. = [1]", "names one FMU variable"),
])
def test_a_vary_an_fmu_plant_cannot_take_is_refused_with_one_line(motor, tmp_path, vary, says):
    done = run(["sweep", str(motor), "--vary", vary, "--out", str(tmp_path / "bad")])
    assert done.returncode == 2, done.stderr
    assert says in done.stderr.splitlines()[0], done.stderr
    assert not (tmp_path / "bad" / "dc-motor-fmu.vary.csv").exists()


def test_an_fmu_parameter_of_a_built_in_plant_is_refused(tmp_path):
    path = tmp_path / "builtin.toml"
    path.write_text(DC_MOTOR.split("[plant.fmu]")[0] + DC_MOTOR.split("substeps = 4.0 }}")[1])
    done = run(["sweep", str(path), "--vary", "plant.fmu.parameters.J *= [2]", "--out", str(tmp_path / "o")])
    assert done.returncode == 2, done.stderr
    assert "plant is not an FMU" in done.stderr.splitlines()[0], done.stderr


def test_a_kit_component_plants_parameter_is_varied_as_single_runs_of_it(tmp_path):
    repo = pathlib.Path(REPO_DIR)
    text = (repo / "scenarios" / "cartpole-python-plant.toml").read_text()
    # 3 s (the push from 2 s), without the [expect] table measured on the full 10 s.
    text = text.split("\n[expect]")[0].replace("duration = 10.0", "duration = 3.0")
    text = text.replace("../components/", str(repo / "components") + "/")
    nominal = "pole_mass = 0.1,"
    assert nominal in text
    path = tmp_path / "cart.toml"
    path.write_text(text)
    out = tmp_path / "vary"
    done = run(["sweep", str(path), "--vary", "plant.process.params.pole_mass *= [0.5, 2]", "--out", str(out)])
    assert done.returncode == 0, done.stderr
    rows = read_csv(out / "cartpole-python-plant.vary.csv")
    assert [float(r["plant.process.params.pole_mass *= [0.5, 2]"]) for r in rows] == [1.0, 0.5, 2.0], rows
    for r, mass in zip(rows, ("0.1", "0.05", "0.2")):
        single = tmp_path / f"single-{mass}.toml"
        single.write_text(text.replace(nominal, f"pole_mass = {mass},"))
        ran = run(["run", str(single), "--out", str(tmp_path / f"r{mass}")])
        assert ran.returncode == 0, ran.stderr
        summary = json.loads((tmp_path / f"r{mass}" / "cartpole-python-plant.summary.json").read_text())
        for o in summary["observers"]:
            assert float(r[f"tail max|e| {o['name']}"]) == o["tail_max_abs_error"], (r, o)
    refused = run(["sweep", str(path), "--vary", "plant.process.params.nosuch *= [2]", "--out", str(tmp_path / "b")])
    assert refused.returncode == 2 and "no number for nosuch in [plant.process] params" in refused.stderr, refused.stderr
