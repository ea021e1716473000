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
