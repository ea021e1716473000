"""`uio-launcher design --freq`: every observer's and bank member's σ over frequency against
python-control's `singular_values_response` on the same sampled systems, built here from the
scenario (Φ, Γ_E by SciPy's `expm` of the continuous model) and the designs' sampled (F, K, P, Q)
of `design --json`: plant and observer together, [x; z]⁺ = [[Φ, 0], [KC, F]][x; z] + …, with
e = [I − QC, −P][x; z] − Qv and r = S[(I − CQ)C, −CP][x; z] + S(I − CQ)v.

Checked to 1e-9 relative (of the transfer's peak) at every grid frequency: σ_max and σ_min of
w → e, v → e, w → r, v → r, and a sensor bank's f → r; the DC gains against G(1) in NumPy; a UIO's
decoupled w → e below 1e-10 in both (rounding); H∞ the largest σ_max python-control finds on a grid ten
times finer, to 1e-9. Scenarios: seed 002 (UIO, Luenberger observer), the DC motor (a plant with
an integrator: no DC gain), seed 003's sensor bank (with [noise]: fault-to-noise ratios).
"""

import json
import subprocess
import tomllib

import control
import numpy as np
import pytest
from scipy.linalg import expm, solve_sylvester

from conftest import REPO
from test_diagnosis_scipy import launcher

SCENARIOS = ["seed002-sine", "dc-motor-load-torque", "seed003-sensor-faults"]


def design(name, tmp_path=None):
    args = [launcher(), "design", "--json", "--freq", f"{REPO}/scenarios/{name}.toml"]
    if tmp_path is not None:
        args += ["--out", str(tmp_path)]
    done = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout), done.stderr


def plant(name):
    with open(f"{REPO}/scenarios/{name}.toml", "rb") as f:
        s = tomllib.load(f)
    a, c = np.array(s["plant"]["A"], float), np.array(s["plant"]["C"], float)
    n = a.shape[0]
    e = np.array(s["plant"].get("E", np.zeros((n, 0))), float).reshape(n, -1)
    dt = s["dt"]
    q = e.shape[1]
    big = np.zeros((n + q, n + q))
    big[:n, :n], big[:n, n:] = a, e
    m = expm(big * dt)
    return m[:n, :n], m[:n, n:], c, dt


def systems(phi, gam_e, c, obs, outputs):
    """(w → e, v → e, w → r, v → r, f → r for a bias on each output) as python-control systems."""
    f, k, p, q = (np.array(obs[x], float) for x in ("F", "K", "P", "Q"))
    n, r, ny = phi.shape[0], f.shape[0], c.shape[0]
    s = np.eye(ny)[outputs]
    a = np.block([[phi, np.zeros((n, r))], [k @ c, f]])
    c_e = np.hstack([np.eye(n) - q @ c, -p])
    i_cq = np.eye(ny) - c @ q
    c_r = s @ np.hstack([i_cq @ c, -c @ p])
    b_w = np.vstack([gam_e, np.zeros((r, gam_e.shape[1]))])
    b_v = np.vstack([np.zeros((n, ny)), k])
    out = {
        "v_e": (a, b_v, c_e, -q),
        "v_r": (a, b_v, c_r, s @ i_cq),
        "faults": [(a, b_v[:, [j]], c_r, (s @ i_cq)[:, [j]]) for j in range(ny)],
    }
    if gam_e.shape[1]:
        out["w_e"] = (a, b_w, c_e, np.zeros((n, gam_e.shape[1])))
        out["w_r"] = (a, b_w, c_r, np.zeros((len(outputs), gam_e.shape[1])))
    # The observer's own coordinates, where M (MΦ − FM = KC) exists and PM + QC = I.
    m = solve_sylvester(-f, phi, k @ c)
    if np.linalg.norm(p @ m + q @ c - np.eye(n)) <= 1e-8 * (1 + np.linalg.norm(p @ m)):
        scp = s @ c @ p
        out["reduced"] = {
            "v_e": (f, k, -p, -q),
            "v_r": (f, k, -scp, s @ i_cq),
            "faults": [(f, k[:, [j]], -scp, (s @ i_cq)[:, [j]]) for j in range(ny)],
        }
        if gam_e.shape[1]:
            out["reduced"]["w_e"] = (f, -m @ gam_e, -p, np.zeros((n, gam_e.shape[1])))
            out["reduced"]["w_r"] = (f, -m @ gam_e, -scp, np.zeros((len(outputs), gam_e.shape[1])))
    return out


def sigma(abcd, dt, omega):
    sys = control.ss(*abcd, dt)
    sv = control.singular_values_response(sys, omega=omega)
    m = np.abs(np.asarray(sv.frdata))  # (σ's, 1, ω), unsqueezed
    return m[0, 0, :], m[-1, 0, :], sys


def check(ours, abcd, dt, omega, decoupled, label, reduced=None):
    smax, smin, sys = sigma(abcd, dt, omega)
    got_max, got_min = np.array(ours["sigma_max"]), np.array(ours["sigma_min"])
    if decoupled:
        # Rounding in both, 1e-10 at most where the same observer's v → e is O(1) (the DC
        # motor's Hui–Zak UIO: 4.83e-12 in both).
        assert got_max.max() <= 1e-10 and smax.max() <= 1e-10, (label, got_max.max(), smax.max())
        return
    peak = smax.max()
    assert np.abs(got_max - smax).max() <= 1e-9 * peak, (label, np.abs(got_max - smax).max() / peak)
    assert np.abs(got_min - smin).max() <= 1e-9 * peak, (label, np.abs(got_min - smin).max() / peak)
    # DC: G(1) = C(I − A)⁻¹B + D, where I − A is invertible.
    a, b, c, d = abcd
    eye = np.eye(a.shape[0])
    cond = np.linalg.cond(eye - a)
    if cond < 1e13:
        # Two backward-stable solves differ by up to cond·ε relative.
        g1 = c @ np.linalg.solve(eye - a, b) + d
        want = np.linalg.svd(g1, compute_uv=False)[0]
        assert ours["dc_sigma_max"] == pytest.approx(want, rel=max(1e-9, 10 * cond * 2.2e-16)), label
    elif reduced is not None:
        # A plant integrator leaves I − A_a singular; the same transfer in the observer's own
        # coordinates ζ = z − Mx (SciPy's Sylvester solver) has F's poles only.
        fa, fb, fc, fd = reduced
        g1 = fc @ np.linalg.solve(np.eye(fa.shape[0]) - fa, fb) + fd
        want = np.linalg.svd(g1, compute_uv=False)[0]
        assert ours["dc_sigma_max"] == pytest.approx(want, rel=1e-9, abs=1e-12), (label, cond)
    else:
        assert ours["dc"] is None and ours["dc_sigma_max"] is None, (label, cond)
    # H∞: no frequency of a grid ten times finer has a larger σ_max than ours (to 1e-9), and ours
    # is σ_max where it says.
    fine = np.geomspace(omega[0], omega[-1], 10 * len(omega))
    fine_max = sigma(abcd, dt, fine)[0].max()
    assert ours["hinf"] >= fine_max * (1 - 1e-9), (label, ours["hinf"], fine_max)
    if ours["hinf_omega"] > 0:
        at = sigma(abcd, dt, np.array([ours["hinf_omega"], omega[-1]]))[0][0]
        assert ours["hinf"] == pytest.approx(at, rel=1e-9), label


@pytest.mark.parametrize("name", SCENARIOS)
def test_every_sigma_equals_python_controls_on_the_same_sampled_systems(name):
    d, _ = design(name)
    phi, gam_e, c, dt = plant(name)
    omega = np.array(d["freq"]["omega"])
    assert omega[-1] == pytest.approx(np.pi / dt, rel=1e-15)
    designs = {o["name"]: (o["sampled"], list(range(c.shape[0]))) for o in d["observers"]}
    for bank in d["diagnosers"]:
        for m in bank["members"]:
            designs[m["name"]] = (m["sampled"], [o - 1 for o in m["outputs"]])  # 1-based in the JSON
    checked = 0
    for s in d["freq"]["systems"]:
        obs, outputs = designs[s["name"]]
        sys = systems(phi, gam_e, c, obs, outputs)
        reduced = sys.get("reduced", {})
        for key in ("w_e", "v_e", "w_r", "v_r"):
            if key in sys:
                check(s[key], sys[key], dt, omega, s["w_decoupled"] and key.startswith("w"), (name, s["name"], key),
                      reduced.get(key))
                checked += 1
            else:
                assert s[key] is None
        for f in s["faults"]:
            j = int(f["channel"][1:]) - 1
            check(f["f_r"], sys["faults"][j], dt, omega, False, (name, s["name"], f["channel"]),
                  reduced["faults"][j] if reduced else None)
            checked += 1
    assert checked >= 8, checked


def test_a_uio_decouples_w_where_a_luenberger_observer_does_not():
    d, _ = design("seed002-sine")
    by = {s["name"]: s for s in d["freq"]["systems"]}
    assert by["uio"]["w_decoupled"] and not by["luenberger"]["w_decoupled"]
    assert by["luenberger"]["w_e"]["hinf"] > 1.0


def test_the_sensor_banks_fault_to_noise_ratios_follow_the_residual_covariance():
    d, _ = design("seed003-sensor-faults")
    bank = d["diagnosers"][0]
    by = {s["name"]: s for s in d["freq"]["systems"]}
    for m in bank["members"]:
        cov = np.array(m["residual_covariance"], float)
        noise = np.sqrt(np.linalg.eigvalsh(cov).max())
        for f in by[m["name"]]["faults"]:
            dc = f["f_r"]["dc_sigma_max"]
            assert f["fault_to_noise"] == pytest.approx(dc / noise, rel=1e-9) if dc > 0 else f["fault_to_noise"] in (None, 0.0)


def test_the_plots_are_written_one_per_observer_and_member(tmp_path):
    d, err = design("seed003-sensor-faults", tmp_path)
    names = {s["name"] for s in d["freq"]["systems"]}
    pngs = sorted(p.name for p in tmp_path.glob("freq_*.png"))
    assert pngs == sorted(f"freq_{n}.png" for n in names), pngs
    assert all((tmp_path / p).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)
    assert f"{len(pngs)} σ plot(s)" in err


@pytest.mark.parametrize("kind,extra", [("chen-patton-uio", {}), ("luenberger", {})])
def test_the_python_packages_freq_gives_the_same_sigmas_as_arrays(kind, extra):
    import uio_observers as uo

    a = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]]
    b = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]
    c = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    e = [[2.0], [0.0], [0.5]]
    d = uo.design(A=a, B=b, C=c, E=e, kind=kind, poles=[-1.0, -2.0, -3.0], dt=0.001, **extra)
    f = d.freq()
    assert isinstance(f["omega"], np.ndarray) and f["omega"][-1] == pytest.approx(np.pi / 0.001)
    n = 3
    big = np.zeros((4, 4))
    big[:3, :3], big[:3, 3:] = a, e
    m = expm(big * 0.001)
    sys = systems(m[:n, :n], m[:n, n:], np.array(c), {k: d.sampled[k] for k in "FGKPQ"}, [0, 1])
    for key in ("w_e", "v_e", "w_r", "v_r"):
        ours = f[key]
        assert isinstance(ours["sigma_max"], np.ndarray)
        check({**ours, "dc": None if ours["dc"] is None else ours["dc"].tolist(),
               "dc_sigma_max": None if ours["dc"] is None else np.linalg.svd(ours["dc"], compute_uv=False)[0]},
              sys[key], 0.001, f["omega"], ours["decoupled"], (kind, key), sys.get("reduced", {}).get(key))
    assert f["w_e"]["decoupled"] == (kind == "chen-patton-uio")
