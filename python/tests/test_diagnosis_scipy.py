"""`uio-launcher design --json` against numbers computed here, independently, with numpy and scipy.

Nothing below is a hard-coded result: every expected number comes from the scenario's own
matrices through scipy, by a route other than the Rust code's.

* Kalman gains (observer kind "kalman"): Φ = e^{A dt} and B_d = ∫₀^dt e^{As} ds B from one
  `scipy.linalg.expm` of the block matrix [[A, B], [0, 0]]·dt; the a-priori covariance P⁻ from
  `scipy.linalg.solve_discrete_are(Φᵀ, Cᵀ, Q_d, R)`; then M = P⁻Cᵀ(CP⁻Cᵀ + R)⁻¹ and the
  observer z⁺ = Fz + Gu + Ky, x̂ = Pz + Qy must have Q = M, K = ΦM, P = I − MC, F = Φ(I − MC),
  G = B_d. For the shipped seed plants, for random systems, and once with the continuous
  `process` intensity and a noise input matrix G, Q_d then by Van Loan's method here
  (e^{[[−A, GQ_cGᵀ], [0, Aᵀ]]dt} = [[·, F₁₂], [0, F₂₂]], Q_d = F₂₂ᵀF₁₂).
* A generalized-observer bank with χ² evaluation on the seed-002 plant with C = I: each member's
  threshold is `scipy.stats.chi2.ppf(1 − α, dof)`; its residual covariance is recomputed from
  the plant and the member's sampled (F, K, P, Q) alone, through the augmented system
  s = [x; z], s⁺ = [[Φ, 0], [KC, F]]s + [w; Kν], r = S[(I − CQ)C, −CP]s + S(I − CQ)ν, by
  `scipy.linalg.solve_discrete_lyapunov` (the Rust code solves a Sylvester equation for the
  tracked state instead); the structure is "member i blind to actuator i"; and the
  fault-to-residual Markov parameters of the augmented system vanish for the member's own
  actuator (and for the unknown input) and not for the other one.

The launcher is `$CARGO_TARGET_DIR/release/uio-launcher`, or `target/release/uio-launcher` of this
checkout (as README.md says); scripts/test.sh builds it before the tests run.
"""

import glob
import json
import os
import subprocess
import tomllib

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.integrate import quad_vec
from scipy.stats import chi2

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SEED_SCENARIOS = sorted(
    f for i in range(5) for f in glob.glob(os.path.join(REPO, "scenarios", f"seed00{i}*.toml"))
)


def launcher():
    """The launcher binary of this checkout (cargo's target directory)."""
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(REPO, "target")
    path = os.path.join(target, "release", "uio-launcher")
    if not os.access(path, os.X_OK):
        pytest.fail(f"{path} is not built: run ./scripts/test.sh (it builds every binary first)")
    return path


def design(tmp_path, text, name="scenario"):
    """`uio-launcher design <file> --json` of a scenario written from `text`, parsed."""
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    done = subprocess.run([launcher(), "design", str(path), "--json"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, f"uio-launcher design {path} --json exited {done.returncode}: {done.stderr}"
    return json.loads(done.stdout)


# --- TOML writing: floats by repr, which TOML reads back to the same double. ---


def fmt(x):
    return repr(float(x))


def rows(m):
    m = np.atleast_2d(np.asarray(m, dtype=float))
    return "[" + ", ".join("[" + ", ".join(fmt(v) for v in row) + "]" for row in m) + "]"


def scenario_text(name, dt, A, B, C, *, E=None, noise, observer=None, diagnoser=None, disturbance=False):
    """A scenario with x0 = 0, one constant-zero input per column of B, [noise] from `noise`
    (a dict key → matrix), an optional Kalman observer and an optional diagnoser table."""
    n, m = np.shape(B)
    out = [
        f'name = "{name}"',
        f"dt = {fmt(dt)}",
        f"duration = {fmt(10 * dt)}",
        "seed = 7",
        "",
        "[plant]",
        f"A = {rows(A)}",
        f"B = {rows(B)}",
        f"C = {rows(C)}",
    ]
    if E is not None:
        out.append(f"E = {rows(E)}")
    out.append(f"x0 = [{', '.join(fmt(0.0) for _ in range(n))}]")
    if disturbance:
        out += ["", "[[disturbance]]", 'kind = "sine"', "amplitude = 1.0", "frequency_hz = 0.5"]
    for _ in range(m):
        out += ["", "[[input]]", 'kind = "constant"', "value = 0.0"]
    out += ["", "[noise]"] + [f"{k} = {rows(v)}" for k, v in noise.items()]
    if observer is not None:
        out += ["", "[[observer]]", f'name = "{observer}"', 'kind = "kalman"']
    if diagnoser is not None:
        out += ["", diagnoser.strip()]
    return "\n".join(out) + "\n"


# --- Independent computations. ---


def sampled(A, B, dt):
    """Φ = e^{A dt} and B_d = ∫₀^dt e^{As} ds B, from one exponential of [[A, B], [0, 0]]·dt."""
    n, m = B.shape
    big = sla.expm(np.block([[A, B], [np.zeros((m, n)), np.zeros((m, m))]]) * dt)
    return big[:n, :n], big[:n, n:]


def van_loan(A, G, Qc, dt):
    """Q_d = ∫₀^dt e^{As} G Q_c Gᵀ e^{Aᵀs} ds by Van Loan's block exponential."""
    n = A.shape[0]
    big = sla.expm(np.block([[-A, G @ Qc @ G.T], [np.zeros((n, n)), A.T]]) * dt)
    f12, f22 = big[:n, n:], big[n:, n:]
    qd = f22.T @ f12
    return (qd + qd.T) / 2


def close(actual, expected, rel, floor=1.0):
    """‖actual − expected‖ ≤ rel·(floor + ‖expected‖), with a message naming both (floor = 0:
    purely relative, for matrices far from unit size such as a covariance of 1e-4)."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, f"shape {actual.shape} != {expected.shape}"
    err = np.linalg.norm(actual - expected)
    bound = rel * (floor + np.linalg.norm(expected))
    assert err <= bound, f"‖Δ‖ = {err:.3e} > {bound:.3e}\nactual:\n{actual}\nexpected:\n{expected}"


def check_kalman(doc, A, B, C, dt, Qd, R, name="kf"):
    """The observer `name` of `doc` is the steady-state Kalman filter computed here."""
    (obs,) = [o for o in doc["observers"] if o["name"] == name]
    assert obs["kind"] == "kalman"
    s = obs["sampled"]
    assert s["dt"] == dt
    phi, bd = sampled(A, B, dt)
    p_prior = sla.solve_discrete_are(phi.T, C.T, Qd, R)
    m_gain = p_prior @ C.T @ np.linalg.inv(C @ p_prior @ C.T + R)
    n = A.shape[0]
    close(s["Q"], m_gain, 1e-9)
    close(s["K"], phi @ m_gain, 1e-9)
    close(s["P"], np.eye(n) - m_gain @ C, 1e-9)
    close(s["F"], phi @ (np.eye(n) - m_gain @ C), 1e-9)
    close(s["G"], bd, 1e-9)


# --- 1. Kalman gains. ---


@pytest.mark.parametrize("path", SEED_SCENARIOS, ids=lambda p: os.path.basename(p)[:-5])
def test_kalman_gain_of_a_seed_plant_is_scipys(tmp_path, path):
    with open(path, "rb") as f:
        sc = tomllib.load(f)
    plant, dt = sc["plant"], float(sc["dt"])
    A, B, C = (np.array(plant[k], dtype=float) for k in ("A", "B", "C"))
    n, p = A.shape[0], C.shape[0]
    Qd, R = 0.01 * np.eye(n), 0.001 * np.eye(p)
    text = scenario_text("kf-" + sc["name"], dt, A, B, C, noise={"process_discrete": Qd, "measurement": R}, observer="kf")
    check_kalman(design(tmp_path, text), A, B, C, dt, Qd, R)


@pytest.mark.parametrize("seed", range(6))
def test_kalman_gain_of_a_random_system_is_scipys(tmp_path, seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    p = int(rng.integers(1, min(3, n) + 1))
    m = int(rng.integers(1, 3))
    shift = rng.uniform(-0.5, 1.5)  # > 0 mostly stable, < 0 may leave unstable modes
    A = rng.standard_normal((n, n)) / np.sqrt(n) - shift * np.eye(n)
    B = rng.standard_normal((n, m))
    C = rng.standard_normal((p, n))
    dt = float(rng.choice([0.01, 0.02, 0.05, 0.1]))
    L = 0.1 * rng.standard_normal((n, n))
    Qd = L @ L.T
    Qd = (Qd + Qd.T) / 2  # exactly symmetric, as the scenario requires
    R = np.diag(rng.uniform(0.01, 1.0, p))
    text = scenario_text(f"kf-random-{seed}", dt, A, B, C, noise={"process_discrete": Qd, "measurement": R}, observer="kf")
    check_kalman(design(tmp_path, text), A, B, C, dt, Qd, R)


def test_kalman_gain_from_a_continuous_intensity_uses_van_loan(tmp_path):
    rng = np.random.default_rng(42)
    A = np.array([[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]])
    B = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]])
    C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    G = rng.standard_normal((3, 2))
    L = rng.standard_normal((2, 2))
    Qc = L @ L.T
    Qc = (Qc + Qc.T) / 2
    R = np.diag([1e-3, 2e-3])
    dt = 0.05
    text = scenario_text("kf-van-loan", dt, A, B, C, noise={"process": Qc, "G": G, "measurement": R}, observer="kf")
    Qd = van_loan(A, G, Qc, dt)
    # Van Loan against the integral by adaptive quadrature, so the reference itself is checked.
    quad, _ = quad_vec(lambda t: sla.expm(A * t) @ G @ Qc @ G.T @ sla.expm(A * t).T, 0.0, dt, epsabs=0.0, epsrel=1e-13)
    close(Qd, quad, 1e-10, floor=0.0)
    check_kalman(design(tmp_path, text), A, B, C, dt, Qd, R)


# --- 2. A generalized-observer bank with χ² evaluation. ---

BANK_A = np.array([[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]])
BANK_B = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]])
BANK_C = np.eye(3)
BANK_E = np.array([[2.0], [0.0], [0.5]])
BANK_DT = 0.01
BANK_QC = 1e-4 * np.eye(3)
BANK_R = 1e-4 * np.eye(3)
ALPHA = 1e-3
DIAGNOSER = f"""
[[diagnoser]]
name = "gos"
scheme = "generalized"
faults = "actuator"
observer = "chen-patton-uio"
poles = [-5.0, -6.0, -7.0]
evaluation = "chi2"
false_alarm = {fmt(ALPHA)}
ignore_before = 2.0
"""


@pytest.fixture(scope="module")
def bank(tmp_path_factory):
    text = scenario_text(
        "gos-chi2", BANK_DT, BANK_A, BANK_B, BANK_C, E=BANK_E, disturbance=True,
        noise={"process": BANK_QC, "measurement": BANK_R}, diagnoser=DIAGNOSER,
    )
    doc = design(tmp_path_factory.mktemp("bank"), text)
    (diag,) = doc["diagnosers"]
    assert diag["name"] == "gos"
    return diag


def augmented(member):
    """(A_aug, C_aug, D, K) of plant + member: s = [x; z], r = C_aug s + D ν, K the member's gain."""
    s = member["sampled"]
    F, K, P, Q = (np.array(s[k], dtype=float) for k in "FKPQ")
    phi, _ = sampled(BANK_A, BANK_B, BANK_DT)
    n, r, p = phi.shape[0], F.shape[0], BANK_C.shape[0]
    S = np.eye(p)[[o - 1 for o in member["outputs"]]]
    a_aug = np.block([[phi, np.zeros((n, r))], [K @ BANK_C, F]])
    i_cq = np.eye(p) - BANK_C @ Q
    c_aug = S @ np.hstack([i_cq @ BANK_C, -BANK_C @ P])
    return a_aug, c_aug, S @ i_cq, K


def test_the_bank_isolates_each_actuator(bank):
    assert bank["channels"] == ["u1", "u2"]
    assert bank["structure"] == [[0, 1], [1, 0]]  # member i blind to actuator i
    assert len(bank["members"]) == 2


def test_chi2_thresholds_are_scipys_quantiles(bank):
    for member in bank["members"]:
        dof = member["dof"]
        assert dof >= 1
        expected = chi2.ppf(1 - ALPHA, dof)
        assert abs(member["threshold"] - expected) <= 1e-9 * expected, (member["name"], member["threshold"], expected)


def test_residual_covariance_is_the_augmented_systems_stationary_one(bank):
    Qd = van_loan(BANK_A, np.eye(3), BANK_QC, BANK_DT)
    for member in bank["members"]:
        a_aug, c_aug, D, K = augmented(member)
        assert np.max(np.abs(np.linalg.eigvals(a_aug))) < 1  # the stationary covariance exists
        w_aug = sla.block_diag(Qd, K @ BANK_R @ K.T)
        sigma_s = sla.solve_discrete_lyapunov(a_aug, w_aug)
        # s_k depends on ν_{k−1}, ν_{k−2}, … only: independent of the ν_k that enters r_k.
        sigma_r = c_aug @ sigma_s @ c_aug.T + D @ BANK_R @ D.T
        close(member["residual_covariance"], sigma_r, 1e-8, floor=0.0)
        # The χ² degrees of freedom: Σ_r's rank (a clear gap separates noise from round-off).
        eig = np.linalg.eigvalsh(sigma_r)
        assert member["dof"] == int(np.sum(eig > 1e-9 * eig.max())), (member["name"], eig)


def test_each_member_is_decoupled_from_its_own_actuator_and_the_unknown_input(bank):
    _, bd = sampled(BANK_A, BANK_B, BANK_DT)  # γ_j = ∫₀^dt e^{As} ds B[:, j]
    _, ed = sampled(BANK_A, BANK_E, BANK_DT)
    for i, member in enumerate(bank["members"]):
        a_aug, c_aug, _, _ = augmented(member)
        r = a_aug.shape[0] - 3
        powers = [np.eye(a_aug.shape[0])]
        for _ in range(40):
            powers.append(a_aug @ powers[-1])

        def markov(column):
            g = np.concatenate([column, np.zeros(r)])
            ratios = [np.linalg.norm(c_aug @ ak @ g) / (np.linalg.norm(c_aug) * np.linalg.norm(ak) * np.linalg.norm(g)) for ak in powers]
            return max(ratios)

        for j in range(bd.shape[1]):
            worst = markov(bd[:, j])
            if j == i:
                assert worst <= 1e-12, (member["name"], f"u{j + 1}", worst)
            else:
                assert worst >= 1e-3, (member["name"], f"u{j + 1}", worst)
        assert markov(ed[:, 0]) <= 1e-12, (member["name"], "E", markov(ed[:, 0]))
