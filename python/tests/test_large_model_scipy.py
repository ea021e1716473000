"""A 200-state model from `.npy` files, run in both modes, against scipy.

The matrices are made here with numpy and saved in three flavours (C order, Fortran order,
big-endian) that the scenario names by path. Both modes must give the same recording bit for
bit (`uio-launcher compare`), and the recorded plant states must follow the exact sampled plant
computed here, independently, from one `scipy.linalg.expm` of [[A, B, E], [0, 0, 0]]·dt:
x_{k+1} = Φx_k + Γ_B u_k + Γ_E w, with the controller's recorded u_k held over the step and a
constant unknown input w. At 200 states the Rust exponential runs in double precision
(lti::expm above 96 rows), and every sample holds hundreds of values.
"""

import csv
import os
import subprocess

import numpy as np
import scipy.linalg as sla

from test_diagnosis_scipy import launcher

N = 200
DT = 0.01
STEPS = 40
W = 0.3


def model(rng):
    a = rng.standard_normal((N, N)) / np.sqrt(N) - 2.0 * np.eye(N)
    b = rng.standard_normal((N, 2))
    c = rng.standard_normal((N, N))
    e = rng.standard_normal((N, 1))
    gain = 0.1 * rng.standard_normal((2, N)) / np.sqrt(N)
    return a, b, c, e, gain


def scenario(tmp_path, a, b, c, e, gain):
    d = tmp_path / "model"
    d.mkdir()
    np.save(d / "A.npy", a)
    np.save(d / "B.npy", np.asfortranarray(b))
    np.save(d / "C.npy", c.astype(">f8"))
    np.save(d / "E.npy", e)
    np.save(d / "G.npy", gain)
    poles = ", ".join(repr(-3.0 - 0.05 * i) for i in range(N))
    x0 = ", ".join(repr(float(0.1 * np.sin(i))) for i in range(N))
    text = f"""name = "large"
dt = {DT}
duration = {STEPS * DT}
[plant]
A = "model/A.npy"
B = "model/B.npy"
C = "model/C.npy"
E = "model/E.npy"
x0 = [{x0}]
[[disturbance]]
kind = "constant"
value = {W}
[[input]]
kind = "constant"
value = 0.0
[[input]]
kind = "constant"
value = 0.5
[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [{poles}]
[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [{poles}]
[controller]
kind = "state-feedback"
observer = "uio"
gain = "model/G.npy"
"""
    path = tmp_path / "large.toml"
    path.write_text(text)
    return path


def run(path, out, mode):
    done = subprocess.run(
        [launcher(), "run", str(path), "--out", str(out), "--mode", mode, "--force"],
        capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 0, f"uio-launcher run --mode {mode} exited {done.returncode}: {done.stderr}"
    return out / "large.rrd"


def table(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(v) for v in r] for r in rows[1:]])


def test_a_large_model_from_npy_files_follows_scipy_in_both_modes(tmp_path):
    a, b, c, e, gain = model(np.random.default_rng(2026))
    path = scenario(tmp_path, a, b, c, e, gain)
    procs = run(path, tmp_path / "processes", "processes")
    inproc = run(path, tmp_path / "in-process", "in-process")
    same = subprocess.run([launcher(), "compare", str(procs), str(inproc)], capture_output=True, text=True, timeout=120)
    assert same.returncode == 0 and "bit for bit" in same.stdout, same.stdout + same.stderr

    csv_dir = tmp_path / "csv"
    done = subprocess.run([launcher(), "export", "--csv", str(csv_dir), str(procs)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    head, x = table(csv_dir / "plant_x.csv")
    assert head[2:] == [f"x{i + 1}" for i in range(N)]
    _, u = table(csv_dir / "controller_u.csv")
    assert x.shape == (STEPS, N + 2) and u.shape == (STEPS, 4)
    x, u = x[:, 2:], u[:, 2:]

    # The exact sampled plant, from one block exponential.
    m = 3
    big = np.zeros((N + m, N + m))
    big[:N, :N], big[:N, N:N + 2], big[:N, N + 2:] = a, b, e
    blk = sla.expm(big * DT)
    phi, gam_b, gam_e = blk[:N, :N], blk[:N, N:N + 2], blk[:N, N + 2:]
    ref = np.empty_like(x)
    ref[0] = [0.1 * np.sin(i) for i in range(N)]
    for k in range(STEPS - 1):
        ref[k + 1] = phi @ ref[k] + gam_b @ u[k] + gam_e[:, 0] * W
    scale = np.abs(ref).max()
    assert np.abs(x - ref).max() <= 1e-10 * scale, np.abs(x - ref).max() / scale
    # The loop is closed: u is the gain on the UIO's estimate, which is not the plant's state.
    assert np.abs(u).max() > 0.0

    # The measured outputs are C x with C read from the big-endian file.
    _, y = table(csv_dir / "plant_y.csv")
    assert np.abs(y[:, 2:] - ref @ c.T).max() <= 1e-9 * np.abs(ref @ c.T).max()
