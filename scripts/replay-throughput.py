#!/usr/bin/env python3
"""Replay throughput (BENCHMARKS.md): the 10⁵-row log of python/tests/test_replay.py's
throughput test (two DC motors, every state measured, one Chen–Patton UIO, dt = 1 ms, 100 s)
replayed from a CSV and from an MCAP log (one JSON message per row, stamped with its time), and
the same scenario with the built-in plant driven by the same inputs (sines, w = 0) — each timed
as a whole `uio-launcher run` process (pre-flight, start-up, run, recording), interleaved, REPS
times; prints every run and the medians in rows/s with the ratios to the built-in plant.

    scripts/replay-throughput.py [REPS]      REPS default 3
    (the launcher: $CARGO_TARGET_DIR/release/uio-launcher, else target/release/uio-launcher)
"""

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python" / "tests"))
from test_replay import DT, C, motor_scenario, write_csv, write_mcap  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
LAUNCHER = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target") / "release" / "uio-launcher"
UIO = '[[observer]]\nname = "uio"\nkind = "chen-patton-uio"\npoles = [-20.0, -25.0, -30.0, -35.0, -40.0, -45.0]\n'
SINES = "".join(f'\n[[input]]\nkind = "sine"\namplitude = 1.0\nfrequency_hz = {1 / (2 * np.pi)}\nphase = {p}\n' for p in (0.0, np.pi / 2))
ZERO_W = '\n[[disturbance]]\nkind = "constant"\nvalue = 0.0\n' * 2


def scenarios(folder, duration=100.0):
    """CSV, MCAP and built-in plant scenarios over `duration` s: the CSV's and MCAP's rows are
    the test's random states with u = (sin t, cos t)."""
    steps = round(duration / DT)
    t = np.arange(steps + 1) * DT
    x = np.random.default_rng(1).standard_normal((steps + 1, 6))
    u, w = np.stack([np.sin(t), np.cos(t)], axis=1), np.zeros((steps + 1, 2))
    write_csv(folder / "big.csv", t, u, w, x, x @ C.T)
    write_mcap(folder / "big.mcap", t, u, w, x, x @ C.T)
    out = {}
    for kind, extra in (("csv", ""), ("mcap", 'channel = "/motor"')):
        text = motor_scenario(folder, csv=f"big.{kind}", duration=duration, extra=extra).read_text()
        out[kind] = folder / f"{kind}.toml"
        out[kind].write_text(text[: text.index("[[fault]]")] + UIO)
    text = out["csv"].read_text()
    out["built-in"] = folder / "built-in.toml"
    out["built-in"].write_text(text[: text.index("[plant.replay]")] + SINES + ZERO_W + "\n" + UIO)
    return out, steps + 1


def run(scenario, out, env):
    start = time.monotonic()
    done = subprocess.run([str(LAUNCHER), "run", str(scenario), "--out", str(out), "--force"], capture_output=True, text=True, env=env)
    wall = time.monotonic() - start
    if done.returncode != 0:
        sys.exit(f"{scenario}: exit {done.returncode}: {done.stderr.strip()}")
    return wall


def main():
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        runs = folder / "runs"
        runs.mkdir(mode=0o700)
        env = {**os.environ, "UIO_RUNS_DIR": str(runs)}
        scen, rows = scenarios(folder)
        walls = {k: [] for k in scen}
        for i in range(reps):
            for kind, path in scen.items():
                walls[kind].append(run(path, folder / f"out-{kind}", env))
                print(f"run {i + 1} {kind:8}: {walls[kind][-1]:.3f} s = {rows / walls[kind][-1]:,.0f} rows/s", flush=True)
        med = {k: statistics.median(v) for k, v in walls.items()}
        print(json.dumps({k: {"median_s": round(m, 3), "rows_per_s": round(rows / m), "vs_built_in": round(m / med["built-in"], 2)} for k, m in med.items()}, indent=1))


if __name__ == "__main__":
    main()
