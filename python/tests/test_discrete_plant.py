"""Discrete-time plants, `[plant] time = "discrete"` with Phi, Gamma_B, Gamma_E.

* ZOH equivalence: seed 002 with its piecewise unknown input (switching on samples) is run as
  given and as the discrete plant (Φ, Γ_B, Γ_E) that scipy's `expm` of [[A, B, E], [0, 0, 0]]·dt
  makes of it, the controller's G fixed to the continuous design's. The observers are designed
  on the discrete model directly (at e^{p·dt}); every recorded signal equals the continuous
  run's to rounding.
* The discrete UIO conditions: a plant whose (Φ, Γ_E, C) has its invariant zero at z = 1.1 is
  refused with that zero; one at z = 0.2 designs.
* What needs a continuous A is refused for a discrete plant with the field named.
"""

import csv
import json
import re
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla

from test_diagnosis_scipy import launcher

REPO = Path(__file__).resolve().parents[2]


def mat(m):
    return "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in np.atleast_2d(m)) + "]"


def run(path, out):
    done = subprocess.run([launcher(), "run", str(path), "--mode", "in-process", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    csv_dir = out / "csv"
    done = subprocess.run([launcher(), "export", "--csv", str(csv_dir), str(next(out.glob("*.rrd")))], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return csv_dir


def test_a_zoh_discrete_plant_records_the_continuous_run(tmp_path):
    source = REPO / "scenarios" / "seed002-piecewise.toml"
    text = source.read_text()
    data = tomllib.loads(text)
    done = subprocess.run([launcher(), "design", "--json", str(source)], capture_output=True, text=True, timeout=60)
    g = np.array(json.loads(done.stdout)["controller"]["matrices"]["G"])
    p = data["plant"]
    a, b, e = (np.array(p[k], dtype=float) for k in "ABE")
    n, l, q = a.shape[0], b.shape[1], e.shape[1]
    m = np.zeros((n + l + q,) * 2)
    m[:n, :n], m[:n, n:n + l], m[:n, n + l:] = a, b, e
    x = sla.expm(m * data["dt"])
    phi, gb, ge = x[:n, :n], x[:n, n:n + l], x[:n, n + l:]
    # The same G for both: the continuous placement's (placing e^{p·dt} on (Φ, Γ_B) would be
    # another gain; the observers' poles are the images e^{p·dt} in both designs).
    fixed = re.sub(r"(\[controller\][^\[]*?)poles = \[[^\]]*\]", lambda mm: mm.group(1) + "gain = " + mat(g), text, flags=re.S)
    assert "gain = " in fixed
    discrete = re.sub(r"^A = .*$", 'time = "discrete"\nPhi = ' + mat(phi), fixed, flags=re.M)
    discrete = re.sub(r"^B = .*$", "Gamma_B = " + mat(gb), discrete, flags=re.M)
    discrete = re.sub(r"^E = .*$", "Gamma_E = " + mat(ge), discrete, flags=re.M)
    (tmp_path / "cont.toml").write_text(fixed)
    (tmp_path / "disc.toml").write_text(discrete)
    design = subprocess.run([launcher(), "design", str(tmp_path / "disc.toml")], capture_output=True, text=True, timeout=60)
    assert design.returncode == 0 and "discrete-time plant" in design.stdout, design.stdout + design.stderr
    cont, disc = run(tmp_path / "cont.toml", tmp_path / "c"), run(tmp_path / "disc.toml", tmp_path / "d")
    files = sorted(f.name for f in cont.iterdir() if not f.name.startswith("latency") and "log10" not in f.name)
    assert "plant_x.csv" in files and "observer_uio_xhat.csv" in files and "observer_uio_what.csv" in files
    for name in files:
        with open(cont / name) as fa, open(disc / name) as fb:
            ra, rb = list(csv.reader(fa)), list(csv.reader(fb))
        assert ra[0] == rb[0] and len(ra) == len(rb) > 1000, name
        va = np.array([[float(v) for v in r[2:]] for r in ra[1:]])
        vb = np.array([[float(v) for v in r[2:]] for r in rb[1:]])
        scale = max(1.0, np.abs(va).max())
        assert np.abs(va - vb).max() <= 1e-11 * scale, (name, np.abs(va - vb).max())


PLANT = """name = "zero"
dt = 0.1
duration = 5.0
[plant]
time = "discrete"
Phi = [[0.5, 0.0], [0.0, 0.8]]
Gamma_B = [[1.0], [0.0]]
Gamma_E = [[1.0], [1.0]]
C = [[1.0, {c2}]]
x0 = [1.0, -1.0]
[[disturbance]]
kind = "step"
time = 1.0
before = 0.0
after = 0.5
[[input]]
kind = "constant"
value = 0.0
[[observer]]
name = "uio"
kind = "chen-patton-uio"
gain = "lqe"
"""


def test_a_discrete_uio_needs_its_zeros_inside_the_unit_circle(tmp_path):
    # C(zI − Φ)⁻¹Γ_E = 1/(z − 0.5) + c₂/(z − 0.8): its zero is z = (0.8 + 0.5c₂)/(1 + c₂).
    bad = tmp_path / "bad.toml"
    bad.write_text(PLANT.format(c2=-0.5))  # z = 1.1
    done = subprocess.run([launcher(), "design", str(bad)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2, done.stdout + done.stderr
    said = done.stdout + done.stderr
    assert "invariant zeros" in said and "z = 1.1" in said, said
    good = tmp_path / "good.toml"
    good.write_text(PLANT.format(c2=-2.0))  # z = 0.2
    done = subprocess.run([launcher(), "design", str(good)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "0.2" in done.stdout


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda t: t.replace('time = "discrete"\n', ""), "plant.Phi"),
        (lambda t: t.replace("Phi = ", "A = "), "plant.A"),
        (lambda t: t + "[noise]\nprocess = [[1e-4, 0.0], [0.0, 1e-4]]\n", "noise.process"),
        (lambda t: t.replace('time = "discrete"', 'time = "sampled"'), "plant.time"),
    ],
)
def test_discrete_plant_refusals(tmp_path, edit, field):
    path = tmp_path / "s.toml"
    path.write_text(edit(PLANT.format(c2=-2.0)))
    done = subprocess.run([launcher(), "design", str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2, done.stdout + done.stderr
    line = done.stderr.strip()
    assert len(line.splitlines()) == 1 and str(path) in line and field in line, line


def test_faults_enter_a_discrete_plant_per_step(tmp_path):
    """An actuator bias on a discrete plant: x_{k+1} = Φx_k + Γ_B(u_k + f_k) + Γ_E w_k, with the
    step disturbance sampled at t_k, recomputed here from the recorded inputs."""
    text = PLANT.format(c2=-2.0) + '[[fault]]\nname = "bias"\ntarget = "actuator"\nchannel = 1\nkind = "additive"\nvalue = 0.3\nstart = 2.0\nend = 4.0\n'
    path = tmp_path / "f.toml"
    path.write_text(text)
    out = run(path, tmp_path / "o")
    table = lambda name: np.array([[float(v) for v in r[2:]] for r in list(csv.reader(open(out / name)))[1:]])
    x, w, r = table("plant_x.csv"), table("disturbance.csv"), table("input.csv")
    phi, gb, ge = np.array([[0.5, 0.0], [0.0, 0.8]]), np.array([[1.0], [0.0]]), np.array([[1.0], [1.0]])
    ours = x[0].copy()
    for k in range(len(x) - 1):
        f = 0.3 if 2.0 <= k * 0.1 < 4.0 - 1e-9 else 0.0
        ours = phi @ ours + gb @ (r[k] + f) + ge @ w[k]
        assert np.abs(ours - x[k + 1]).max() <= 1e-12, (k, ours, x[k + 1])
