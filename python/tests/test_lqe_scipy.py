"""`gain = "lqe"` for every observer family, against scipy's DARE on the pair formed here.

For each family the error pair (Φ₁, C₁) of its sampled design is formed independently from the
scenario's matrices (one `scipy.linalg.expm` of [[A, B, E], [0, 0, 0]]·dt for Φ, Γ_B, Γ_E) by
the family's published construction; `scipy.linalg.solve_discrete_are(Φ₁ᵀ, C₁ᵀ, Q, R)` gives P,
the predictor gain K = Φ₁PC₁ᵀ(C₁PC₁ᵀ + R)⁻¹, and the sampled observer's matrices follow. They
must equal what `uio-launcher design --json` reports the observer runs with, to 1e-9. Weights given
for the plant (Q n×n, R p×p) are carried to a reduced pair as TQTᵀ and MRMᵀ. Only structural
choices that are not part of the gain (the basis L of ker C, Cumming's H) are read from the
report.
"""

import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla

from test_diagnosis_scipy import design, launcher

REPO = Path(__file__).resolve().parents[2]
TOL = 1e-9


def seed(name):
    """The scenario's text with every [[observer]]'s design keys dropped and gain = "lqe" added
    (to those named in `lqe`), and its parsed plant."""
    text = (REPO / "scenarios" / f"{name}.toml").read_text()
    data = tomllib.loads(text)
    return text, data


def lqe_text(text, extra):
    """The scenario with each observer's poles/placement/H/path replaced by gain = "lqe" plus
    the keys in extra[observer name]."""
    out, section, name = [], None, None
    for line in text.splitlines():
        if line.startswith("["):
            section = line.strip()
        key = line.split("=")[0].strip()
        if section == "[[observer]]" and key in ("poles", "placement", "H", "path"):
            continue
        if section == "[[observer]]" and key == "name":
            name = line.split("=", 1)[1].strip().strip('"')
        out.append(line)
        if section == "[[observer]]" and key == "kind":
            out.append('gain = "lqe"')
            out.extend(extra.get(name, []))
    return "\n".join(out) + "\n"


def toml_matrix(m):
    return "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in np.atleast_2d(m)) + "]"


def sampled(data):
    p = data["plant"]
    a, b, c = (np.array(p[k], dtype=float) for k in "ABC")
    n = a.shape[0]
    e = np.array(p["E"], dtype=float) if "E" in p else np.zeros((n, 0))
    d = np.array(p["D"], dtype=float) if "D" in p else np.zeros((c.shape[0], 0))
    dt = data["dt"]
    m = np.zeros((n + b.shape[1] + e.shape[1],) * 2)
    m[:n, :n] = a
    m[:n, n:n + b.shape[1]] = b
    m[:n, n + b.shape[1]:] = e
    x = sla.expm(m * dt)
    return x[:n, :n], x[:n, n:n + b.shape[1]], x[:n, n + b.shape[1]:], c, d


def kalman(phi1, c1, q, r):
    p = sla.solve_discrete_are(phi1.T, c1.T, q, r)
    return phi1 @ p @ c1.T @ np.linalg.inv(c1 @ p @ c1.T + r)


def observer(report, name):
    (o,) = [o for o in report["observers"] if o["name"] == name]
    return o


def close(ours, theirs, what):
    ours = np.array(ours, dtype=float)
    scale = max(1.0, np.abs(theirs).max())
    err = np.abs(ours - theirs).max() / scale
    print(f"{what}: {err:.2e}")
    assert err <= TOL, f"{what}: max relative difference {err:.3e} (ours {ours}, scipy {theirs})"
    return err


def spd(k, rng):
    m = rng.standard_normal((k, k))
    return m @ m.T + k * np.eye(k)


def test_luenberger_and_chen_patton(tmp_path):
    text, data = seed("seed002-sine")
    phi, _, ge, c, _ = sampled(data)
    rng = np.random.default_rng(1)
    q, r = spd(3, rng), spd(2, rng)
    report = design(tmp_path, lqe_text(text, {"luenberger": [f"Q = {toml_matrix(q)}", f"R = {toml_matrix(r)}"]}))
    # Luenberger: the pair (Φ, C).
    k = kalman(phi, c, q, r)
    s = observer(report, "luenberger")["sampled"]
    close(s["F"], phi - k @ c, "luenberger F")
    close(s["K"], k, "luenberger K")
    # Chen–Patton: H = Γ_E(CΓ_E)⁺, T = I − HC, the pair (TΦ, C), identities.
    h = ge @ np.linalg.pinv(c @ ge)
    t = np.eye(3) - h @ c
    k1 = kalman(t @ phi, c, np.eye(3), np.eye(2))
    f = t @ phi - k1 @ c
    s = observer(report, "uio")["sampled"]
    close(s["F"], f, "chen-patton F")
    close(s["K"], k1 + f @ h, "chen-patton K = K1 + FH")
    close(s["Q"], h, "chen-patton H")


def test_gi_full_order(tmp_path):
    text, data = seed("seed001-missile-full-order")
    phi, _, _, c, _ = sampled(data)
    r = np.diag([2.0, 0.5])
    report = design(tmp_path, lqe_text(text, {"gi": [f"R = {toml_matrix(r)}"]}))
    # The pair (Φ, CΦ): y_{k+1} − CΓ_Bu_k = CΦx_k.
    k = kalman(phi, c @ phi, np.eye(4), r)
    s = observer(report, "gi")["sampled"]
    close(s["F"], phi - k @ c @ phi, "gi F")
    close(s["Q"], k, "gi K")


def test_das_ghosal_and_cumming(tmp_path):
    text, data = seed("seed003-charlie-open-loop")
    phi, _, _, c, _ = sampled(data)
    rng = np.random.default_rng(3)
    q_plant, q_reduced = spd(4, rng), spd(2, rng)
    extra = {"dgo": [f"Q = {toml_matrix(q_plant)}"], "cumming": [f"Q = {toml_matrix(q_reduced)}"]}
    report = design(tmp_path, lqe_text(text, extra))
    # Das–Ghosal: x = Cᵍy + Lh, h = Lᵍx; the pair (LᵍΦL, CΦL), Q carried as LᵍQLᵍᵀ.
    o = observer(report, "dgo")
    big_l = np.array(o["matrices"]["L"])
    lg = np.linalg.pinv(big_l)
    k = kalman(lg @ phi @ big_l, c @ phi @ big_l, lg @ q_plant @ lg.T, np.eye(2))
    close(o["sampled"]["F"], lg @ phi @ big_l - k @ c @ phi @ big_l, "das-ghosal F")
    close(o["sampled"]["Q"], np.linalg.pinv(c) + big_l @ k, "das-ghosal Cᵍ + LK")
    # Cumming: [C; H]⁻¹ = [E F]; the pair (HΦF, CΦF), Q at the reduced order as given.
    o = observer(report, "cumming")
    hh = np.array(o["matrices"]["H"])
    inv = np.linalg.inv(np.vstack([c, hh]))
    ee, ff = inv[:, :2], inv[:, 2:]
    k = kalman(hh @ phi @ ff, c @ phi @ ff, q_reduced, np.eye(2))
    close(o["sampled"]["F"], hh @ phi @ ff - k @ c @ phi @ ff, "cumming F")
    close(o["sampled"]["Q"], ee + ff @ k, "cumming E + FK")


def test_das_ghosal_uio(tmp_path):
    text, data = seed("seed000-missile-dgo-uio")
    phi, _, ge, c, _ = sampled(data)
    r = np.array([[3.0, 0.4], [0.4, 1.0]])
    report = design(tmp_path, lqe_text(text, {"dgo-uio": [f"R = {toml_matrix(r)}"]}))
    o = observer(report, "dgo-uio")
    big_l = np.array(o["matrices"]["L"])
    lg = np.linalg.pinv(big_l)
    ce = c @ ge
    ce_g = np.linalg.pinv(ce)
    k0 = lg @ ge @ ce_g
    pi = np.eye(2) - ce @ ce_g
    u = sla.orth(pi)  # Π = UUᵀ: the DARE on the pair's independent outputs UᵀCΦL, R as UᵀRU
    at = lg @ phi @ big_l - k0 @ c @ phi @ big_l
    ht = kalman(at, u.T @ c @ phi @ big_l, np.eye(big_l.shape[1]), u.T @ r @ u)
    k = k0 + ht @ u.T
    f = lg @ phi @ big_l - k @ c @ phi @ big_l
    close(o["sampled"]["F"], f, "das-ghosal-uio F")
    close(o["sampled"]["Q"], np.linalg.pinv(c) + big_l @ k, "das-ghosal-uio Cᵍ + LK")
    # Decoupling (eq. 20) holds for the LQE gain too.
    assert np.abs(lg @ ge - k @ ce).max() <= 1e-12 * max(1.0, np.abs(lg @ ge).max())


def test_hui_zak(tmp_path):
    text, data = seed("seed004-projection-uio-sine")
    phi, _, ge, c, d = sampled(data)
    r = np.array([[2.0, 0.3], [0.3, 0.5]])
    report = design(tmp_path, lqe_text(text, {"uio": [f"R = {toml_matrix(r)}"]}))
    # M = [Γ_E 0][CΓ_E D]⁺, A₁ = (I − MC)Φ, N spans the left null space of D: the pair (A₁, NC),
    # R carried as NRNᵀ, L = L̃N.
    m = np.hstack([ge, np.zeros((3, d.shape[1]))]) @ np.linalg.pinv(np.hstack([c @ ge, d]))
    a1 = (np.eye(3) - m @ c) @ phi
    nn = sla.null_space(d.T).T
    lt = kalman(a1, nn @ c, np.eye(3), nn @ r @ nn.T)
    f = a1 - lt @ nn @ c
    s = observer(report, "uio")["sampled"]
    close(s["F"], f, "hui-zak F")
    close(s["Q"], m, "hui-zak M")


def test_noise_covariances_are_the_default_weights(tmp_path):
    """Without Q and R, a scenario's [noise] gives them: the Luenberger LQE gain is then the
    steady-state Kalman filter's predictor gain ΦM of the same plant."""
    text, data = seed("seed002-sine")
    phi, _, _, c, _ = sampled(data)
    qd = np.diag([1e-6, 2e-6, 5e-7])
    r = np.diag([1e-4, 4e-4])
    noisy = lqe_text(text, {}) + f"[noise]\nprocess_discrete = {toml_matrix(qd)}\nmeasurement = {toml_matrix(r)}\n"
    report = design(tmp_path, noisy)
    k = kalman(phi, c, qd, r)
    close(observer(report, "luenberger")["sampled"]["K"], k, "luenberger K from [noise]")


@pytest.mark.parametrize(
    "keys, field, reason",
    [
        (['gain = "lqe"', "poles = [-1.0, -2.0, -3.0]"], "observer[2].gain", "not both"),
        (['gain = "lqe"', "Q = [[1.0, 2.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]"], "observer[2].Q", "symmetric"),
        (['gain = "lqe"', "Q = [[1.0, 0.0], [0.0, 1.0]]"], "observer[2].Q", "must be 3×3"),
        (['gain = "lqe"', "R = [[1.0, 0.0], [0.0, -1.0]]"], "observer[2].R", "definite"),
        (['gain = "lqe"', "R = [[1.0]]"], "observer[2].R", "must be 2×2"),
        (['gain = "kalman"'], "observer[2].gain", "not a gain"),
        (["poles = [-1.0, -2.0, -3.0]", "R = [[1.0, 0.0], [0.0, 1.0]]"], "observer[2].R", "lqe"),
    ],
)
def test_bad_weights_exit_2(tmp_path, keys, field, reason):
    text, _ = seed("seed002-sine")
    lines, section, index = [], None, 0
    for line in text.splitlines():
        if line.startswith("["):
            section = line.strip()
            index += section == "[[observer]]"
        key = line.split("=")[0].strip()
        if section == "[[observer]]" and index == 2 and key in ("poles", "placement"):
            continue
        lines.append(line)
        if section == "[[observer]]" and index == 2 and key == "kind":
            lines.extend(keys)
    path = tmp_path / "bad.toml"
    path.write_text("\n".join(lines) + "\n")
    done = subprocess.run([launcher(), "design", str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2, done.stderr
    line = done.stderr.strip()
    assert len(line.splitlines()) == 1 and str(path) in line and field in line and reason in line, line
