"""Observers on recorded data (`[plant.replay]`, `uio-launcher replay`):

* a CSV log of the DC motor with Coulomb friction, simulated here by scipy's solve_ivp (not our
  plant) with an additive actuator fault in it, replayed through a UIO and a bank of UIOs: the
  bank detects the fault, and raises no alarm before it (the friction acts through E);
* a run's .rrd replayed with its own scenario records the original bit for bit (open loop), or
  the same observer signals bit for bit (closed loop, replayed open loop with the recorded u);
* a replay with another scenario of the same plant runs; one with another plant's sizes does not;
* bad data exits 2 before anything runs, naming file, line/column and reason, leaving nothing;
* `resample = "zoh"` puts a log with missing rows on the grid and counts the held samples;
* an MCAP log of the CSV's rows (JSON messages) replays to the CSV replay's recording bit for
  bit, a run's `uio-launcher export --mcap` replays to its observer signals bit for bit, and a bad
  MCAP (no such channel, not JSON, a missing or non-finite field, time going back) exits 2.
"""

import json
import os
import re
import subprocess
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from conftest import REPO
from test_diagnosis_scipy import launcher

SCEN = os.path.join(REPO, "scenarios")

# Two DC motors of scenarios/dc-motor-friction.toml, each x = [i, ω, θ], u = voltage,
# w = load torque, with Coulomb friction on each shaft; every state is measured.
A1 = np.array([[-2.0, -0.02, 0.0], [1.0, -10.0, 0.0], [0.0, 1.0, 0.0]])
A = np.kron(np.eye(2), A1)
B = np.kron(np.eye(2), np.array([[2.0], [0.0], [0.0]]))
E = np.kron(np.eye(2), np.array([[0.0], [-100.0], [0.0]]))
C = np.eye(6)
TAU_C, OMEGA_S = 0.02, 0.05
DT = 0.001
FAULT_START, FAULT_VALUE = 5.0, 2.0
SWITCHES = (0.5, 1.0, 2.0, 3.0, FAULT_START, 6.0)


def motor_log(duration):
    """(t, u, w, x, y) on the grid: u and w held over each step (switching on samples), an
    additive fault on the first motor's voltage from FAULT_START on (the log's u is the
    commanded one), integrated by solve_ivp between the switching times."""
    steps = round(duration / DT)
    t = np.arange(steps + 1) * DT
    on = lambda t0: t >= t0 - 1e-9  # noqa: E731
    u = np.stack([np.where(on(0.5), 12.0, 0.0), np.where(on(1.0), 8.0, 0.0)], axis=1)
    w = np.stack([np.where(on(6.0), 0.02, np.where(on(2.0), 0.05, 0.0)), np.where(on(3.0), 0.03, 0.0)], axis=1)
    cuts = sorted({c for c in (0.0, *SWITCHES) if c < duration} | {duration})
    x = np.zeros((steps + 1, 6))
    x0 = np.zeros(6)
    for a, b in zip(cuts[:-1], cuts[1:]):
        ka, kb = round(a / DT), round(b / DT)
        ua = u[ka] + np.array([FAULT_VALUE if a >= FAULT_START else 0.0, 0.0])
        wa = w[ka]

        def f(_, s):
            return A @ s + B @ ua + E @ (wa + TAU_C * np.tanh(s[[1, 4]] / OMEGA_S))

        sol = solve_ivp(f, (a, b), x0, t_eval=t[ka:kb + 1], method="LSODA", rtol=1e-10, atol=1e-12)
        assert sol.success
        x[ka:kb + 1] = sol.y.T
        x0 = sol.y[:, -1]
    return t, u, w, x, x @ C.T


STATES = ["i1", "omega1", "theta1", "i2", "omega2", "theta2"]
OUTPUTS = [f"{s}_meas" for s in STATES]


def write_csv(path, t, u, w, x, y, drop=()):
    with open(path, "w") as f:
        f.write(",".join(["t", "volts1", "volts2", "load1", "load2", *STATES, *OUTPUTS]) + "\n")
        for k in range(len(t)):
            if k in drop:
                continue
            f.write(",".join(repr(float(v)) for v in (t[k], *u[k], *w[k], *x[k], *y[k])) + "\n")


def rows(m):
    return "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in r) + "]" for r in m) + "]"


def names(xs):
    return "[" + ", ".join(f'"{x}"' for x in xs) + "]"


def motor_scenario(folder, csv="motor.csv", duration=8.0, extra=""):
    text = f"""name = "motor-log"
dt = {DT}
duration = {duration}

[plant]
A = {rows(A)}
B = {rows(B)}
C = {rows(C)}
E = {rows(E)}
x0 = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]

[plant.replay]
path = "{csv}"
time = "t"
inputs = ["volts1", "volts2"]
outputs = {names(OUTPUTS)}
disturbances = ["load1", "load2"]
states = {names(STATES)}
{extra}

[[fault]]
name = "volts1-bias"
target = "actuator"
channel = 1
kind = "additive"
value = {FAULT_VALUE}
start = {FAULT_START}

[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [-20.0, -25.0, -30.0, -35.0, -40.0, -45.0]

[[diagnoser]]
name = "bank"
scheme = "generalized"
faults = "actuator"
observer = "chen-patton-uio"
poles = [-20.0, -25.0, -30.0, -35.0, -40.0, -45.0]
evaluation = "norm"
threshold = 1e-3
persistence = 5
ignore_before = 1.0
"""
    path = folder / "motor.toml"
    path.write_text(text)
    return path


def env(tmp_path):
    runs = tmp_path / "runs"
    runs.mkdir(mode=0o700, exist_ok=True)
    return {**os.environ, "UIO_RUNS_DIR": str(runs)}


def launch(tmp_path, *args, timeout=600):
    return subprocess.run([launcher(), *map(str, args)], env=env(tmp_path), capture_output=True, text=True, timeout=timeout)


def nothing_left(tmp_path, out):
    assert not out.exists(), f"{out} was created"
    assert os.listdir(tmp_path / "runs") == [], "a run directory was left"


def refused(tmp_path, scen, want):
    """`uio-launcher run scen` exits 2 with one line holding every phrase of `want`, leaving nothing."""
    out = tmp_path / "out"
    p = launch(tmp_path, "run", scen, "--out", out)
    assert p.returncode == 2, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1, p.stderr
    for w_ in want:
        assert w_ in p.stderr, p.stderr
    nothing_left(tmp_path, out)


@pytest.fixture(scope="module")
def motor(tmp_path_factory):
    folder = tmp_path_factory.mktemp("motor")
    t, u, w, x, y = motor_log(8.0)
    write_csv(folder / "motor.csv", t, u, w, x, y)
    return folder, (t, u, w, x, y)


def test_csv_log_of_a_nonlinear_plant_fault_detected(motor, tmp_path):
    folder, (t, u, w, x, y) = motor
    scen = motor_scenario(folder)
    out = tmp_path / "out"
    p = launch(tmp_path, "run", scen, "--out", out)
    assert p.returncode == 0, p.stderr
    s = json.loads((out / "motor-log.summary.json").read_text())
    assert s["replay"] == {"file": "motor.csv", "rows": len(t), "samples": len(t), "held_rows": 0, "held_cells": 0, "states": True, "disturbances": True}
    (fault,) = s["diagnosis"]["faults"]
    assert fault["detected_at"] is not None and FAULT_START <= fault["detected_at"] < FAULT_START + 0.1, fault
    assert 0 <= fault["delay"] < 0.1
    assert fault["isolated_as"] == "volts1-bias" and fault["correct"], fault
    assert s["diagnosis"]["false_alarms"] == 0
    # Before the fault the UIO rejects the friction (it enters through E): its error against
    # solve_ivp's states is at the discretisation's level, far below the fault's effect.
    (uio,) = [o for o in s["observers"] if o["name"] == "uio"]
    assert uio["fault_free"]["tail_max_abs_error"] < 1e-4, uio
    print(f"\nCSV replay: fault at {FAULT_START} s detected at {fault['detected_at']} s (delay {fault['delay'] * 1e3:.0f} ms), "
          f"UIO fault-free tail error {uio['fault_free']['tail_max_abs_error']:.2e}")


def test_zoh_counts_held_rows(motor, tmp_path):
    folder, (t, u, w, x, y) = motor
    drop = set(range(3000, 3010)) | {4444}
    write_csv(folder / "gappy.csv", t, u, w, x, y, drop=drop)
    scen = motor_scenario(folder, csv="gappy.csv")
    out = tmp_path / "out"
    p = launch(tmp_path, "run", scen, "--out", out)
    assert p.returncode == 2 and "gappy.csv: line 3002 (row 3001)" in p.stderr and "non-uniform" in p.stderr, p.stderr
    nothing_left(tmp_path, out)
    scen = motor_scenario(folder, csv="gappy.csv", extra='resample = "zoh"')
    p = launch(tmp_path, "run", scen, "--out", out)
    assert p.returncode == 0, p.stderr
    s = json.loads((out / "motor-log.summary.json").read_text())
    assert s["replay"]["held_rows"] == len(drop) and s["replay"]["rows"] == len(t) - len(drop), s["replay"]


@pytest.mark.parametrize("case", ["missing column", "non-finite cell", "empty cell", "time goes back", "too few rows", "controller"])
def test_bad_csv_exits_2_before_anything_runs(motor, tmp_path, case):
    folder, (t, u, w, x, y) = motor
    lines = (folder / "motor.csv").read_text().splitlines()
    extra, want = "", None
    if case == "missing column":
        lines[0] = lines[0].replace("theta2_meas", "theta2_mea")
        want = ["bad.csv: no column 'theta2_meas' (plant.replay.outputs[6])", "did you mean", "the header has 't', 'volts1'"]
    elif case == "non-finite cell":
        lines[101] = re.sub(r",[^,]*$", ",nan", lines[101])
        want = ['bad.csv: line 102 (row 101), column "theta2_meas"', "not finite"]
    elif case == "empty cell":
        cells = lines[51].split(",")
        cells[1] = ""
        lines[51] = ",".join(cells)
        want = ['bad.csv: line 52 (row 51), column "volts1"', "empty cell"]
    elif case == "time goes back":
        lines[201], lines[202] = lines[202], lines[201]
        want = ["bad.csv: line 203 (row 202), time column", "must increase"]
    elif case == "too few rows":
        lines = lines[:5001]
        want = ["bad.csv: 5000 rows", "runs 8000 steps"]
    elif case == "controller":
        extra = None
        want = ["controller", "cannot react to a controller"]
    (tmp_path / "bad.csv").write_text("\n".join(lines) + "\n")
    scen = motor_scenario(tmp_path, csv="bad.csv")
    if extra is None:
        scen.write_text(scen.read_text() + '\n[controller]\nkind = "lqr"\nobserver = "uio"\n')
    refused(tmp_path, scen, want)


def test_missing_hold(motor, tmp_path):
    folder, _ = motor
    lines = (folder / "motor.csv").read_text().splitlines()
    for i in (300, 301, 302):
        lines[i] = re.sub(r",[^,]*$", ",", lines[i])
    (tmp_path / "holes.csv").write_text("\n".join(lines) + "\n")
    scen = motor_scenario(tmp_path, csv="holes.csv", extra='missing = "hold"')
    out = tmp_path / "out"
    p = launch(tmp_path, "run", scen, "--out", out)
    assert p.returncode == 0, p.stderr
    assert json.loads((out / "motor-log.summary.json").read_text())["replay"]["held_cells"] == 3


def test_without_states_the_summary_says_so(motor, tmp_path):
    folder, _ = motor
    scen = motor_scenario(folder)
    scen.write_text(re.sub(r"^states = .*$", "", scen.read_text(), flags=re.M))
    out = tmp_path / "out"
    p = launch(tmp_path, "run", scen, "--out", out)
    assert p.returncode == 0, p.stderr
    s = json.loads((out / "motor-log.summary.json").read_text())
    assert s["replay"]["states"] is False
    # The detection does not need x: the same figures as with it.
    assert s["diagnosis"]["faults"][0]["isolated_as"] == "volts1-bias"
    # No error figure from a run without x: null in the JSON, "—" and the reason in the table
    # (before, the table printed max|x̂| as the error).
    uio = s["observers"][0]
    assert [uio[k] for k in ("tail_max_abs_error", "max_abs_error", "final_abs_error")] == [None] * 3, uio
    assert uio["fault_free"]["tail_max_abs_error"] is None and uio["fault_free"]["tail_max_abs_residual"] > 0
    assert uio["tail_max_abs_residual"] > 0
    assert any("holds no states" in u for u in s["unmeasured"]), s["unmeasured"]
    line = next(l for l in p.stdout.splitlines() if l.strip().startswith("uio "))
    assert line.split()[2] == "—", line
    assert "x − x̂ would be −x̂" in p.stdout


def test_without_disturbances_no_input_error_is_claimed(motor, tmp_path):
    """A log without w columns: the run takes w = 0, so |w − ŵ| would be |ŵ|; the summary gives
    none and says why, while the state errors (x is in the log) stay."""
    folder, _ = motor
    scen = motor_scenario(folder)
    full = tmp_path / "full"
    p = launch(tmp_path, "run", scen, "--out", full)
    assert p.returncode == 0, p.stderr
    with_w = json.loads((full / "motor-log.summary.json").read_text())["observers"][0]
    assert with_w["tail_max_abs_input_error"] is not None, with_w
    scen.write_text(re.sub(r"^disturbances = .*$", "", scen.read_text(), flags=re.M))
    out = tmp_path / "out"
    p = launch(tmp_path, "run", scen, "--out", out)
    assert p.returncode == 0, p.stderr
    s = json.loads((out / "motor-log.summary.json").read_text())
    uio = s["observers"][0]
    assert "tail_max_abs_input_error" not in uio and s["replay"]["disturbances"] is False
    assert uio["tail_max_abs_error"] is not None
    assert any("holds no unknown inputs" in u for u in s["unmeasured"]), s["unmeasured"]
    assert "max|w − ŵ|              —" in p.stdout or re.search(r"max\|w − ŵ\| +—", p.stdout), p.stdout


def compared(p):
    m = re.search(r"same: (\d+) values of (\d+) signals, bit for bit", p.stdout)
    assert p.returncode == 0 and m, p.stdout + p.stderr
    return int(m.group(1)), int(m.group(2))


def test_rrd_replay_open_loop_bit_for_bit(tmp_path):
    out = tmp_path / "orig"
    p = launch(tmp_path, "run", os.path.join(SCEN, "seed003-sensor-faults.toml"), "--out", out)
    assert p.returncode == 0, p.stderr
    rrd = out / "seed003-sensor-faults.rrd"
    p = launch(tmp_path, "replay", rrd)
    assert p.returncode == 0, p.stderr
    values, signals = compared(launch(tmp_path, "compare", rrd, out / "replay" / "seed003-sensor-faults.rrd"))
    print(f"\nopen-loop .rrd replay: {values} values of {signals} signals bit for bit")
    assert signals > 30
    a = json.loads((out / "seed003-sensor-faults.summary.json").read_text())
    b = json.loads((out / "replay" / "seed003-sensor-faults.summary.json").read_text())
    # Every signal's digest agrees; the scenario text (rewritten for the replay) and the
    # latencies (timing, not signals) are the only ones that differ.
    signal = lambda d: {k: v for k, v in d.items() if k != "scenario" and not k.startswith("/latency/")}  # noqa: E731
    assert a["diagnosis"] == b["diagnosis"] and signal(a["recording_digest"]) == signal(b["recording_digest"])
    assert len(signal(a["recording_digest"])) == signals
    # A replay does not overwrite what it replays.
    p = launch(tmp_path, "replay", rrd, "--out", out, "--force")
    assert p.returncode == 2 and "would overwrite" in p.stderr, p.stderr


def test_rrd_replay_closed_loop_observers_bit_for_bit_and_other_scenarios(tmp_path):
    out = tmp_path / "orig"
    p = launch(tmp_path, "run", os.path.join(SCEN, "seed002-sine.toml"), "--out", out)
    assert p.returncode == 0, p.stderr
    rrd = out / "seed002-sine.rrd"
    p = launch(tmp_path, "replay", rrd, "--out", tmp_path / "again")
    assert p.returncode == 0, p.stderr
    for d in ("orig", "again"):
        p = launch(tmp_path, "export", tmp_path / d / "seed002-sine.rrd", "--csv", tmp_path / f"csv-{d}")
        assert p.returncode == 0, p.stderr
    a, b = sorted(os.listdir(tmp_path / "csv-orig")), sorted(os.listdir(tmp_path / "csv-again"))
    assert "controller_u.csv" in a and "controller_u.csv" not in b  # replayed open loop
    same = [f for f in a if f.startswith(("observer_", "plant_")) and f in b]
    assert any(f.startswith("observer_uio_") for f in same) and len(same) >= 8
    for f in same:
        assert (tmp_path / "csv-orig" / f).read_bytes() == (tmp_path / "csv-again" / f).read_bytes(), f
    # Another scenario of the same plant: its observers on this run's samples.
    p = launch(tmp_path, "replay", rrd, "--scenario", os.path.join(SCEN, "seed002-piecewise.toml"), "--out", tmp_path / "other")
    assert p.returncode == 0, p.stderr
    s = json.loads((tmp_path / "other" / "seed002-piecewise.summary.json").read_text())
    assert s["steps"] == s["steps_planned"] and s["replay"]["states"] is True
    # Another plant's sizes: refused naming both, nothing written.
    p = launch(tmp_path, "replay", rrd, "--scenario", os.path.join(SCEN, "seed003-charlie-open-loop.toml"), "--out", tmp_path / "wrong")
    assert p.returncode == 2, p.stderr
    assert "seed002-sine.rrd: the recorded plant has n = 3" in p.stderr and "the scenario's plant has n = 4" in p.stderr, p.stderr
    nothing_left(tmp_path, tmp_path / "wrong")


def test_replay_throughput(tmp_path):
    """A 10⁵-row log, timed as a whole process (pre-flight, start-up, run, recording)."""
    duration = 100.0
    steps = round(duration / DT)
    t = np.arange(steps + 1) * DT
    rng = np.random.default_rng(1)
    x = rng.standard_normal((steps + 1, 6))
    u, w = np.stack([np.sin(t), np.cos(t)], axis=1), np.zeros((steps + 1, 2))
    write_csv(tmp_path / "big.csv", t, u, w, x, x @ C.T)
    scen = motor_scenario(tmp_path, csv="big.csv", duration=duration)
    text = scen.read_text()
    scen.write_text(text[: text.index("[[fault]]")] + '[[observer]]\nname = "uio"\nkind = "chen-patton-uio"\npoles = [-20.0, -25.0, -30.0, -35.0, -40.0, -45.0]\n')
    start = time.monotonic()
    p = launch(tmp_path, "run", scen, "--out", tmp_path / "out")
    wall = time.monotonic() - start
    assert p.returncode == 0, p.stderr
    print(f"\nreplay throughput: {steps + 1} rows in {wall:.2f} s = {(steps + 1) / wall:.0f} rows/s (whole process)")


# ---- MCAP logs: the fields of a JSON channel's messages mapped by name as a CSV's columns ----

FIELDS = ["t", "volts1", "volts2", "load1", "load2", *STATES, *OUTPUTS]


def write_mcap(path, t, u, w, x, y, topic="/motor", encoding="json", edit=None):
    """The CSV's rows as JSON messages on `topic`, stamped with t in ns (log and publish time).
    `edit(k, fields, stamp)` may return other (payload bytes, stamp) for message k."""
    from mcap.writer import Writer

    with open(path, "wb") as f:
        out = Writer(f)
        out.start()
        schema = out.register_schema(name="motor", encoding="jsonschema", data=json.dumps({"type": "object"}).encode())
        channel = out.register_channel(topic=topic, message_encoding=encoding, schema_id=schema)
        out.register_channel(topic="/notes", message_encoding="json", schema_id=schema)
        for k in range(len(t)):
            fields = dict(zip(FIELDS, (float(v) for v in (t[k], *u[k], *w[k], *x[k], *y[k]))))
            stamp = round(t[k] * 1e9)
            data = json.dumps(fields).encode()
            if edit is not None:
                data, stamp = edit(k, fields, stamp) or (data, stamp)
            out.add_message(channel_id=channel, log_time=stamp, data=data, publish_time=stamp)
        out.finish()


def mcap_scenario(folder, name="motor.mcap", time_field=True, extra=""):
    """The CSV scenario on an MCAP log: `channel` added, the time a field or the log_time."""
    scen = motor_scenario(folder, csv=name, extra=f'channel = "/motor"\n{extra}')
    if not time_field:
        scen.write_text(re.sub(r'^time = "t"\n', "", scen.read_text(), count=1, flags=re.M))
    return scen


@pytest.mark.parametrize("time_field", [True, False], ids=["time-field", "log-time"])
def test_mcap_log_replays_as_the_csv_bit_for_bit(motor, tmp_path, time_field):
    folder, (t, u, w, x, y) = motor
    csv_out, mcap_out = tmp_path / "csv", tmp_path / "mcap"
    p = launch(tmp_path, "run", motor_scenario(folder), "--out", csv_out)
    assert p.returncode == 0, p.stderr
    write_mcap(tmp_path / "motor.mcap", t, u, w, x, y)
    p = launch(tmp_path, "run", mcap_scenario(tmp_path, time_field=time_field), "--out", mcap_out)
    assert p.returncode == 0, p.stderr
    s = json.loads((mcap_out / "motor-log.summary.json").read_text())
    assert s["replay"] == {"file": "motor.mcap", "rows": len(t), "samples": len(t), "held_rows": 0, "held_cells": 0, "states": True, "disturbances": True}
    values, signals = compared(launch(tmp_path, "compare", csv_out / "motor-log.rrd", mcap_out / "motor-log.rrd"))
    print(f"\nMCAP replay ({'time field' if time_field else 'log_time'}): {values} values of {signals} signals equal the CSV replay's bit for bit")
    assert signals > 30 and values > 8000 * 30


def test_mcap_of_our_export_replays_open_loop_bit_for_bit(tmp_path):
    """`uio-launcher export --mcap` of an open-loop run, replayed with the run's scenario on the
    exported /plant/x, /plant/y and /input channels: every observer signal is the original's."""
    from mcap.reader import make_reader

    out = tmp_path / "orig"
    p = launch(tmp_path, "run", os.path.join(SCEN, "seed003-sensor-faults.toml"), "--out", out)
    assert p.returncode == 0, p.stderr
    folder = tmp_path / "scen"
    folder.mkdir()
    p = launch(tmp_path, "export", out / "seed003-sensor-faults.rrd", "--mcap", folder / "run.mcap")
    assert p.returncode == 0, p.stderr
    # Each channel's members, in order: the keys of its first message but step and sim_time.
    fields = {}
    with open(folder / "run.mcap", "rb") as f:
        for _, channel, message in make_reader(f).iter_messages(topics=["/plant/x", "/plant/y", "/input"]):
            fields.setdefault(channel.topic, [f"{channel.topic}.{k}" for k in json.loads(message.data) if k not in ("step", "sim_time")])
    assert [len(fields[c]) for c in ("/plant/x", "/plant/y", "/input")] == [4, 3, 1], fields
    # The path absolute, as `uio-launcher replay` writes it: the recording's copy of the scenario
    # then parses anywhere, so the exported headers carry the names and units too.
    text = open(os.path.join(SCEN, "seed003-sensor-faults.toml")).read()
    text += f"""
[plant.replay]
path = "{folder / 'run.mcap'}"
channel = ["/plant/x", "/plant/y", "/input"]
states = {names(fields["/plant/x"])}
outputs = {names(fields["/plant/y"])}
inputs = {names(fields["/input"])}
"""
    (folder / "seed003-sensor-faults.toml").write_text(text)
    p = launch(tmp_path, "run", folder / "seed003-sensor-faults.toml", "--out", tmp_path / "again")
    assert p.returncode == 0, p.stderr
    for d in ("orig", "again"):
        p = launch(tmp_path, "export", tmp_path / d / "seed003-sensor-faults.rrd", "--csv", tmp_path / f"csv-{d}")
        assert p.returncode == 0, p.stderr
    a, b = sorted(os.listdir(tmp_path / "csv-orig")), sorted(os.listdir(tmp_path / "csv-again"))
    same = [f for f in a if f.startswith(("observer_", "diagnos", "plant_", "input")) and f in b]
    assert sum(f.startswith("observer_kalman_") for f in same) >= 3 and any(f.startswith("diagnos") for f in same), same
    cells = 0
    for f in same:
        mine, theirs = (tmp_path / "csv-orig" / f).read_bytes(), (tmp_path / "csv-again" / f).read_bytes()
        assert mine == theirs, f
        cells += sum(len(line.split(b",")) - 2 for line in mine.splitlines()[1:])
    a = json.loads((out / "seed003-sensor-faults.summary.json").read_text())
    b = json.loads((tmp_path / "again" / "seed003-sensor-faults.summary.json").read_text())
    assert a["diagnosis"] == b["diagnosis"]
    print(f"\nexported MCAP replayed: {len(same)} groups, {cells} values equal the original's bit for bit")


def nan_at(k0, field):
    def edit(k, fields, stamp):
        if k == k0:
            fields[field] = float("nan")
            return json.dumps(fields).encode(), stamp  # Python writes a bare NaN
    return edit


def drop_at(k0, field):
    def edit(k, fields, stamp):
        if k == k0:
            del fields[field]
            return json.dumps(fields).encode(), stamp
    return edit


def swap_stamps(k0):
    def edit(k, fields, stamp):
        if k in (k0, k0 + 1):
            return json.dumps(fields).encode(), round((k0 + 1 if k == k0 else k0) * DT * 1e9)
    return edit


BAD_MCAP = {
    "no such channel": (dict(topic="/motors"), ["bad.mcap: no channel '/motor' (plant.replay.channel) (did you mean '/motors'?); the file has '/motors', '/notes'"]),
    "not json": (dict(encoding="cdr"), ['bad.mcap: channel "/motor" is encoded as "cdr"', 'only JSON channels']),
    "not an object": (dict(edit=lambda k, f, s: (b"[1, 2]", s) if k == 50 else None), ['bad.mcap: row 51 of "/motor": a JSON array, not an object']),
    "field missing": (dict(edit=drop_at(50, "volts1")), ['bad.mcap: row 51, field "volts1": not in the message', 'missing = "hold"']),
    "no such field": (dict(edit=lambda k, f, s: (json.dumps({("theta2_mea" if n == "theta2_meas" else n): v for n, v in f.items()}).encode(), s)),
                      ["bad.mcap: no field 'theta2_meas' (plant.replay.outputs[6]) in the first message of '/motor' (did you mean", "it has 't', 'volts1', 'volts2', 'load1'"]),
    "non-finite": (dict(edit=nan_at(100, "theta2_meas")), ['bad.mcap: row 101, field "theta2_meas": NaN is not finite']),
    "null": (dict(edit=lambda k, f, s: (json.dumps({**f, "omega1": None}).encode(), s) if k == 70 else None), ['bad.mcap: row 71, field "omega1": null is not finite']),
    "time goes back": (dict(edit=swap_stamps(200)), ["bad.mcap: row 202, log_time (s after the first message): t = 0.2 after t = 0.201: time stamps must increase"]),
}


@pytest.mark.parametrize("case", list(BAD_MCAP))
def test_bad_mcap_exits_2_before_anything_runs(motor, tmp_path, case):
    _, (t, u, w, x, y) = motor
    kwargs, want = BAD_MCAP[case]
    write_mcap(tmp_path / "bad.mcap", t, u, w, x, y, **kwargs)
    scen = mcap_scenario(tmp_path, name="bad.mcap", time_field=case != "time goes back")
    refused(tmp_path, scen, want)


def test_mcap_missing_hold(motor, tmp_path):
    """missing = "hold" fills a field left out, null or NaN as it fills a CSV's empty cell."""
    _, (t, u, w, x, y) = motor

    def edit(k, fields, stamp):
        if k == 300:
            fields["theta2_meas"] = None
        elif k == 301:
            fields["theta2_meas"] = float("nan")
        elif k == 302:
            del fields["theta2_meas"]
        else:
            return None
        return json.dumps(fields).encode(), stamp

    write_mcap(tmp_path / "holes.mcap", t, u, w, x, y, edit=edit)
    out = tmp_path / "out"
    p = launch(tmp_path, "run", mcap_scenario(tmp_path, name="holes.mcap", extra='missing = "hold"'), "--out", out)
    assert p.returncode == 0, p.stderr
    assert json.loads((out / "motor-log.summary.json").read_text())["replay"]["held_cells"] == 3


def test_a_log_without_input_columns_replays_as_u_zero(motor, tmp_path):
    """`inputs` is optional: a log of a plant whose known inputs held still
    replays with u = 0 (u_op at an operating point), the same bit for bit as the log with columns
    of zeros mapped to u."""
    folder, (t, u, w, x, y) = motor
    write_csv(folder / "still.csv", t, np.zeros_like(u), w, x, y)
    text = motor_scenario(folder, csv="still.csv", duration=2.0).read_text()
    assert 'inputs = ["volts1", "volts2"]\n' in text
    with_u = folder / "with-u.toml"
    with_u.write_text(text.replace('name = "motor-log"', 'name = "with-u"'))
    without = folder / "without-u.toml"
    without.write_text(text.replace('name = "motor-log"', 'name = "without-u"').replace('inputs = ["volts1", "volts2"]\n', ""))
    out = tmp_path / "out"
    for scen in (with_u, without):
        p = launch(tmp_path, "run", scen, "--out", out)
        assert p.returncode == 0, p.stderr
    values, signals = compared(launch(tmp_path, "compare", out / "with-u.rrd", out / "without-u.rrd"))
    assert values > 2000 * 6 and signals > 20, (values, signals)
