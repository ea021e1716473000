"""The Python package `uio_observers` (pyuio/, PyO3 + maturin), against the CLI:
its designs equal `uio-launcher design --json` bit for bit, a design from a python-control
StateSpace equals the one from its matrices, `run` and `read` give the recording's values as
the CSV export does, and bad input raises with the launcher's message."""

import csv
import json
import subprocess

import control
import numpy as np
import pytest

import uio_observers as uo
from test_diagnosis_scipy import launcher

# Seed 002 (Chen & Patton's example) and the DC motor of scenarios/dc-motor-load-torque.toml.
SEED002 = dict(A=[[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]], B=[[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]],
               C=[[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], E=[[2.0], [0.0], [0.5]])
MOTOR = dict(A=[[-2.0, -0.02, 0.0], [1.0, -10.0, 0.0], [0.0, 1.0, 0.0]], B=[[2.0], [0.0], [0.0]],
             C=[[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], E=[[0.0], [-100.0], [0.0]])

# 30 states: A (900 entries) and B go to the launcher as .npy files, not TOML text.
_rng = np.random.default_rng(30)
LARGE = dict(A=_rng.standard_normal((30, 30)) - 8 * np.eye(30), B=_rng.standard_normal((30, 2)),
             C=np.round(_rng.standard_normal((6, 30)), 2), E=_rng.standard_normal((30, 1)))

CASES = {
    "random-30-states-lqe": (LARGE, dict(kind="chen-patton-uio", gain="lqe", dt=0.01)),
    "seed002-chen-patton": (SEED002, dict(kind="chen-patton-uio", poles=[-1.0, -2.0, -3.0], placement="matlab", dt=0.001)),
    "seed002-luenberger-lqe": (SEED002, dict(kind="luenberger", gain="lqe", Q=np.eye(3), R=0.01 * np.eye(2), dt=0.01)),
    "motor-chen-patton": (MOTOR, dict(kind="chen-patton-uio", poles=[-20.0, -30.0], dt=0.001)),
    "motor-hui-zak": (MOTOR, dict(kind="hui-zak-uio", decay=1.0, dt=0.001)),
    "motor-complex-poles": (MOTOR, dict(kind="luenberger", poles=[-20.0, complex(-30.0, 5.0), complex(-30.0, -5.0)], dt=0.002)),
}


def cli_design(tmp_path, text):
    path = tmp_path / "design.toml"
    path.write_text(text)
    done = subprocess.run([launcher(), "design", "--json", str(path)], capture_output=True, text=True, timeout=120)
    return done


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_python_design_equals_the_launchers_bit_for_bit(tmp_path, case):
    plant, kw = CASES[case]
    d = uo.design(**plant, **kw)
    done = cli_design(tmp_path, uo.design_scenario(**plant, **kw))
    assert done.returncode == 0, done.stderr
    cli = json.loads(done.stdout)["observers"][0]
    assert d.json["observers"][0] == cli  # the whole report, every float by value
    for k in "FGKPQ":
        want = np.array(cli["sampled"][k], dtype=float).reshape(d.sampled[k].shape)
        assert np.array_equal(d.sampled[k].view(np.uint64), want.view(np.uint64)), k  # bits, signed zeros too
    for k, m in cli["matrices"].items():
        assert np.array_equal(d.continuous[k], np.array(m, dtype=float).reshape(d.continuous[k].shape)), k
    # The sampled observer's poles are its F's eigenvalues: the discrete poles reported.
    assert np.allclose(np.sort_complex(np.linalg.eigvals(d.sampled["F"])), np.sort_complex(d.discrete_poles), atol=1e-9)


def test_a_design_from_a_python_control_statespace():
    sys = control.ss(SEED002["A"], SEED002["B"], SEED002["C"], np.zeros((2, 2)))
    kw = dict(kind="chen-patton-uio", poles=[-1.0, -2.0, -3.0], dt=0.001)
    from_sys, from_matrices = uo.design(sys=sys, E=SEED002["E"], **kw), uo.design(**SEED002, **kw)
    for k in "FGKPQ":
        assert np.array_equal(from_sys.sampled[k], from_matrices.sampled[k]), k
    # As a python-control system from [u; y] to x̂, its poles are the design's discrete poles.
    obs = from_sys.statespace()
    assert obs.dt == 0.001 and obs.ninputs == 4 and obs.noutputs == 3
    # Named as what they are: the known inputs, the measurements, and the estimates.
    assert obs.input_labels == ["u1", "u2", "y1", "y2"] and obs.output_labels == ["xhat1", "xhat2", "xhat3"]
    assert np.allclose(np.sort_complex(obs.poles()), np.sort_complex(from_sys.discrete_poles), atol=1e-9)
    # A discrete-time model runs at its own period: another dt is refused, naming both.
    with pytest.raises(ValueError, match=r"^dt: 0.001 differs from sys.dt = 0.1"):
        uo.design(sys=control.ss(sys.A, sys.B, sys.C, sys.D, 0.1), E=SEED002["E"], **kw)
    with pytest.raises(ValueError, match=r"^sys.dt is True"):
        uo.design(sys=control.ss(sys.A, sys.B, sys.C, sys.D, True), E=SEED002["E"], kind="luenberger", poles=[-1.0])


@pytest.mark.parametrize("kind", ["luenberger", "chen-patton-uio"])
def test_a_discrete_time_model_designs_as_its_continuous_original_sampled(kind):
    """An identified model is discrete: (Φ, Γ_B, C, Γ_E) as a StateSpace with its dt, or with
    time="discrete". Sampled here by SciPy from seed 002's continuous model, its design equals the
    continuous model's (sampled by the launcher) to 1e-9, and the two discrete spellings agree bit
    for bit."""
    from scipy.linalg import expm

    dt = 0.01
    a, b, e = (np.array(SEED002[k]) for k in "ABE")
    big = np.zeros((6, 6))
    big[:3, :3], big[:3, 3:5], big[:3, 5:] = a, b, e
    m = expm(big * dt)
    phi, gam_b, gam_e = m[:3, :3], m[:3, 3:5], m[:3, 5:]
    kw = dict(kind=kind, poles=[-1.0, -2.0, -3.0])
    from_sys = uo.design(sys=control.ss(phi, gam_b, SEED002["C"], np.zeros((2, 2)), dt), E=gam_e, **kw)
    from_time = uo.design(A=phi, B=gam_b, C=SEED002["C"], E=gam_e, time="discrete", dt=dt, **kw)
    continuous = uo.design(**SEED002, dt=dt, **kw)
    assert from_sys.dt == dt
    for k in "FGKPQ":
        assert np.array_equal(from_sys.sampled[k], from_time.sampled[k]), k
        scale = max(1.0, np.abs(continuous.sampled[k]).max())
        assert np.abs(from_sys.sampled[k] - continuous.sampled[k]).max() <= 1e-9 * scale, k
    assert 'time = "discrete"' in uo.design_scenario(sys=control.ss(phi, gam_b, SEED002["C"], 0, dt), E=gam_e, **kw)


def test_a_design_that_cannot_exist_raises_the_launchers_reason(tmp_path):
    # E seen by no output: rank(CE) = 0 < rank(E) = 1, no unknown-input decoupling.
    plant = dict(SEED002, E=[[0.0], [1.0], [0.0]])
    kw = dict(kind="chen-patton-uio", poles=[-1.0, -2.0, -3.0], dt=0.001)
    with pytest.raises(ValueError) as e:
        uo.design(**plant, **kw)
    done = cli_design(tmp_path, uo.design_scenario(**plant, **kw))
    assert done.returncode == 2
    assert str(e.value) in done.stdout, (str(e.value), done.stdout)
    # A scenario error names the argument, not the generated file the caller never saw.
    with pytest.raises(ValueError, match=r"^C: ") as e:  # C of the wrong width
        uo.design(**dict(SEED002, C=[[1.0, 0.0]]), **kw)
    assert "design.toml" not in str(e.value), str(e.value)
    with pytest.raises(ValueError, match=r"^poles") as e:  # one pole too few
        uo.design(**SEED002, **dict(kw, poles=[-1.0, -2.0]))
    assert "design.toml" not in str(e.value), str(e.value)


def csv_table(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return np.array([[float(v) if v else np.nan for v in r] for r in rows[1:]])


def test_run_and_read_give_the_recordings_values(tmp_path):
    r = uo.run("seed002-piecewise", tmp_path / "out")
    assert r.ok and len(r.step) == r.summary["steps"] == 20000 and r.summary["scenario"] == "seed002-piecewise"
    summary = json.loads((tmp_path / "out" / "seed002-piecewise.summary.json").read_text())
    assert r.summary["observers"] == summary["observers"]
    done = subprocess.run([launcher(), "export", "--csv", str(tmp_path / "csv"), r.path], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    compared = 0
    for group in ("/plant/x", "/plant/y", "/observer/uio/xhat", "/observer/uio/error", "/controller/u"):
        want = csv_table(tmp_path / "csv" / (group.strip("/").replace("/", "_") + ".csv"))
        got = r.groups[group][np.isin(r.step, want[:, 0].astype(np.int64))]
        assert np.array_equal(got, want[:, 2:], equal_nan=True), group
        assert np.array_equal(r.t[np.isin(r.step, want[:, 0].astype(np.int64))], want[:, 1])
        compared += got.size
    assert compared > 200_000
    again = uo.read(r.path)
    assert all(np.array_equal(again.groups[g], r.groups[g], equal_nan=True) for g in r.groups)
    assert r["observer_uio_xhat"] is r.groups["/observer/uio/xhat"]
    with pytest.raises(ValueError):
        uo.read(tmp_path / "nothing.rrd")
    with pytest.raises(ValueError, match="did you mean"):
        uo.run("seed002-piecewse", tmp_path / "out2")


def test_a_run_without_out_leaves_no_folder_behind(tmp_path, monkeypatch):
    """Before, every `uo.run()` without `out` left a `uio-run-*` folder with its recording in the
    temporary directory. Now the folder goes once the signals are read; the values stay."""
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    import tempfile
    monkeypatch.setattr(tempfile, "tempdir", None)  # re-read TMPDIR
    r = uo.run("seed002-piecewise")
    assert r.ok and r.path is None and len(r.step) == 20000
    assert list(tmp_path.iterdir()) == []
    kept = uo.run("seed002-piecewise", tmp_path / "out")
    for g in ("/plant/x", "/observer/uio/xhat", "/controller/u"):  # not the latencies: timing
        assert np.array_equal(kept.groups[g], r.groups[g], equal_nan=True), g


def test_a_matrix_beyond_the_launchers_limit_is_refused_before_anything_is_built():
    """Before, a 10⁴ × 10⁴ A was turned into TOML text (gigabytes) and the interpreter aborted.
    Now the launcher's own limit (1 GiB a matrix) is checked on the array's size first: a
    12 000 × 12 000 A (1.15 GB, here a broadcast view that takes no memory) raises at once."""
    import resource
    import time

    A = np.broadcast_to(0.0, (12000, 12000))
    before, t = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, time.monotonic()
    with pytest.raises(ValueError, match=r"A: 12000 × 12000 is 1152000000 bytes of doubles, more than the 1073741824 bytes \(1 GiB\)"):
        uo.design(A=A, B=np.zeros((12000, 1)), C=np.zeros((1, 12000)), dt=0.01, kind="luenberger", gain="lqe")
    assert time.monotonic() - t < 5
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100_000  # KiB: under 100 MB
    with pytest.raises(ValueError, match="not a finite number"):
        uo.design(A=[[np.nan]], B=[[1.0]], C=[[1.0]], dt=0.01, kind="luenberger", poles=[-1.0])
