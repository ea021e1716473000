"""`uio-launcher sweep --vary` with two varied parameters draws a 2-D map per figure: its cells,
read back from the PNG with matplotlib's viridis (the colour map the launcher's plotters uses,
as eight control points), give the values of the `.vary.csv` — each grid point's value in a cell
of its colour, within 4 % of the figure's range — and a sweep with three varied parameters
names the maps it cannot draw."""

import csv
import os
import subprocess

import numpy as np
import pytest
from PIL import Image

from test_diagnosis_scipy import launcher

mpl_cm = pytest.importorskip("matplotlib.cm")


def sweep(tmp_path, *varies):
    args = [launcher(), "sweep", "seed002-sine", "--out", str(tmp_path)]
    for v in varies:
        args += ["--vary", v]
    done = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done


def cells(png, min_pixels):
    """The colours that fill at least `min_pixels` pixels, but white, black and greys."""
    img = np.asarray(Image.open(png).convert("RGB")).reshape(-1, 3)
    colours, counts = np.unique(img, axis=0, return_counts=True)
    keep = []
    for c, n in zip(colours, counts):
        grey = int(c.max()) - int(c.min()) < 12
        if n >= min_pixels and not grey:
            keep.append(c.astype(float))
    return keep


def viridis_position(colour):
    """t in [0, 1] whose matplotlib viridis colour is nearest."""
    t = np.linspace(0.0, 1.0, 2001)
    table = mpl_cm.viridis(t)[:, :3] * 255.0
    return t[np.argmin(np.linalg.norm(table - colour, axis=1))]


def test_two_varied_parameters_give_a_map_whose_cells_are_the_csvs_values(tmp_path):
    a, b = "A[2,1] *= 0.8..1.2:5", "A[2,2] *= 0.9..1.1:3"
    sweep(tmp_path, a, b)
    with open(tmp_path / "seed002-sine.vary.csv") as f:
        rows = [r for r in csv.DictReader(f) if r["nominal"] == "false" and r["status"] == "completed"]
    assert len(rows) == 15
    figure = "tail max|e| uio"
    values = np.array([float(r[figure]) for r in rows])
    maps = [p for p in os.listdir(tmp_path) if p.startswith("seed002-sine.vary_tail_max_e__uio__") and p.count("A_") == 2]
    assert len(maps) == 1, maps
    # A cell is ≈ 1100/5 × 600/3 pixels; the colour bar's rows are 30 pixels each.
    found = cells(tmp_path / maps[0], min_pixels=5000)
    # Each value has a cell of its colour, and each cell a value (values closer than a colour
    # step share one: 15 points, 13 colours here).
    assert 2 <= len(found) <= len(values), len(found)
    lo, hi = values.min(), values.max()
    read = np.array([lo + viridis_position(c) * (hi - lo) for c in found])
    tol = 0.04 * (hi - lo)
    assert all(np.min(np.abs(read - v)) <= tol for v in values), (np.sort(read), np.sort(values))
    assert all(np.min(np.abs(values - r)) <= tol for r in read), (np.sort(read), np.sort(values))

def test_three_varied_parameters_name_the_maps_they_cannot_draw(tmp_path):
    done = sweep(tmp_path, "A[2,1] *= [0.9, 1.1]", "A[2,2] *= [0.9, 1.1]", "A[1,2] *= [0.9, 1.1]")
    assert "no map of A[2,1] *= [0.9, 1.1] against A[2,2] *= [0.9, 1.1]: the other parameters take 2 values" in done.stdout + done.stderr
    pngs = [p for p in os.listdir(tmp_path) if p.endswith(".png")]
    assert pngs and not [p for p in pngs if p.count("A_") > 1], pngs
