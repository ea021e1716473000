#!/usr/bin/env python3
"""Design time of a Chen–Patton UIO on random stiff models, ours beside scipy's.

For each n: a random stable model whose eigenvalues spread over three decades (−0.1 … −100, a
third of them as complex pairs, in a random orthogonal basis), p = n/10 outputs, two unknown
inputs, dt = 1 ms. Two scenarios are written with the model as `.npy` files: the UIO with
`gain = "lqe"` and with n placed poles. The launcher's `design` is timed as a whole process
(wall seconds, best of --runs); scipy is timed in-process on the same matrices and the same
pair: one `expm` for Φ, Γ_E, then H = Γ_E(CΓ_E)⁺, T = I − HC, and `solve_discrete_are((TΦ)ᵀ, Cᵀ,
I, I)` with the gain, or `place_poles((TΦ)ᵀ, Cᵀ, e^{p·dt})` (Tits–Yang). Every timing runs in a
child process with a time limit; one that runs out is reported as "> limit".

    .venv/bin/python scripts/design-bench.py [--sizes 50,200,500,1000] [--limit 300] [--runs 3] [--gains lqe,place]
    .venv/bin/python scripts/design-bench.py --andes kundur,ieee14,ieee39,npcc,wecc [--dt 0.001] --gains lqe

With `--andes`, the models are the real power-system ones in `fixtures/andes/<case>/` (their
design times beside scipy's) instead of random ones; IEEE 39 and WECC are refused by both (an
unseen mode at s = 0), so their rows time the refusal against scipy's DARE failing.

The launcher is the release build in $CARGO_TARGET_DIR (default target/).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DT = 1e-3


def model(n, rng):
    p, q = max(n // 10, 2), 2
    mags = np.logspace(-1, 2, n)
    t = np.zeros((n, n))
    i = 0
    while i < n:
        if i + 1 < n and rng.random() < 0.33:
            s, w = -mags[i], mags[i] * rng.uniform(0.5, 3.0)
            t[i:i + 2, i:i + 2] = [[s, w], [-w, s]]
            i += 2
        else:
            t[i, i] = -mags[i]
            i += 1
    t += np.triu(rng.standard_normal((n, n)) * 0.1, 2)
    basis, _ = np.linalg.qr(rng.standard_normal((n, n)))
    return basis @ t @ basis.T, rng.standard_normal((n, 2)), rng.standard_normal((p, n)), rng.standard_normal((n, q))


def poles(n):
    return [-1.0 - 0.2 * i for i in range(n)]


def scenarios(d, n, a, b, c, e, dt=DT):
    for k, v in dict(A=a, B=b, C=c, E=e).items():
        np.save(d / f"{k}.npy", v)
    disturbances = "".join(f'[[disturbance]]\nkind = "constant"\nvalue = {0.3 if i % 2 == 0 else -0.2}\n' for i in range(e.shape[1]))
    inputs = "".join('[[input]]\nkind = "constant"\nvalue = 0.0\n' for _ in range(b.shape[1]))
    head = f"""name = "stiff{n}"
dt = {dt}
duration = {10 * dt}
[plant]
A = "A.npy"
B = "B.npy"
C = "C.npy"
E = "E.npy"
x0 = [{", ".join("0.0" for _ in range(n))}]
{disturbances}{inputs}[[observer]]
name = "uio"
kind = "chen-patton-uio"
"""
    (d / "lqe.toml").write_text(head + 'gain = "lqe"\n')
    (d / "place.toml").write_text(head + f"poles = [{', '.join(map(repr, poles(n)))}]\n")


SCIPY = r"""
import sys, time, numpy as np, scipy.linalg as sla, scipy.signal as sig
d, what = sys.argv[1], sys.argv[2]
a, b, c, e = (np.load(f"{d}/{k}.npy") for k in "ABCE")
n, dt = a.shape[0], float(sys.argv[3])
t0 = time.perf_counter()
m = np.zeros((n + e.shape[1],) * 2); m[:n, :n] = a; m[:n, n:] = e
x = sla.expm(m * dt); phi, ge = x[:n, :n], x[:n, n:]
h = ge @ np.linalg.pinv(c @ ge); t1 = (np.eye(n) - h @ c) @ phi
if what == "lqe":
    p = sla.solve_discrete_are(t1.T, c.T, np.eye(n), np.eye(c.shape[0]))
    k1 = t1 @ p @ c.T @ np.linalg.inv(c @ p @ c.T + np.eye(c.shape[0]))
    ok = max(abs(np.linalg.eigvals(t1 - k1 @ c))) < 1
else:
    want = np.exp(np.array([-1.0 - 0.2 * i for i in range(n)]) * dt)
    r = sig.place_poles(t1.T, c.T, want, method="YT")
    got = np.sort(np.linalg.eigvals(t1 - r.gain_matrix.T @ c).real)
    ok = bool(np.max(np.abs(got - np.sort(want)) / np.abs(want)) < 1e-3)
print(time.perf_counter() - t0, ok)
"""


def timed(cmd, limit):
    t0 = time.perf_counter()
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=limit)
    except subprocess.TimeoutExpired:
        return None, f"> {limit} s"
    return time.perf_counter() - t0, done


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="50,200,500,1000")
    ap.add_argument("--limit", type=float, default=300.0)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--gains", default="lqe,place", help="which designs to time: lqe, place or both")
    ap.add_argument("--andes", default="", help="real models from fixtures/andes instead of random ones")
    ap.add_argument("--dt", type=float, default=DT)
    args = ap.parse_args()
    target = os.environ.get("CARGO_TARGET_DIR") or str(REPO / "target")
    launcher = os.path.join(target, "release", "uio-launcher")
    rows = []
    cases = args.andes.split(",") if args.andes else [int(s) for s in args.sizes.split(",")]
    for case in cases:
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            if args.andes:
                a, b, c, e = (np.load(REPO / "fixtures" / "andes" / case / f"{k}.npy") for k in "ABCE")
            else:
                a, b, c, e = model(case, np.random.default_rng(case))
            n = a.shape[0]
            scenarios(d, n, a, b, c, e, args.dt)
            row = {"n": n, "p": c.shape[0], "case": case}
            for what in args.gains.split(","):
                best, verdict = None, ""
                for _ in range(args.runs):
                    wall, done = timed([launcher, "design", str(d / f"{what}.toml")], args.limit)
                    if wall is None:
                        verdict = done
                        break
                    verdict = "designed" if done.returncode == 0 else f"refused (exit {done.returncode})"
                    best = wall if best is None else min(best, wall)
                row[f"ours_{what}"] = (best, verdict)
                best, verdict = None, ""
                for _ in range(args.runs):
                    _, done = timed([sys.executable, "-c", SCIPY, str(d), what, str(args.dt)], args.limit)
                    if isinstance(done, str):
                        verdict = done
                        break
                    if done.returncode != 0:
                        verdict = "failed: " + done.stderr.strip().splitlines()[-1]
                        break
                    secs, ok = done.stdout.split()
                    best = float(secs) if best is None else min(best, float(secs))
                    verdict = ("stable" if ok == "True" else "not stable") if what == "lqe" else ("placed" if ok == "True" else "missed")
                row[f"scipy_{what}"] = (best, verdict)
            rows.append(row)
            print(json.dumps(row), flush=True)
    print("\n| case | n | p | ours, lqe | scipy, DARE | ours, placement | scipy, place_poles (YT) |")
    print("|---|---|---|---|---|---|---|")
    fmt = lambda v: (f"{v[0]:.2f} s " if v[0] is not None else "") + v[1] if v else "—"
    for r in rows:
        cells = [fmt(r.get(k)) for k in ("ours_lqe", "scipy_lqe", "ours_place", "scipy_place")]
        print(f"| {r['case']} | {r['n']} | {r['p']} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
