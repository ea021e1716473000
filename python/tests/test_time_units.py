"""Times and frequencies written with their units (`dt = "1 min"`, `duration = "48 h"`, a step at
`"12 h"`, a sine of `"1/day"`): the run is the same run as the scenario written in seconds and Hz,
bit for bit (`uio-launcher compare`), and a unit that is not one is refused naming the field (a signal's, its table and line)."""

import subprocess

import pytest

from test_diagnosis_scipy import launcher

PLANT = """
[plant]
A = [[-0.0002, 0.0001], [0.0001, -0.0003]]
B = [[0.0001], [0.0]]
C = [[1.0, 0.0], [0.0, 1.0]]
E = [[0.0, 0.0001], [0.0002, 0.0]]
x0 = [1.0, 0.5]

[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [-0.001, -0.002]

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-0.001, -0.002]
"""

WITH_UNITS = """name = "building"
dt = "1 min"
duration = "48 h"
""" + PLANT + """
[[input]]
kind = "step"
time = "12 h"
after = 1.0

[[disturbance]]
kind = "sine"
amplitude = 0.5
frequency_hz = "1/day"

[[disturbance]]
kind = "piecewise"
times = ["6 h", "30 h"]
values = [0.2, -0.1]
"""

IN_SECONDS = WITH_UNITS.replace('dt = "1 min"', "dt = 60.0").replace('duration = "48 h"', "duration = 172800.0") \
    .replace('time = "12 h"', "time = 43200.0").replace('frequency_hz = "1/day"', f"frequency_hz = {1 / 86400!r}") \
    .replace('times = ["6 h", "30 h"]', "times = [21600.0, 108000.0]")


def run(args):
    return subprocess.run([launcher(), *args], capture_output=True, text=True, timeout=300)


def test_a_scenario_written_in_hours_is_the_run_written_in_seconds(tmp_path):
    assert all(u not in IN_SECONDS for u in ('"1 min"', '"48 h"', '"12 h"', '"1/day"', '"6 h"'))
    for folder, text in (("h", WITH_UNITS), ("s", IN_SECONDS)):
        (tmp_path / f"{folder}.toml").write_text(text)
        done = run(["run", str(tmp_path / f"{folder}.toml"), "--mode", "in-process", "--out", str(tmp_path / folder)])
        assert done.returncode == 0, done.stderr
    done = run(["compare", str(tmp_path / "h" / "building.rrd"), str(tmp_path / "s" / "building.rrd")])
    assert done.returncode == 0 and "same" in done.stdout, done.stdout + done.stderr
    assert (tmp_path / "h" / "building.summary.json").read_text().count("172800") >= 1


@pytest.mark.parametrize("old,new,field", [
    ('duration = "48 h"', 'duration = "48 x"', "duration"),
    ('dt = "1 min"', 'dt = "one min"', "dt"),
    # A signal's field is named by its table (its kind chooses its fields) and its line.
    ('frequency_hz = "1/day"', 'frequency_hz = "1/week"', "disturbance[1]"),
    ('time = "12 h"', 'time = "12 hours"', "input[1]"),
])
def test_a_time_without_a_unit_we_know_is_refused_naming_its_field(tmp_path, old, new, field):
    bad = WITH_UNITS.replace(old, new)
    assert bad != WITH_UNITS
    (tmp_path / "bad.toml").write_text(bad)
    done = run(["run", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "out")])
    assert done.returncode == 2, done.stderr
    first = done.stderr.strip().splitlines()[0]
    assert "bad.toml" in first and field in first and new.split("= ")[1].strip('"') in first, first
    assert not (tmp_path / "out" / "building.rrd").exists()


def test_the_design_gives_each_pole_as_a_time_constant_in_a_readable_unit(tmp_path):
    (tmp_path / "h.toml").write_text(WITH_UNITS)
    done = run(["design", str(tmp_path / "h.toml")])
    assert done.returncode == 0, done.stderr
    lines = [ln for ln in done.stdout.splitlines() if "time constants" in ln]
    # Poles −0.001 and −0.002 1/s: τ = 1000 s and 500 s, read in minutes.
    assert lines and all("16.6667 min" in ln and "8.33333 min" in ln for ln in lines), lines


def _csv(path):
    import csv
    with open(path) as f:
        rows = list(csv.reader(f))
    return [[float(v) for v in r] for r in rows[1:]]


@pytest.mark.parametrize("tail,first", [('"12 h"', 2880 - 720), ("3600.0", 2880 - 60), (None, 2880 - 720)])
def test_the_tail_is_the_stretch_the_scenario_sets_else_the_last_quarter(tmp_path, tail, first):
    """`tail = "12 h"` on a 48 h run at dt = 1 min is its last 720 steps: the summary's, the table's and
    `inspect`'s tail figures are the maxima over those steps of the exported x − x̂ and y − Cx̂,
    bit for bit; an hour is the last 60; without `tail`, the last quarter (also 720 here, and
    different from the hour's figures)."""
    import json

    text = WITH_UNITS if tail is None else WITH_UNITS.replace('duration = "48 h"\n', f'duration = "48 h"\ntail = {tail}\n')
    (tmp_path / "h.toml").write_text(text)
    done = run(["run", str(tmp_path / "h.toml"), "--mode", "in-process", "--out", str(tmp_path / "out")])
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "out" / "building.summary.json").read_text())
    assert summary["tail_from_step"] == first
    want = "tail: last quarter" if tail is None else ("tail: last 12 h" if "12" in tail else "tail: last 60 min")
    assert want in done.stdout, done.stdout
    csv_dir = tmp_path / "csv"
    assert run(["export", "--csv", str(csv_dir), str(tmp_path / "out" / "building.rrd")]).returncode == 0
    x, y = _csv(csv_dir / "plant_x.csv"), _csv(csv_dir / "plant_y.csv")
    inspected = run(["inspect", "--json", str(tmp_path / "out" / "building.rrd")])
    assert inspected.returncode == 0, inspected.stderr
    by_name = {o["name"]: o for o in json.loads(inspected.stdout)["observers"]}
    for o in summary["observers"]:
        xhat = _csv(csv_dir / f"observer_{o['name']}_xhat.csv")
        assert len(xhat) == len(x) == 2880
        e = max(abs(a - b) for rx, rh in zip(x[first:], xhat[first:]) for a, b in zip(rx[2:], rh[2:]))
        # C = I here: r = y − x̂.
        r = max(abs(a - b) for ry, rh in zip(y[first:], xhat[first:]) for a, b in zip(ry[2:], rh[2:]))
        assert o["tail_max_abs_error"] == e, (o["name"], o["tail_max_abs_error"], e)
        assert o["tail_max_abs_residual"] == r
        assert by_name[o["name"]]["tail_max_abs_error"] == e


@pytest.mark.parametrize("tail", ['"3 days"', '"10 s"', "-60.0"])
def test_a_tail_longer_than_the_run_or_shorter_than_a_step_is_refused(tmp_path, tail):
    (tmp_path / "bad.toml").write_text(WITH_UNITS.replace('duration = "48 h"\n', f'duration = "48 h"\ntail = {tail}\n'))
    done = run(["run", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "out")])
    assert done.returncode == 2, done.stderr
    first = done.stderr.strip().splitlines()[0]
    assert "bad.toml" in first and "tail" in first, first
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


FAULT_IN_SECONDS = """
[[fault]]
name = "bias"
target = "sensor"
channel = 1
kind = "bias"
value = 0.3
profile = "intermittent"
intervals = [[21600.0, 25200.0], [108000.0, 111600.0]]
"""


def test_a_scenario_in_a_time_unit_is_the_run_written_in_seconds(tmp_path):
    """`time_unit = "min"` makes every bare simulated time minutes (dt, duration, tail, a step's
    time, piecewise times, fault intervals), while `frequency_hz` stays Hz and `stall_timeout`
    wall-clock seconds (2000 would be 33 h as minutes: refused as over a day): the same run as the
    one written in seconds, bit for bit."""
    in_minutes = IN_SECONDS.replace("dt = 60.0", 'time_unit = "min"\nstall_timeout = 2000\ndt = 1') \
        .replace("duration = 172800.0", "duration = 2880") \
        .replace("time = 43200.0", "time = 720").replace("times = [21600.0, 108000.0]", "times = [360, 1800]") \
        + FAULT_IN_SECONDS.replace("[[21600.0, 25200.0], [108000.0, 111600.0]]", "[[360, 420], [1800, 1860]]")
    in_hours_written = IN_SECONDS + FAULT_IN_SECONDS.replace(
        "[[21600.0, 25200.0], [108000.0, 111600.0]]", '[["6 h", "7 h"], ["30 h", "31 h"]]')
    for folder, text in (("min", in_minutes), ("s", IN_SECONDS + FAULT_IN_SECONDS), ("written", in_hours_written)):
        (tmp_path / f"{folder}.toml").write_text(text)
        done = run(["run", str(tmp_path / f"{folder}.toml"), "--mode", "in-process", "--out", str(tmp_path / folder)])
        assert done.returncode == 0, folder + done.stderr
    for other in ("min", "written"):
        done = run(["compare", str(tmp_path / other / "building.rrd"), str(tmp_path / "s" / "building.rrd")])
        assert done.returncode == 0 and "same" in done.stdout, other + done.stdout + done.stderr


def test_an_unknown_time_unit_is_refused_naming_it(tmp_path):
    (tmp_path / "bad.toml").write_text('time_unit = "fortnight"\n' + IN_SECONDS)
    done = run(["run", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "out")])
    assert done.returncode == 2, done.stderr
    first = done.stderr.strip().splitlines()[0]
    assert "bad.toml" in first and "time_unit" in first and "fortnight" in first, first


def test_the_plot_window_takes_times_with_units(tmp_path):
    """`plot --from "24 h" --to "36 h"` draws the same window as `--from 86400 --to 129600`."""
    (tmp_path / "h.toml").write_text(WITH_UNITS)
    assert run(["run", str(tmp_path / "h.toml"), "--mode", "in-process", "--out", str(tmp_path / "out")]).returncode == 0
    rrd = str(tmp_path / "out" / "building.rrd")
    pngs = {}
    for name, window in (("units", ["--from", "24 h", "--to", "36 h"]), ("s", ["--from", "86400", "--to", "129600"])):
        done = run(["plot", rrd, "--out", str(tmp_path / name), "--signals", "/plant/**", *window])
        assert done.returncode == 0, done.stderr
        pngs[name] = {p.name: p.read_bytes() for p in (tmp_path / name).glob("*.png")}
    assert pngs["units"] and pngs["units"] == pngs["s"]
    bad = run(["plot", rrd, "--out", str(tmp_path / "bad"), "--from", "24 fortnights"])
    assert bad.returncode == 2 and "fortnights" in bad.stderr, bad.stderr
