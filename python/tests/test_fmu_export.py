"""Observers as FMUs (`uio-launcher export-fmu`): FMPy — an FMI importer independent of this
repository — runs each exported observer on a recording's u and y, and its x̂ and r must be the
recording's bit for bit.

* A scenario is run in one process and exported to CSV (bit-exact floats). Its observer is
  exported as an FMI 3.0 and an FMI 2.0 co-simulation FMU; `validate_fmu` finds no problem.
* FMU3Slave / FMU2Slave step it: at t_k the inputs y_k (/plant/y) and u_k (the input held over
  [t_k, t_{k+1}): /controller/u in closed loop, /input in open loop) are set, x̂_k and r_k read,
  then doStep(t_k, dt). x̂ must equal /observer/<name>/xhat and r /observer/<name>/residual
  exactly (numpy array_equal), at every recorded step.
* Observers: seed002-piecewise's Chen–Patton UIO and Luenberger observer (closed loop, P = I);
  seed003's Cumming observer (reduced order, P ≠ I) and its Das & Ghosal observer given an
  initial estimate x̂₀ (z_0 = P⁺(x̂₀ − Q y_0)).
* The FMU refuses a doStep of another size than dt, and an instantiation whose resources are
  garbled. `export-fmu` refuses an unknown observer (naming those it can export), a bank member,
  an external observer, and a launcher without its library: exit code 2, one line, no file.
"""

import csv
import json
import os
import re
import shutil
import subprocess
import tomllib
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

from test_diagnosis_scipy import launcher

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
XHAT0 = [0.5, -0.05, 0.1, 0.02]  # for seed003's four states, away from x0 = [1, 0.1, 0.05, 0]


def table(path):
    """A CSV of `uio-launcher export`: the value columns (after step, sim_time) as float64."""
    with open(path) as f:
        rows = list(csv.reader(f))
    return np.array([[float(v) for v in r[2:]] for r in rows[1:]])


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """Scenario name → (its file, CSV directory of its in-process run)."""
    base = tmp_path_factory.mktemp("runs")
    seed003 = (SCENARIOS / "seed003-charlie-open-loop.toml").read_text()
    # dgo with an initial estimate; the [expect] table (cumming and dgo agreeing) no longer holds.
    xhat0 = re.sub(r'(name = "dgo"\n)', r"\1xhat0 = " + repr(XHAT0) + "\n", seed003)
    xhat0 = xhat0[: xhat0.index("[expect]")]
    assert "xhat0" in xhat0
    (base / "seed003-xhat0.toml").write_text(xhat0)
    out = {}
    for name, path in [("seed002-piecewise", SCENARIOS / "seed002-piecewise.toml"), ("seed003-xhat0", base / "seed003-xhat0.toml")]:
        run = base / name
        done = subprocess.run([launcher(), "run", str(path), "--mode", "in-process", "--out", str(run)], capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        rrd = next(run.glob("*.rrd"))
        done = subprocess.run([launcher(), "export", "--csv", str(run / "csv"), str(rrd)], capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        out[name] = (path, run / "csv")
    return out


def export(scenario, observer, out, fmi):
    """`uio-launcher export-fmu`; the FMU's path (what it prints)."""
    done = subprocess.run([launcher(), "export-fmu", str(scenario), "--observer", observer, "--out", str(out), "--fmi", str(fmi)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    path = Path(done.stdout.strip())
    assert path.is_file() and path.parent == out, done.stdout
    return path


def slave(path, unzip):
    """An instantiated FMU2Slave / FMU3Slave of the FMU at `path`; its model description."""
    md = fmpy.read_model_description(str(path), validate=True)
    cls = FMU3Slave if md.fmiVersion == "3.0" else FMU2Slave
    fmu = cls(guid=md.guid, unzipDirectory=str(unzip), modelIdentifier=md.coSimulation.modelIdentifier, instanceName="observer")
    fmu.instantiate()
    return fmu, md


def drive(path, u, y, dt):
    """FMPy steps the FMU over the recording's u and y: (x̂, r) at every communication point."""
    fmu, md = slave(path, fmpy.extract(str(path)))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    l, p, n = u.shape[1], y.shape[1], sum(v.name.startswith("xhat_") for v in md.modelVariables)
    inputs = [vr[f"u_{i + 1}"] for i in range(l)] + [vr[f"y_{j + 1}"] for j in range(p)]
    outputs = [vr[f"xhat_{i + 1}"] for i in range(n)] + [vr[f"r_{j + 1}"] for j in range(p)]
    fmi3 = md.fmiVersion == "3.0"
    set_, get = (fmu.setFloat64, fmu.getFloat64) if fmi3 else (fmu.setReal, fmu.getReal)
    if fmi3:
        fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    values = np.empty((len(y), n + p))
    for k in range(len(y)):
        set_(inputs, list(u[k]) + list(y[k]))
        values[k] = get(outputs)
        if k + 1 < len(y):
            fmu.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
    fmu.terminate()
    fmu.freeInstance()
    return values[:, :n], values[:, n:]


CASES = [
    ("seed002-piecewise", "uio"),
    ("seed002-piecewise", "luenberger"),
    ("seed003-xhat0", "cumming"),
    ("seed003-xhat0", "dgo"),
]


@pytest.mark.parametrize("fmi", [3, 2])
@pytest.mark.parametrize("scenario,observer", CASES)
def test_the_fmu_reproduces_the_recorded_estimate_bit_for_bit(recordings, tmp_path, scenario, observer, fmi):
    path, csv_dir = recordings[scenario]
    data = tomllib.loads(path.read_text())
    fmu = export(path, observer, tmp_path, fmi)
    assert validate_fmu(str(fmu)) == []
    with zipfile.ZipFile(fmu) as z:
        platform = "x86_64-linux" if fmi == 3 else "linux64"
        assert f"binaries/{platform}/{observer}.so" in z.namelist()
        resource = json.loads(z.read("resources/observer.json"))
    # seed003's observers are of reduced order (z has r < n entries, P is n×r); dgo carries x̂₀ and P⁺.
    reduced = scenario.startswith("seed003")
    assert (resource["p"]["cols"] < resource["p"]["rows"]) == reduced
    assert ("p_pinv" in resource) == (observer == "dgo") == ("xhat0" in resource)
    y = table(csv_dir / "plant_y.csv")
    u = table(csv_dir / ("controller_u.csv" if "controller" in data else "input.csv"))
    xhat = table(csv_dir / f"observer_{observer}_xhat.csv")
    residual = table(csv_dir / f"observer_{observer}_residual.csv")
    assert len(y) == len(u) == len(xhat) == round(data["duration"] / data["dt"])
    got_xhat, got_r = drive(fmu, u, y, data["dt"])
    assert np.array_equal(got_xhat, xhat), np.abs(got_xhat - xhat).max()
    assert np.array_equal(got_r, residual), np.abs(got_r - residual).max()
    if observer == "dgo":
        # x̂₀ acted: without it dgo's estimate coincides with Cumming's (C = [I 0]), with it not.
        assert not np.allclose(xhat[0], table(csv_dir / "observer_cumming_xhat.csv")[0])


def fmpy_input(md, u, y, dt):
    """The recording's u and y as simulate_fmu's input table, at t_k = k·dt (the CSV's times)."""
    names = [v.name for v in md.modelVariables if v.causality == "input"]
    table = np.zeros(len(y), dtype=[("time", np.float64)] + [(n, np.float64) for n in names])
    table["time"] = np.arange(len(y)) * dt
    for i in range(u.shape[1]):
        table[f"u_{i + 1}"] = u[:, i]
    for j in range(y.shape[1]):
        table[f"y_{j + 1}"] = y[:, j]
    return table


@pytest.mark.parametrize("fmi", [3, 2])
@pytest.mark.parametrize("scenario,observer", CASES)
def test_fmpy_simulate_fmu_gives_the_recorded_estimate(recordings, tmp_path, scenario, observer, fmi):
    """FMPy's own simulate_fmu on the recording's u and y, output_interval = dt: every row is
    the recording's x̂ bit for bit where x̂ has no direct feedthrough (Q = 0). simulate_fmu
    samples the outputs right after doStep, before it sets the inputs of that point
    (fmpy/simulation.py, simulateCS), so with Q ≠ 0 its row k holds P z_k + Q y_{k−1}: the
    recording's x̂_k − Q(y_k − y_{k−1}), checked to 1e-12 of |x̂|'s scale. Its defaults (no
    output_interval: the DefaultExperiment's or fixedInternalStepSize dt, doubled until at most
    1000 rows) are accepted: steps of 2^j·dt, the inputs held."""
    path, csv_dir = recordings[scenario]
    data = tomllib.loads(path.read_text())
    dt = data["dt"]
    fmu = export(path, observer, tmp_path, fmi)
    md = fmpy.read_model_description(str(fmu))
    assert float(md.defaultExperiment.stepSize) == dt and float(md.defaultExperiment.stopTime) == data["duration"]
    with zipfile.ZipFile(fmu) as z:
        resource = json.loads(z.read("resources/observer.json"))
    q = resource["q"]
    Q = np.array(q["data"]).reshape(q["rows"], q["cols"])
    y = table(csv_dir / "plant_y.csv")
    u = table(csv_dir / ("controller_u.csv" if "controller" in data else "input.csv"))
    xhat = table(csv_dir / f"observer_{observer}_xhat.csv")
    n = xhat.shape[1]
    inputs = fmpy_input(md, u, y, dt)
    stop = (len(y) - 1) * dt
    res = fmpy.simulate_fmu(str(fmu), input=inputs, output_interval=dt, stop_time=stop)
    got = np.column_stack([res[f"xhat_{i + 1}"] for i in range(n)])
    assert len(got) == len(xhat) and np.array_equal(res["time"], inputs["time"])
    assert np.array_equal(got[0], xhat[0])
    if not Q.any():
        assert np.array_equal(got, xhat), np.abs(got - xhat).max()
    else:
        want = xhat[1:] - (y[1:] - y[:-1]) @ Q.T
        gap = np.abs(got[1:] - want).max()
        assert gap <= 1e-12 * np.abs(xhat).max(), gap
        # Not the recording's x̂ at those rows: the feedthrough shows.
        assert not np.array_equal(got, xhat)
    # FMPy's defaults: every 2^j·dt up to 1000 rows, the inputs held over each step.
    res = fmpy.simulate_fmu(str(fmu), input=inputs, stop_time=stop)
    j = int(np.ceil(np.log2(stop / dt / 1000))) if stop / dt > 1000 else 0
    assert len(res) == int(np.floor(stop / (dt * 2 ** j) + 1e-9)) + 1, (len(res), j)
    assert np.array_equal(np.column_stack([res[f"xhat_{i + 1}"] for i in range(n)])[0], xhat[0])


def test_an_observer_at_an_operating_point_takes_and_gives_absolute_signals(tmp_path):
    """The two-zone building's UIO, designed in deviations from 20 °C / 5 °C and run on the
    plant's absolute signals: its FMU (the point inside, the inputs starting there, units from
    the scenario) gives the recording's absolute x̂ and r bit for bit."""
    import test_operating_point_loop as building
    scen = building.scenario(tmp_path / "building.toml")
    run = tmp_path / "run"
    done = subprocess.run([launcher(), "run", str(scen), "--mode", "in-process", "--out", str(run)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    subprocess.run([launcher(), "export", "--csv", str(run / "csv"), str(next(run.glob("*.rrd")))], check=True, capture_output=True, timeout=300)
    y, u = table(run / "csv" / "plant_y.csv"), table(run / "csv" / "controller_u.csv")
    xhat, residual = table(run / "csv" / "observer_uio_xhat.csv"), table(run / "csv" / "observer_uio_residual.csv")
    assert np.abs(xhat[0] - building.X_OP).max() < 1e-9  # it starts at the point, in °C
    for fmi in (3, 2):
        fmu = export(scen, "uio", tmp_path / f"fmi{fmi}", fmi)
        assert validate_fmu(str(fmu)) == []
        md = fmpy.read_model_description(str(fmu))
        units = {v.name: (v.unit, v.start) for v in md.modelVariables}
        assert units["u_1"] == ("kW", repr(float(building.U_OP[0]))) and units["u_3"][0] == "degC", units
        assert units["y_1"][1] is not None and float(units["y_1"][1]) == 20.0
        got_xhat, got_r = drive(fmu, u, y, building.DT)
        assert np.array_equal(got_xhat, xhat), np.abs(got_xhat - xhat).max()
        assert np.array_equal(got_r, residual), np.abs(got_r - residual).max()


def test_a_step_of_another_size_and_garbled_resources_are_refused(tmp_path):
    fmu = export(SCENARIOS / "seed002-piecewise.toml", "uio", tmp_path, 3)
    unzip = Path(fmpy.extract(str(fmu)))
    slave3, _ = slave(fmu, unzip)
    slave3.enterInitializationMode(startTime=0.0)
    slave3.exitInitializationMode()
    slave3.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.001)
    with pytest.raises(FMICallException):
        slave3.doStep(currentCommunicationPoint=0.001, communicationStepSize=0.0015)
    slave3.freeInstance()
    (unzip / "resources" / "observer.json").write_text('{"format": 1, "token": ')
    with pytest.raises(Exception, match="[Ff]ailed to instantiate"):
        slave(fmu, unzip)


def refused(tmp_path, *args):
    """`uio-launcher export-fmu …` that must fail: its one-line message; nothing written."""
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    done = subprocess.run([*args[:1], "export-fmu", *map(str, args[1:]), "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stdout + done.stderr
    assert list(out.iterdir()) == [], list(out.iterdir())
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    return done.stderr


def test_refusals_are_one_line_exit_2_and_write_nothing(tmp_path):
    piecewise = SCENARIOS / "seed002-piecewise.toml"
    e = refused(tmp_path, launcher(), piecewise, "--observer", "nope")
    assert "no observer 'nope'" in e and "uio, luenberger" in e
    faults = SCENARIOS / "seed002-actuator-faults.toml"
    bank = tomllib.loads(faults.read_text())["diagnoser"][0]["name"]
    e = refused(tmp_path, launcher(), faults, "--observer", f"{bank}-1")
    assert "member of diagnoser" in e
    external = tmp_path / "external.toml"
    external.write_text(piecewise.read_text().replace('[[observer]]\nname = "luenberger"', '[[observer]]\nname = "ext"\nkind = "process"\ncommand = ["python3", "obs.py"]\n\n[[observer]]\nname = "luenberger"'))
    e = refused(tmp_path, launcher(), external, "--observer", "ext")
    assert "external process" in e and "no matrices" in e
    # A launcher with no library beside it.
    lonely = tmp_path / "bin" / "uio-launcher"
    lonely.parent.mkdir()
    try:
        os.link(launcher(), lonely)
    except OSError:
        shutil.copy2(launcher(), lonely)
    e = refused(tmp_path, lonely, piecewise, "--observer", "uio")
    assert "cargo build --release -p fmu-observer" in e
