"""`uio-launcher export --mcap/--npz/--mat`: the same signals as the CSV export, bit for bit.

Two shipped scenarios (seed 002 with its piecewise unknown input and two observers; the vehicle
with a camera bias fault and a diagnoser) are run in-process and exported to all four formats in
one command. Each format is read back with an independent reader — the `mcap` package,
`numpy.load`, `scipy.io.loadmat` — and every value, step and time is compared with the CSV's
(shortest round-trip floats) by its bits. Where the CSV leaves a cell empty, npz and MAT hold
NaN and the MCAP message leaves the field out. Bad input exits as the CSV export does and leaves
no file behind.
"""

import csv
import json
import re
import shutil
import struct
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
import scipy.io
from mcap.reader import make_reader

from test_diagnosis_scipy import launcher

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = ["seed002-piecewise", "vehicle-camera-bias"]


def bits(v):
    return struct.pack("<d", v)


def export(rrd, *args):
    return subprocess.run([launcher(), "export", str(rrd), *map(str, args)], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module", params=SCENARIOS)
def exported(request, tmp_path_factory):
    out = tmp_path_factory.mktemp(request.param)
    done = subprocess.run([launcher(), "run", request.param, "--mode", "in-process", "--out", str(out / "run")], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rrd = next((out / "run").glob("*.rrd"))
    done = export(rrd, "--csv", out / "csv", "--mcap", out / "x.mcap", "--npz", out / "x.npz", "--mat", out / "x.mat")
    assert done.returncode == 0, done.stderr
    groups = {}
    for f in sorted((out / "csv").glob("*.csv")):
        with f.open(newline="") as fh:
            rows = list(csv.reader(fh))
        assert rows[0][:2] == ["step", "sim_time"]
        groups[f.stem] = {
            "headers": rows[0][2:],
            "steps": [int(r[0]) for r in rows[1:]],
            "times": [float(r[1]) for r in rows[1:]],
            "cells": [[float(c) if c else None for c in r[2:]] for r in rows[1:]],
        }
    assert len(groups) > 10
    return {"dir": out, "rrd": rrd, "groups": groups}


def test_some_group_lacks_values_at_steps_it_has(exported):
    """The case NaN is for: the CSV holds empty cells (in-process latency is timed every 16th
    step, groups do not share steps), so the alignment below is exercised."""
    g = exported["groups"]
    assert any(c is None for grp in g.values() for row in grp["cells"] for c in row) or len({len(x["steps"]) for x in g.values()}) > 1


def check_arrays(arrays, names, exported):
    """npz or MAT arrays against the CSV: `step` and `t` over every step, a group's rows equal
    to its CSV rows at its steps and NaN elsewhere. Returns the number of values compared."""
    groups = exported["groups"]
    steps = np.asarray(arrays["step"]).ravel()
    union = sorted({k for g in groups.values() for k in g["steps"]})
    assert steps.tolist() == union
    assert set(arrays) == {names(stem) for stem in groups} | {"t", "step"}
    t = np.asarray(arrays["t"], dtype=np.float64).ravel()
    compared = 0
    for stem, g in groups.items():
        a = np.asarray(arrays[names(stem)])
        assert a.dtype == np.float64 and a.shape == (len(union), len(g["headers"])), stem
        rows = np.searchsorted(steps, g["steps"])
        assert (steps[rows] == g["steps"]).all()
        for i, r in enumerate(rows):
            assert bits(t[r]) == bits(g["times"][i]), (stem, g["steps"][i])
            for j, cell in enumerate(g["cells"][i]):
                if cell is None:
                    assert np.isnan(a[r, j]), (stem, g["steps"][i], j)
                else:
                    assert bits(a[r, j]) == bits(cell), (stem, g["steps"][i], j, a[r, j], cell)
                    compared += 1
        others = np.setdiff1d(np.arange(len(union)), rows)
        assert np.isnan(a[others]).all(), stem
    return compared


def test_npz_equals_the_csv_bit_for_bit(exported):
    with np.load(exported["dir"] / "x.npz") as z:
        arrays = {k: z[k] for k in z.files}
    assert arrays["step"].dtype == np.int64
    compared = check_arrays(arrays, lambda stem: stem, exported)
    assert compared > 10_000
    print(f"{compared} npz values equal the CSV's")


def test_mat_equals_the_csv_bit_for_bit(exported):
    m = scipy.io.loadmat(exported["dir"] / "x.mat")
    assert m["__header__"].startswith(b"MATLAB 5.0 MAT-file")
    arrays = {k: v for k, v in m.items() if not k.startswith("__")}
    assert arrays["step"].dtype == np.int64 and arrays["step"].shape[1] == 1
    ident = lambda stem: re.sub(r"[^A-Za-z0-9]", "_", stem)  # noqa: E731  MATLAB identifiers
    compared = check_arrays(arrays, ident, exported)
    assert compared > 10_000
    print(f"{compared} MAT values equal the CSV's")


def test_mcap_equals_the_csv_bit_for_bit(exported):
    groups = exported["groups"]
    seen = {}
    with open(exported["dir"] / "x.mcap", "rb") as f:
        reader = make_reader(f)
        last = -1
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            # One channel per group, topic = the group's path, JSON with a JSON Schema.
            stem = channel.topic.lstrip("/").replace("/", "_")
            assert channel.message_encoding == "json" and schema.encoding == "jsonschema"
            if stem not in seen:
                props = json.loads(schema.data)["properties"]
                # The CSV's columns in order, by the field whose title is the column's header.
                by_title = {p["title"]: k for k, p in props.items() if k not in ("step", "sim_time")}
                assert sorted(by_title) == sorted(groups[stem]["headers"]) and len(by_title) == len(props) - 2, stem
                fields = [by_title[h] for h in groups[stem]["headers"]]
                seen[stem] = {"fields": fields, "rows": []}
            assert message.log_time >= last, "messages in time order across channels"
            last = message.log_time
            seen[stem]["rows"].append((message.log_time, message.publish_time, message.sequence, json.loads(message.data)))
    assert set(seen) == set(groups)
    compared = 0
    for stem, got in seen.items():
        g = groups[stem]
        assert [m["step"] for *_, m in got["rows"]] == g["steps"], stem
        for i, (log_time, publish_time, sequence, m) in enumerate(got["rows"]):
            t = g["times"][i]
            assert bits(m["sim_time"]) == bits(t)
            assert log_time == publish_time and abs(log_time - t * 1e9) <= 0.5 and sequence == i
            assert [k for k in m if k not in ("step", "sim_time")] == [f for f in got["fields"] if f in m], "fields in column order"
            for field, cell in zip(got["fields"], g["cells"][i]):
                if cell is None:
                    assert field not in m, (stem, g["steps"][i], field)
                else:
                    assert bits(m[field]) == bits(cell), (stem, g["steps"][i], field)
                    compared += 1
    assert compared > 10_000
    print(f"{compared} MCAP values equal the CSV's")


def test_an_unknown_input_estimate_is_named_after_its_unknown_input(exported):
    """ŵ_k's column is headed as w_k's (name and unit: `crosswind [N]`, `w1` where the scenario
    names none) and its MCAP field is w_k's field, in every observer that estimates w; before,
    the headers were the bare indices `1` and the fields `_1`."""
    groups = exported["groups"]
    w = groups["disturbance"]["headers"]
    estimates = [stem for stem in groups if stem.startswith("observer_") and stem.endswith("_what")]
    assert estimates, "the scenario has an observer that estimates w"
    with open(exported["dir"] / "x.mcap", "rb") as f:
        schemas = {c.topic.lstrip("/").replace("/", "_"): json.loads(s.data)["properties"] for s, c, _ in make_reader(f).iter_messages()}
    w_fields = [k for k in schemas["disturbance"] if k not in ("step", "sim_time")]
    for stem in estimates:
        assert groups[stem]["headers"] == w, stem
        assert [k for k in schemas[stem] if k not in ("step", "sim_time")] == w_fields, stem
        assert not any(re.fullmatch(r"_?\d+", h) for h in groups[stem]["headers"] + w_fields)


def test_every_format_together_and_alone_is_the_same_file(exported, tmp_path):
    """A format exported alone is byte for byte what the four-format export wrote — later:
    nothing of the clock gets in (zip entry times have a 2-second resolution)."""
    time.sleep(2.1)
    done = export(exported["rrd"], "--mat", tmp_path / "a.mat", "--npz", tmp_path / "a.npz")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "a.mat").read_bytes() == (exported["dir"] / "x.mat").read_bytes()
    assert (tmp_path / "a.npz").read_bytes() == (exported["dir"] / "x.npz").read_bytes()


FORMATS = [("--mcap", "x.mcap"), ("--npz", "x.npz"), ("--mat", "x.mat")]


def csv_exit(rrd, tmp_path):
    return export(rrd, "--csv", tmp_path / "csv-probe").returncode


def assert_failed(done, code, *words):
    """Exit `code` with a one-line error naming `words`."""
    assert done.returncode == code, (done.returncode, done.stderr)
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert all(w in done.stderr for w in words), done.stderr


def left_behind(d):
    """Exports or staged files under `d`."""
    return [p for p in d.rglob("*") if p.suffix in (".mcap", ".npz", ".mat") and p.is_file() or ".partial" in p.name]


@pytest.mark.parametrize("flag,name", FORMATS)
def test_a_missing_or_unreadable_recording(flag, name, tmp_path):
    for rrd in (tmp_path / "missing.rrd", tmp_path):  # absent; a directory
        done = export(rrd, flag, tmp_path / name)
        assert_failed(done, csv_exit(rrd, tmp_path), str(rrd))
        assert done.returncode == 2 and not left_behind(tmp_path)


@pytest.mark.parametrize("flag,name", FORMATS)
def test_an_output_that_cannot_be_written(flag, name, exported, tmp_path):
    # In a directory that does not exist.
    done = export(exported["rrd"], flag, tmp_path / "nowhere" / name)
    assert_failed(done, 2, "cannot write", str(tmp_path / "nowhere" / name))
    assert not (tmp_path / "nowhere").exists()
    # Where a directory is: the staged file is removed, the directory left as it was.
    taken = tmp_path / f"taken{Path(name).suffix}"
    taken.mkdir()
    (taken / "keep").write_text("kept")
    done = export(exported["rrd"], flag, taken)
    assert_failed(done, 2, "already exists (pass --force to overwrite)", str(taken))
    done = export(exported["rrd"], flag, taken, "--force")
    assert_failed(done, 2, "cannot write", str(taken))
    assert [p.name for p in taken.iterdir()] == ["keep"] and not left_behind(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == [taken.name]


def test_a_damaged_recording_writes_nothing(exported, tmp_path):
    """One bit of a sim_time stamp flipped (as tests/tests/features/recording_tools/damaged.rs does): exit 6, no file."""
    data = bytearray(exported["rrd"].read_bytes())
    t = round(exported["groups"]["plant_x"]["times"][1234] * 1e9)
    at = data.find(struct.pack("<q", t))
    assert at > 0
    data[at + 3] ^= 0x04
    bad = tmp_path / "bad.rrd"
    bad.write_bytes(data)
    args = [a for flag, name in FORMATS for a in (flag, tmp_path / name)]
    done = export(bad, *args)
    assert_failed(done, 6, "damaged", str(bad))
    assert csv_exit(bad, tmp_path) == 6 and not left_behind(tmp_path)


@pytest.mark.parametrize("flag", ["--mcap", "--npz", "--mat"])
def test_an_export_over_its_own_recording_is_refused(exported, tmp_path, flag):
    """Before, `export x.rrd --mcap x.rrd` replaced the recording with its own export."""
    rrd = tmp_path / "copy.rrd"
    shutil.copy(exported["rrd"], rrd)
    before = rrd.read_bytes()
    done = export(rrd, flag, tmp_path / "." / "copy.rrd")
    assert done.returncode == 2 and "is the recording being exported" in done.stderr, done.stderr
    assert rrd.read_bytes() == before


def test_no_format_is_a_usage_error(exported):
    done = export(exported["rrd"])
    assert done.returncode == 2 and "--mcap" in done.stderr



def test_existing_exports_are_replaced_only_with_force(exported, tmp_path):
    """Before, a second export silently replaced the first's files. Now it is refused (exit 2,
    naming the first file that exists, nothing written) unless --force, which replaces them."""
    args = ["--csv", tmp_path / "csv", "--mcap", tmp_path / "x.mcap", "--npz", tmp_path / "x.npz", "--mat", tmp_path / "x.mat"]
    assert export(exported["rrd"], *args).returncode == 0
    for f in [tmp_path / "x.mcap", tmp_path / "x.npz", tmp_path / "x.mat", *sorted((tmp_path / "csv").iterdir())]:
        f.write_bytes(b"mine")
    for one in (["--mcap", tmp_path / "x.mcap"], ["--csv", tmp_path / "csv"], args):
        done = export(exported["rrd"], *one)
        assert_failed(done, 2, "already exists (pass --force to overwrite)")
    files = [tmp_path / "x.mcap", tmp_path / "x.npz", tmp_path / "x.mat", *sorted((tmp_path / "csv").iterdir())]
    assert all(f.read_bytes() == b"mine" for f in files)
    # A CSV folder holding other files only is no conflict.
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("kept")
    assert export(exported["rrd"], "--csv", tmp_path / "other").returncode == 0
    assert (tmp_path / "other" / "notes.txt").read_text() == "kept"
    done = export(exported["rrd"], *args, "--force")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "x.npz").stat().st_size == (exported["dir"] / "x.npz").stat().st_size
    assert (tmp_path / "x.mcap").read_bytes()[:8] == b"\x89MCAP0\r\n"
    assert all(f.read_bytes() != b"mine" for f in files)
