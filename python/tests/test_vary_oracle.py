"""`uio-launcher sweep --vary`: the observers stay designed on the nominal model while the simulated
plant's matrices change. Checked against an independent simulation in NumPy/SciPy of each
point — the varied plant sampled exactly with its sinusoidal unknown input (the generator
augmented, `expm`), the observers' sampled matrices from `uio-launcher design --json`
(z⁺ = Fz + Gu + Ky, x̂ = Pz + Qy, z₀ = 0) — the tail max |x − x̂| of every observer at every
point to 1e-9; the grid's values are numpy's linspace; a distribution's draws are in range and
follow the seed; the nominal point is the plain run's; one PNG per figure and varied parameter.

The plant's second row carries the unknown input (E = e₂): a wrong A in that row enters as an
unknown input does, and the UIO absorbs it where the Luenberger observer does not.
"""

import csv
import json
import subprocess

import numpy as np
import pytest
from scipy.linalg import expm

from test_diagnosis_scipy import launcher

A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]]
C = [[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]]
E = [[0.0], [1.0], [0.0]]
X0 = [1.0, -1.0, 2.0]
DT, DURATION, F_HZ = 0.01, 4.0, 0.5

SCENARIO = f"""name = "mismatch"
dt = {DT}
duration = {DURATION}

[plant]
A = {A}
B = [[0.0], [1.0], [0.0]]
C = {C}
E = {E}
x0 = {X0}

[[disturbance]]
kind = "sine"
amplitude = 1.0
frequency_hz = {F_HZ}

[[input]]
kind = "constant"
value = 0.0

[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [-2.0, -3.0, -4.0]

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-2.0, -3.0, -4.0]
"""


def run(args, **kw):
    done = subprocess.run([launcher(), *args], capture_output=True, text=True, timeout=300, **kw)
    return done


def oracle_tail_errors(a, observers, dt=DT):
    """Each observer's tail max |x − x̂| on the plant with state matrix `a` (u = 0) sampled at
    `dt` (the observers' matrices as designed, whatever dt they were made for)."""
    n = len(a)
    w = 2 * np.pi * F_HZ
    aug = np.zeros((n + 2, n + 2))
    aug[:n, :n] = a
    aug[:n, n] = np.array(E)[:, 0]        # w = sin(ωt), the generator's first state
    aug[n, n + 1], aug[n + 1, n] = w, -w
    phi = expm(aug * dt)
    steps = round(DURATION / dt)
    s = np.concatenate([X0, [0.0, 1.0]])  # sin 0, cos 0
    c = np.array(C)
    xs = np.empty((steps, n))
    for k in range(steps):
        xs[k] = s[:n]
        s = phi @ s
    tail = steps - steps // 4
    out = {}
    for name, m in observers.items():
        f, k_, p, q = (np.array(m[x]) for x in ("F", "K", "P", "Q"))
        z = np.zeros(f.shape[0])
        worst = 0.0
        for k in range(steps):
            if k > 0:
                z = f @ z + k_ @ (c @ xs[k - 1])   # u = 0
            e = xs[k] - (p @ z + q @ (c @ xs[k]))
            if k >= tail:
                worst = max(worst, np.max(np.abs(e)))
        out[name] = worst
    return out


@pytest.fixture
def scenario(tmp_path):
    path = tmp_path / "mismatch.toml"
    path.write_text(SCENARIO)
    return path


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_every_points_tail_errors_follow_an_independent_simulation(scenario, tmp_path):
    design = run(["design", "--json", str(scenario)])
    assert design.returncode == 0, design.stdout + design.stderr
    observers = {o["name"]: o["sampled"] for o in json.loads(design.stdout)["observers"]}
    out = tmp_path / "out"
    done = run(["sweep", str(scenario), "--vary", "A[2,1] *= 0.5..1.5:5", "--vary", "A[2,2] *= [0.8, 1.25]",
                "--out", str(out)])
    assert done.returncode == 0, done.stderr
    rows = read_csv(out / "mismatch.vary.csv")
    assert len(rows) == 1 + 5 * 2
    assert rows[0]["nominal"] == "true" and float(rows[0]["A[2,1] *= 0.5..1.5:5"]) == 1.0
    grid = sorted({float(r["A[2,1] *= 0.5..1.5:5"]) for r in rows[1:]})
    assert grid == list(np.linspace(0.5, 1.5, 5))
    seen = {"uio": [], "luenberger": []}
    for r in rows:
        a = np.array(A)
        a[1, 0] *= float(r["A[2,1] *= 0.5..1.5:5"])
        a[1, 1] *= float(r["A[2,2] *= [0.8, 1.25]"])
        want = oracle_tail_errors(a, observers)
        for name, value in want.items():
            got = float(r[f"tail max|e| {name}"])
            assert abs(got - value) <= 1e-9 * max(value, 1e-12), (r, name, got, value)
            seen[name].append(got)
    # The mismatch lies in range(E): the UIO's tail error does not move (it is the sampling's
    # alone), its ŵ takes the mismatch up, and the Luenberger observer's error moves with it.
    spread = {n: (max(v) - min(v)) / v[0] for n, v in seen.items()}
    assert spread["uio"] <= 1e-6 and spread["luenberger"] >= 0.2, spread
    w = [float(r["tail max|ŵ−w| uio"]) for r in rows]
    assert max(w) >= 10 * w[0], w
    # The worst point named in the JSON is the CSV's largest.
    summary = json.loads((out / "mismatch.vary.json").read_text())
    assert summary["worst"]["tail max|e| luenberger"]["value"] == max(seen["luenberger"])
    assert "worst at" in done.stdout
    pngs = sorted(p.name for p in out.glob("mismatch.vary_*.png"))
    # A plot per figure and parameter, and a 2-D map per figure over the two parameters.
    assert len(pngs) == len(summary["columns"]) * 3, pngs
    for p in pngs:
        assert (out / p).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_nominal_point_is_the_plain_run(scenario, tmp_path):
    done = run(["sweep", str(scenario), "--vary", "A[2,1] *= [0.9]", "--out", str(tmp_path / "v")])
    assert done.returncode == 0, done.stderr
    plain = run(["run", str(scenario), "--mode", "in-process", "--out", str(tmp_path / "r")])
    assert plain.returncode == 0, plain.stderr
    summary = json.loads((tmp_path / "r" / "mismatch.summary.json").read_text())
    nominal = read_csv(tmp_path / "v" / "mismatch.vary.csv")[0]
    for o in summary["observers"]:
        assert float(nominal[f"tail max|e| {o['name']}"]) == o["tail_max_abs_error"]


def test_draws_are_in_range_and_follow_the_seed(scenario, tmp_path):
    def draws(seed, folder):
        done = run(["sweep", str(scenario), "--vary", "A[2,2] = U(-3.5, -2.5)", "--points", "6",
                    "--seed", str(seed), "--out", str(tmp_path / folder)])
        assert done.returncode == 0, done.stderr
        rows = read_csv(tmp_path / folder / "mismatch.vary.csv")
        assert float(rows[0]["A[2,2] = U(-3.5, -2.5)"]) == -3.0  # the nominal value, as set
        return [float(r["A[2,2] = U(-3.5, -2.5)"]) for r in rows[1:]]

    a, b, c = draws(1, "a"), draws(1, "b"), draws(2, "c")
    assert len(a) == 6 and all(-3.5 <= v <= -2.5 for v in a)
    assert a == b and a != c


@pytest.mark.parametrize("args,says", [
    (["--vary", "A[4,1] *= [1]"], "A is 3×3, it has no entry [4,1]"),
    (["--vary", "A[1,1] *= [1]", "--runs", "3"], "--runs: with --vary each point runs once"),
    (["--vary", "Q *= [1]"], "not one of the plant's matrices"),
    (["--vary", "A[1,1] *= U(1, 0)"], "lo < hi"),
])
def test_a_bad_vary_is_refused_with_one_line(scenario, tmp_path, args, says):
    done = run(["sweep", str(scenario), *args, "--out", str(tmp_path / "bad")])
    assert done.returncode == 2, done.stderr
    # The reason on the first line (clap adds its "For more information" line to its own).
    assert says in done.stderr.splitlines()[0], done.stderr
    assert not (tmp_path / "bad" / "mismatch.vary.csv").exists()


def test_the_python_package_varies_as_the_launcher_does(scenario, tmp_path):
    import uio_observers as uo

    varies = ["A[2,1] *= [0.5, 1.5]", "A[2,2] = U(-3.5, -2.5)"]
    cli = run(["sweep", str(scenario), *sum((["--vary", v] for v in varies), []), "--points", "3", "--jobs", "1",
               "--out", str(tmp_path / "cli")])
    assert cli.returncode == 0, cli.stderr
    got = uo.sweep(scenario, vary=varies, points=3, out=tmp_path / "py")
    assert got.summary == json.loads((tmp_path / "cli" / "mismatch.vary.json").read_text())
    for f in ("mismatch.vary.csv", "mismatch.vary.json"):
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    assert got.table in cli.stdout
    assert len(list((tmp_path / "py").glob("*.png"))) == len(list((tmp_path / "cli").glob("*.png")))
    with pytest.raises(ValueError, match="not one of the plant's matrices"):
        uo.sweep(scenario, vary="Q *= [1]")
    with pytest.raises(ValueError, match="a noise sweep's"):
        uo.sweep(scenario, vary=varies[0], runs=5)
