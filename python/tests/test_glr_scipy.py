"""The windowed GLR test of a diagnoser bank (`glr = { window, false_alarm }`) against numbers
computed here, independently, with numpy and scipy — and what it is for: seed 003's pitch-rate
bias isolated for most of its time, at no more false alarms than the χ² test alone.

* The design (`uio-launcher design --json`): per member, the innovation covariance Σ_e of its
  residual, from `scipy.linalg.solve_discrete_are` with the cross-covariance `s=` on the
  augmented system s = [x; z] (plant and member: s⁺ = [[Φ, 0], [KC, F]]s + [w; Kν],
  r = S[(I − CQ)C, −CP]s + S(I − CQ)ν) — the Rust code models the residual through the tracked
  state ζ = z − Mx instead; Σ_e is the process's own, whatever the coordinates. The threshold
  is `scipy.stats.chi2.ppf(1 − α/(N·J), 1)` with J the channels of the member's structure row.
* The statistic (a run): the recorded g_k of every member equals the GLR computed here from
  the recorded residuals — whitened in time by the augmented system's steady-state predictor,
  correlated with the signatures of unit steps simulated here through the same system — at
  every step up to its first confirmation (after it the test compensates the change it holds).
  Random stable plants with a sensor bias, a bank of Kalman members.
* Seed 003: sweeps of the shipped scenario and of the same without its `glr` line.
"""

import json
import os
import re
import subprocess
import tomllib

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.stats import chi2

from test_diagnosis_scipy import close, design, fmt, launcher, rows, sampled, van_loan

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SEED003 = os.path.join(REPO, "scenarios", "seed003-sensor-faults.toml")


def run(tmp_path, *args, timeout=300):
    done = subprocess.run([launcher(), *map(str, args)], capture_output=True, text=True, timeout=timeout,
                          cwd=tmp_path)
    return done


# --- The model of a member's residual, in the augmented coordinates s = [x; z]. ---


def augmented(phi, C, member):
    """(A, C_r, B_n, D_n) of s⁺ = A s + B_n [w; ν], r = C_r s + D_n [w; ν] for a member."""
    s = member["sampled"]
    F, K, P, Q = (np.array(s[k], dtype=float) for k in "FKPQ")
    n, r, p = phi.shape[0], F.shape[0], C.shape[0]
    S = np.eye(p)[[o - 1 for o in member["outputs"]]]
    i_cq = np.eye(p) - C @ Q
    a = np.block([[phi, np.zeros((n, r))], [K @ C, F]])
    c_r = S @ np.hstack([i_cq @ C, -C @ P])
    b_n = sla.block_diag(np.eye(n), K)
    d_n = np.hstack([np.zeros((S.shape[0], n)), S @ i_cq])
    return a, c_r, b_n, d_n, K, S @ i_cq


def innovations(phi, C, member, Qd, R):
    """(A, C_r, L, Σ_e, W) of the steady-state predictor of the member's residual."""
    a, c_r, b_n, d_n, _, _ = augmented(phi, C, member)
    noise = sla.block_diag(Qd, R)
    qn, rn, sn = b_n @ noise @ b_n.T, d_n @ noise @ d_n.T, b_n @ noise @ d_n.T
    x = sla.solve_discrete_are(a.T, c_r.T, qn, rn, s=sn)
    se = c_r @ x @ c_r.T + rn
    gain = (a @ x @ c_r.T + sn) @ np.linalg.inv(se)
    w = np.linalg.cholesky(np.linalg.inv(se)).T  # WᵀW = Σ_e⁻¹
    return a, c_r, gain, se, w


def signature(phi, C, member, gain, w, channel, window):
    """ρ_i, i < window: the whitened innovations of a unit step on output `channel` (0-based)."""
    a, c_r, _, _, K, s_icq = augmented(phi, C, member)
    n = phi.shape[0]
    b = np.concatenate([np.zeros(n), K[:, channel]])
    d = s_icq[:, channel]
    s, s_hat, out = np.zeros(a.shape[0]), np.zeros(a.shape[0]), []
    for _ in range(window):
        e = c_r @ s + d - c_r @ s_hat
        out.append(w @ e)
        s, s_hat = a @ s + b, a @ s_hat + gain @ e
    return np.array(out)


def glr_statistic(residuals, phi, C, member, Qd, R, structure_row, window):
    """g_k of the recorded residuals (k × outputs), before any confirmation (module docs)."""
    a, c_r, gain, _, w = innovations(phi, C, member, Qd, R)
    sigs = [signature(phi, C, member, gain, w, j, window) for j, on in enumerate(structure_row) if on]
    info = [np.cumsum((r ** 2).sum(axis=1)) for r in sigs]
    s_hat, eps = np.zeros(a.shape[0]), []
    for r in residuals:
        e = r - c_r @ s_hat
        eps.append(w @ e)
        s_hat = a @ s_hat + gain @ e
    eps = np.array(eps)
    g = np.zeros(len(eps))
    for k in range(len(eps)):
        lo = max(0, k + 1 - window)
        for rho, inf in zip(sigs, info):
            for s in range(lo, k + 1):
                age = k - s
                c = float(np.sum(rho[: age + 1] * eps[s : k + 1]))
                if inf[age] > 0:
                    g[k] = max(g[k], c * c / inf[age])
    return g


def csv_columns(path):
    with open(path) as f:
        lines = f.read().splitlines()
    return np.array([[float(v) for v in line.split(",")[2:]] for line in lines[1:]])


def random_sensor_bank(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 5))
    A = rng.standard_normal((n, n)) / np.sqrt(n) - rng.uniform(1.0, 2.0) * np.eye(n)
    assert np.max(np.linalg.eigvals(A).real) < 0  # the augmented route needs a stable plant
    B = rng.standard_normal((n, 1))
    C = rng.standard_normal((3, n))
    dt = float(rng.choice([0.01, 0.02, 0.05]))
    Qc = np.diag(rng.uniform(1e-4, 1e-2, n))
    R = np.diag(rng.uniform(1e-4, 1e-3, 3))
    return rng, A, B, C, dt, Qc, R


@pytest.mark.parametrize("seed", range(4))
def test_the_glr_design_and_statistic_are_the_ones_computed_here(tmp_path, seed):
    rng, A, B, C, dt, Qc, R = random_sensor_bank(seed)
    n = A.shape[0]
    window_s, alpha, steps = 40 * dt, float(rng.choice([1e-4, 1e-5])), 160
    channel = int(rng.integers(1, 4))
    bias = 20.0 * float(np.sqrt(R[channel - 1, channel - 1]))
    text = "\n".join([
        f'name = "glr-{seed}"', f"dt = {fmt(dt)}", f"duration = {fmt(steps * dt)}", "seed = 11", "",
        "[plant]", f"A = {rows(A)}", f"B = {rows(B)}", f"C = {rows(C)}",
        f"x0 = [{', '.join('0.0' for _ in range(n))}]", "",
        "[[input]]", 'kind = "constant"', "value = 0.0", "",
        "[noise]", f"process = {rows(Qc)}", f"measurement = {rows(R)}", "",
        "[[fault]]", 'name = "bias"', 'target = "sensor"', f"channel = {channel}", 'kind = "bias"',
        f"value = {fmt(bias)}", f"start = {fmt(80 * dt)}", "",
        "[[diagnoser]]", 'name = "gos"', 'scheme = "generalized"', 'faults = "sensor"', 'observer = "kalman"',
        'evaluation = "chi2"', "false_alarm = 1e-4", "persistence = 3",
        f"glr = {{ window = {fmt(window_s)}, false_alarm = {fmt(alpha)} }}", "",
    ])
    doc = design(tmp_path, text)
    (bank,) = doc["diagnosers"]
    phi, _ = sampled(A, B, dt)
    Qd = van_loan(A, np.eye(n), Qc, dt)
    window = int(round(window_s / dt))
    for member, row in zip(bank["members"], bank["structure"]):
        glr = member["glr"]
        tested = [bank["channels"][j] for j, on in enumerate(row) if on]
        assert glr["window"] == window and glr["channels"] == tested
        want = chi2.ppf(1 - alpha / (window * len(tested)), 1)
        assert abs(glr["threshold"] - want) <= 1e-9 * want, (member["name"], glr["threshold"], want)
        _, _, _, se, _ = innovations(phi, C, member, Qd, R)
        close(glr["innovation_covariance"], se, 1e-7, floor=0.0)

    (tmp_path / "s.toml").write_text(text)
    done = run(tmp_path, "run", "s.toml", "--mode", "in-process", "--out", "out")
    assert done.returncode in (0, 1), done.stderr
    done = run(tmp_path, "export", "--csv", "csv", "out/glr-%d.rrd" % seed)
    assert done.returncode == 0, done.stderr
    recorded = csv_columns(tmp_path / "csv" / "diagnosis_gos_glr.csv")
    confirmed = 0
    for i, (member, row) in enumerate(zip(bank["members"], bank["structure"])):
        residuals = csv_columns(tmp_path / "csv" / f"diagnoser_gos_residual_{i + 1}.csv")
        g = glr_statistic(residuals, phi, C, member, Qd, R, row, window)
        h = member["glr"]["threshold"]
        # Up to the first confirmation: three exceedances in a row (the persistence).
        above = g > h
        first = next((k for k in range(2, len(g)) if above[k - 2 : k + 1].all()), len(g) - 1)
        confirmed += first < len(g) - 1
        close(recorded[: first + 1, i], g[: first + 1], 1e-7, floor=1e-6)
    # The bias (20σ on one output) is confirmed by the members that read that output.
    assert confirmed >= 1


# --- Seed 003: the bias held, the false alarms not more. ---


def without_glr(tmp_path, name, *, faults=True, duration=None):
    """The shipped seed-003 scenario (its GLR line kept or not; faults and [expect] kept or not)."""
    text = open(SEED003).read()
    assert re.search(r"^glr = ", text, flags=re.M), "seed003-sensor-faults has no glr line any more"
    if name.endswith("chi2"):
        text = re.sub(r"^glr = .*$", "", text, flags=re.M)
    if not faults:
        text = re.sub(r"\[\[fault\]\].*?(?=\[\[observer\]\])", "", text, flags=re.S)
        text = re.sub(r"\[expect\].*", "", text, flags=re.S)
    if duration is not None:
        text = re.sub(r"^duration = .*$", f"duration = {fmt(duration)}", text, flags=re.M)
    tomllib.loads(text)
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


def sweep(tmp_path, path, runs):
    out = tmp_path / f"sweep-{path.stem}"
    done = run(tmp_path, "sweep", path, "--runs", runs, "--jobs", 1, "--out", out)
    assert done.returncode == 0, done.stderr
    with open(out / "seed003-sensor-faults.sweep.json") as f:
        return json.load(f)


def test_seed003s_bias_is_isolated_for_most_of_its_time_at_no_more_false_alarms(tmp_path):
    glr = sweep(tmp_path, without_glr(tmp_path, "with-glr"), 100)
    chi = sweep(tmp_path, without_glr(tmp_path, "chi2"), 100)
    (bias,) = [f for f in glr["faults"] if f["name"] == "pitch-rate-bias"]
    (bias_chi,) = [f for f in chi["faults"] if f["name"] == "pitch-rate-bias"]
    print(f"\nbias isolated share with GLR {bias['isolated_fraction']}, χ² alone {bias_chi['isolated_fraction']}")
    assert glr["runs"] == 100
    assert bias["isolated_fraction"]["min"] >= 0.9 and bias["isolation_accuracy"] == 1.0, bias
    assert bias_chi["isolated_fraction"]["max"] < 0.1, bias_chi  # what the GLR is for
    # False alarms per hour, on fault-free realisations of 27 s decided each (the plant, open
    # loop, leaves its bound after ~32 s): 400 of them, 3 h.
    ff_glr = sweep(tmp_path, without_glr(tmp_path, "ff-glr", faults=False, duration=30.0), 400)
    ff_chi = sweep(tmp_path, without_glr(tmp_path, "ff-chi2", faults=False, duration=30.0), 400)
    print(f"false alarms over {ff_glr['fault_free_time_s']} s: GLR {ff_glr['false_alarms']}, χ² {ff_chi['false_alarms']}")
    assert ff_glr["fault_free_time_s"] == ff_chi["fault_free_time_s"] >= 400 * 27.0 - 1e-6
    assert ff_glr["false_alarms"] <= ff_chi["false_alarms"], (ff_glr["false_alarms"], ff_chi["false_alarms"])


@pytest.mark.parametrize(
    "glr, noise, field, words",
    [
        ("{ window = 5.0, false_alarm = 1e-5 }", False, "diagnoser[1].glr", "no [noise]"),
        ("{ window = 0.001, false_alarm = 1e-5 }", True, "diagnoser[1].glr.window", "at least one sample"),
        ("{ window = 500.0, false_alarm = 1e-5 }", True, "diagnoser[1].glr.window", "at most"),
        ("{ window = 5.0, false_alarm = 0.5 }", True, "diagnoser[1].glr.false_alarm", "between 0 and 0.5"),
        ("{ window = 5.0, alpha = 1e-5 }", True, "diagnoser[1].glr", "alpha"),
    ],
)
def test_a_bad_glr_table_is_refused_naming_its_field(tmp_path, glr, noise, field, words):
    text = open(SEED003).read()
    text = re.sub(r"^glr = .*$", f"glr = {glr}", text, flags=re.M)
    if not noise:
        text = re.sub(r"\[noise\].*?(?=\[\[input\]\])", "", text, flags=re.S)
        text = text.replace("false_alarm = 1e-4\n", "threshold = 20.0\n")
        text = re.sub(r'\[\[observer\]\]\nname = "kalman"\nkind = "kalman"\n', "", text)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    done = run(tmp_path, "design", path)
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    line = done.stderr.strip().splitlines()[-1]
    assert field in line and words in line, line
