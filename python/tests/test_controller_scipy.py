"""The `[controller]` designs of `uio-launcher design --json` against scipy, from the scenario's matrices.

Every expected number is computed here from the scenario's own TOML: Φ = e^{A dt} and
Γ_B = ∫₀^dt e^{As} ds B from one `scipy.linalg.expm` of [[A, B], [0, 0]]·dt; the LQR gain
G = (R + ΓᵀXΓ)⁻¹ΓᵀXΦ from X = `scipy.linalg.solve_discrete_are(Φ, Γ, Q, R)`; with integral action
on the augmented sampled plant Φ_a = [[Φ, 0], [−dt C_t, I]], Γ_a = [[Γ_B], [0]]. Placed gains
are checked by the eigenvalues numpy finds for the loop they make (eig(Φ − Γ_BG) = e^{p·dt}, or
eig(A − BG) = p with `domain = "continuous"`).
"""

import subprocess
import tomllib
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from test_diagnosis_scipy import design, launcher

REPO = Path(__file__).resolve().parents[2]
TOL = 1e-9


def scenario(name):
    return (REPO / "scenarios" / f"{name}.toml").read_text()


def edit_controller(text, drop=(), replace=None, after_kind=None):
    """The scenario with the [controller] lines whose key is in `drop` removed, those in
    `replace` (key → full line) replaced, and `after_kind` lines inserted after its kind."""
    out, section = [], None
    for line in text.splitlines():
        if line.startswith("["):
            section = line.split("#")[0].strip()
        key = line.split("=")[0].strip()
        if section == "[controller]" and key in drop:
            continue
        if section == "[controller]" and replace and key in replace:
            line = replace[key]
        out.append(line)
        if section == "[controller]" and key == "kind" and after_kind:
            out.extend(after_kind)
    return "\n".join(out) + "\n"


def sampled(data):
    """(A, B, Φ, Γ_B, dt) of the scenario's continuous-time plant."""
    p = data["plant"]
    a, b = (np.array(p[k], dtype=float) for k in "AB")
    n, m = b.shape
    dt = float(data["dt"])
    blk = np.zeros((n + m, n + m))
    blk[:n, :n], blk[:n, n:] = a, b
    x = sla.expm(blk * dt)
    return a, b, x[:n, :n], x[:n, n:], dt


def lqr(phi, gamma, q, r):
    x = sla.solve_discrete_are(phi, gamma, q, r)
    return np.linalg.solve(r + gamma.T @ x @ gamma, gamma.T @ x @ phi)


def rel(got, want):
    got, want = np.asarray(got, dtype=complex), np.asarray(want, dtype=complex)
    assert got.shape == want.shape, f"{got.shape} ≠ {want.shape}"
    return float(np.max(np.abs(got - want)) / np.max(np.abs(want)))


def sort_c(z):
    """Complex numbers sorted by real part (rounded, so a conjugate pair keeps its order), then imaginary."""
    z = np.asarray(z, dtype=complex)
    return z[np.lexsort((z.imag, np.round(z.real, 7)))]


def poles(pairs):
    return sort_c([complex(re, im) for re, im in pairs])


def controller(tmp_path, text, name):
    c = design(tmp_path, text, name)["controller"]
    assert "error" not in c, c
    return c


def test_lqr_integral_equals_scipy_dare_on_augmented_plant(tmp_path):
    text = scenario("vehicle-lateral-integral")
    data = tomllib.loads(text)
    _, _, phi, gb, dt = sampled(data)
    ct = np.array(data["controller"]["track"], dtype=float)
    n, l = phi.shape[0], ct.shape[0]
    phi_a = np.block([[phi, np.zeros((n, l))], [-dt * ct, np.eye(l)]])
    gamma_a = np.vstack([gb, np.zeros((l, gb.shape[1]))])
    want = lqr(phi_a, gamma_a, np.array(data["controller"]["Q"], dtype=float), np.array(data["controller"]["R"], dtype=float))

    c = controller(tmp_path, text, "lqr-integral")
    assert c["kind"] == "lqr" and c["integral"] is True and c["stable"] is True
    m = c["matrices"]
    got = np.hstack([np.array(m["G"]), np.array(m["G_xi"])])
    assert rel(got, want) < TOL
    assert rel(m["C_t"], ct) == 0.0
    c_meas = np.array(data["plant"]["C"], dtype=float)
    assert rel(np.array(m["M"]) @ c_meas, ct) < 1e-12

    loop = sort_c(np.linalg.eigvals(phi_a - gamma_a @ want))
    reported = poles(c["discrete_closed_loop_poles"])
    assert rel(reported, loop) < TOL
    assert np.all(np.abs(reported) < 1.0)
    assert np.all(np.abs(loop) < 1.0)


def test_lqr_without_integral_equals_scipy_dare(tmp_path):
    text = scenario("vehicle-lateral-integral")
    data = tomllib.loads(text)
    _, _, phi, gb, _ = sampled(data)
    q = np.diag([50.0, 2.0, 20.0, 0.5])
    q[0, 2] = q[2, 0] = 3.0  # an off-diagonal term, still positive definite
    r = np.array(data["controller"]["R"], dtype=float)
    rows = "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in q) + "]"

    weighted = edit_controller(text, drop=("integral",), replace={"Q": f"Q = {rows}"})
    c = controller(tmp_path, weighted, "lqr-q4")
    assert c["kind"] == "lqr" and c["integral"] is False and "G_xi" not in c["matrices"]
    want = lqr(phi, gb, q, r)
    assert rel(c["matrices"]["G"], want) < TOL
    assert rel(poles(c["discrete_closed_loop_poles"]), sort_c(np.linalg.eigvals(phi - gb @ want))) < TOL

    plain = edit_controller(text, drop=("integral", "Q", "R"))
    c = controller(tmp_path, plain, "lqr-identity")
    want_i = lqr(phi, gb, np.eye(4), np.eye(1))
    assert rel(c["matrices"]["G"], want_i) < TOL
    assert rel(want_i, want) > 1e-3  # the weights matter: the two designs are different gains


def test_state_feedback_sampled_and_continuous_placement(tmp_path):
    text = scenario("seed002-sine")
    data = tomllib.loads(text)
    a, b, phi, gb, dt = sampled(data)
    p = np.array(data["controller"]["poles"], dtype=float)
    assert b.shape[1] == 2

    c = controller(tmp_path, text, "sf-sampled")
    g = np.array(c["matrices"]["G"])
    assert c["kind"] == "state-feedback" and g.shape == (2, 3)
    got = sort_c(np.linalg.eigvals(phi - gb @ g))
    want = sort_c(np.exp(p * dt))
    assert np.max(np.abs(got - want)) < 1e-12
    assert rel(poles(c["discrete_closed_loop_poles"]), want) < 1e-12

    cont = edit_controller(text, after_kind=['domain = "continuous"'])
    c = controller(tmp_path, cont, "sf-continuous")
    g = np.array(c["matrices"]["G"])
    got = sort_c(np.linalg.eigvals(a - b @ g))
    assert rel(got, sort_c(p)) < TOL
    assert rel(poles(c["closed_loop_poles"]), sort_c(p)) < TOL


def test_lqr_q_of_wrong_size_is_refused(tmp_path):
    text = edit_controller(scenario("vehicle-lateral-integral"), replace={"Q": "Q = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]"})
    path = tmp_path / "bad-q.toml"
    path.write_text(text)
    done = subprocess.run([launcher(), "design", str(path), "--json"], capture_output=True, text=True, timeout=60)
    out = done.stdout + done.stderr
    assert done.returncode == 2, out
    assert "controller.Q" in out and "is 4×4" in out and "must be 5×5" in out, out
