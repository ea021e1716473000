"""The unknown-input estimate ŵ of a UIO, read back from the recording.

Each run is exported to CSV (`uio-launcher export --csv`); here, independently, scipy samples the
plant (one `expm` of [[A, B, E], [0, 0, 0]]·dt) and forms ŵ_k = (CΓ_E)⁺(y_{k+1} − CΦx̂_k − CΓ_Bu_k)
from the recorded y, x̂ and the input the plant held (the controller's u, or the open-loop r).
The recorded ŵ must be that, and must estimate the recorded w:
* DC motor (`dc-motor-load-torque`, the load torque): within 1e-6 over the tail, for both UIOs;
* seed 002 with a piecewise w (`seed002-piecewise`) and the UIO started at x(0) (`xhat0`):
  exact to rounding at every step, the steps where w switches included.
"""

import csv
import json
import re
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from test_diagnosis_scipy import launcher

REPO = Path(__file__).resolve().parents[2]


def table(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return np.array([[float(v) for v in r[2:]] for r in rows[1:]])


def run(tmp_path, text, name):
    scenario = tmp_path / f"{name}.toml"
    scenario.write_text(text)
    out = tmp_path / "out"
    done = subprocess.run([launcher(), "run", str(scenario), "--mode", "in-process", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    csv_dir = tmp_path / "csv"
    done = subprocess.run([launcher(), "export", "--csv", str(csv_dir), str(out / f"{name}.rrd")], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / f"{name}.summary.json").read_text())
    return csv_dir, summary


def sampled(data):
    p = data["plant"]
    a, b, c, e = (np.array(p[k], dtype=float) for k in "ABCE")
    n, l = a.shape[0], b.shape[1]
    m = np.zeros((n + l + e.shape[1],) * 2)
    m[:n, :n], m[:n, n:n + l], m[:n, n + l:] = a, b, e
    x = sla.expm(m * data["dt"])
    return x[:n, :n], x[:n, n:n + l], x[:n, n + l:], c


def check(csv_dir, data, observer):
    phi, gb, ge, c = sampled(data)
    y, xhat, w = table(csv_dir / "plant_y.csv"), table(csv_dir / f"observer_{observer}_xhat.csv"), table(csv_dir / "disturbance.csv")
    u = table(csv_dir / ("controller_u.csv" if "controller" in data else "input.csv"))
    ours = table(csv_dir / f"observer_{observer}_what.csv")
    wg = np.linalg.pinv(c @ ge)
    scipy_w = (wg @ (y[1:].T - c @ phi @ xhat[:-1].T - c @ gb @ u[:-1].T)).T
    assert ours.shape == scipy_w.shape == w[:-1].shape, (ours.shape, scipy_w.shape)
    scale = max(1.0, np.abs(scipy_w).max())
    assert np.abs(ours - scipy_w).max() <= 1e-9 * scale, np.abs(ours - scipy_w).max()
    return np.abs(ours - w[:-1]).max(axis=1)


def test_dc_motor_load_torque(tmp_path):
    text = (REPO / "scenarios" / "dc-motor-load-torque.toml").read_text()
    data = tomllib.loads(text)
    csv_dir, summary = run(tmp_path, text, data["name"])
    tail = len(table(csv_dir / "plant_y.csv")) * 3 // 4
    for name in ("uio", "hui-zak"):
        err = check(csv_dir, data, name) if name == "uio" else None
        (o,) = [o for o in summary["observers"] if o["name"] == name]
        assert o["tail_max_abs_input_error"] <= 1e-6, o
        if err is not None:
            assert err[tail:].max() <= 1e-6, err[tail:].max()
    (lu,) = [o for o in summary["observers"] if o["name"] == "luenberger"]
    assert "tail_max_abs_input_error" not in lu


def test_seed002_piecewise_exact_from_the_true_start(tmp_path):
    text = (REPO / "scenarios" / "seed002-piecewise.toml").read_text()
    x0 = re.search(r"^x0 = (.*)$", text, re.M).group(1)
    text = text.replace('name = "uio"\n', f'name = "uio"\nxhat0 = {x0}\n', 1)
    data = tomllib.loads(text)
    csv_dir, summary = run(tmp_path, text, data["name"])
    err = check(csv_dir, data, "uio")
    w = table(csv_dir / "disturbance.csv")[:, 0]
    switches = np.flatnonzero(np.diff(w)) + 1
    assert len(switches) >= 2, switches
    assert err.max() <= 1e-9 * np.abs(w).max(), (err.max(), np.argmax(err))
    assert err[switches[switches < len(err)]].max() <= 1e-9 * np.abs(w).max()
