"""A closed loop at an operating point: a two-zone building (air and wall
node per zone, heaters Qh1 and Qh2 known and commanded, the outdoor temperature T_out known and
*measured*, the zones' heat gains unknown) at 20 °C indoors and 5 °C outdoors, under an LQR
with integral action on the UIO's estimate.

* `measured_disturbances = ["T_out"]`: the controller does not command the outdoor
  temperature — the plant receives exactly the `[[input]]` signal, bit for bit — and it keeps
  the heaters near their nominal powers: exactly nominal while the plant rests at its point,
  their tail the equilibrium numpy solves for the final outdoor temperature, setpoints and gains,
  and no sample more than 1 kW outside those two balances (the issue's first try drove them to
  −20 kW and commanded T_out to −4.3 °C).
* The same loop written in deviations by hand (no operating point, every signal shifted by hand)
  gives the same observer estimate, controller output and plant state, to rounding; and
  `uio-launcher export --deviations` of the run at the point gives the by-hand run's signals.
* A diagnoser bank at the point is the bank of the loop in deviations.
* A measured disturbance that is not an input, or every input declared measured, is refused
  (exit 2, the field named).
"""

import json
import subprocess

import numpy as np
import pytest
import scipy.linalg as sla

from test_diagnosis_scipy import launcher
from test_fmu_plant import columns, export_csv, mat, num, run

DT, DAYS = 60.0, 4
# Conductances, kW/K, and capacities, kJ/K (air, wall) of the two zones.
H_AW, H_WO, H_AO, H_12 = (0.5, 0.4), (0.1, 0.08), (0.05, 0.06), 0.1
C_AIR, C_WALL = (2000.0, 1500.0), (20000.0, 16000.0)


def building():
    """(A, B, C, E) with x = [Ta1, Tw1, Ta2, Tw2] °C, u = [Qh1, Qh2, T_out] (kW, kW, °C), w the
    zones' heat gains (kW), y the air temperatures."""
    A, B, E = np.zeros((4, 4)), np.zeros((4, 3)), np.zeros((4, 2))
    for z, (a, w, o) in enumerate([(0, 1, 2), (2, 3, 0)]):
        ca, cw = C_AIR[z], C_WALL[z]
        A[a, a] = -(H_AW[z] + H_AO[z] + H_12) / ca
        A[a, w] = H_AW[z] / ca
        A[a, o] = H_12 / ca
        A[w, a] = H_AW[z] / cw
        A[w, w] = -(H_AW[z] + H_WO[z]) / cw
        B[a, z] = 1.0 / ca
        B[a, 2] = H_AO[z] / ca
        B[w, 2] = H_WO[z] / cw
        E[a, z] = 1.0 / ca
    C = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
    return A, B, C, E


def equilibrium(A, B, E, T_air, T_out, w):
    """The state and heater powers holding the air at T_air: A x + B u + E w = 0 with
    x = [T_air1, Tw1, T_air2, Tw2], u = [Qh1, Qh2, T_out], solved for (Tw1, Tw2, Qh1, Qh2)."""
    # Unknowns z = [Tw1, Tw2, Qh1, Qh2]: A[:, [1, 3]] z_w + B[:, :2] z_q = −(A[:, [0, 2]] T_air + B[:, 2] T_out + E w).
    M = np.column_stack([A[:, 1], A[:, 3], B[:, 0], B[:, 1]])
    z = np.linalg.solve(M, -(A[:, [0, 2]] @ T_air + B[:, 2] * T_out + E @ w))
    return np.array([T_air[0], z[0], T_air[1], z[1]]), z[2:]


A, B, C, E = building()
X_OP, Q_OP = equilibrium(A, B, E, np.array([20.0, 20.0]), 5.0, np.zeros(2))
U_OP = np.array([*Q_OP, 5.0])
# The run: the thermostats at 20 °C; T_out down to −2 °C at 1 d, a 0.3 kW gain in zone 1 from
# 1.5 d.
STEPS_AT = {"T_out": 86400.0, "w1": 129600.0}


# A diagnoser bank on the two air-temperature sensors, and a 0.5 K bias of sensor 1 from 2.5 d.
BANK = """
[[fault]]
name = "Ta1-bias"
target = "sensor"
channel = 1
kind = "bias"
value = 0.5
start = 216000.0

[[diagnoser]]
name = "dos"
scheme = "dedicated"
faults = "sensor"
observer = "luenberger"
poles = [-0.002, -0.0025, -0.003, -0.0035]
evaluation = "norm"
threshold = 0.05
persistence = 3
ignore_before = 3600.0
"""


def scenario(path, shift=None, measured=True, bank=False):
    """The loop at its operating point; with `shift`, the same loop in deviations by hand;
    with `bank`, the sensor-fault bank and its fault too."""
    x_op, u_op = (X_OP, U_OP) if shift else (np.zeros(4), np.zeros(3))
    op = "" if shift else f"""
[plant.operating_point]
x = {mat(X_OP)[1:-1]}
u = {mat(U_OP)[1:-1]}
"""
    r1, r2, t_out = 20.0 - x_op[0], 20.0 - x_op[2], (5.0 - u_op[2], -2.0 - u_op[2])
    path.write_text(f"""name = "{path.stem}"
dt = {DT}
duration = {DAYS * 86400.0}

[plant]
A = {mat(A)}
B = {mat(B)}
C = {mat(C)}
E = {mat(E)}
x0 = {mat(X_OP - x_op)[1:-1]}
state_names = ["Ta1", "Tw1", "Ta2", "Tw2"]
state_units = ["degC", "degC", "degC", "degC"]
output_names = ["Ta1", "Ta2"]
output_units = ["degC", "degC"]
input_names = ["Qh1", "Qh2", "T_out"]
input_units = ["kW", "kW", "degC"]
disturbance_names = ["gain1", "gain2"]
{op}
[[input]]
kind = "constant"
value = {num(r1)}

[[input]]
kind = "constant"
value = {num(r2)}

[[input]]
kind = "step"
time = {STEPS_AT["T_out"]}
before = {num(t_out[0])}
after = {num(t_out[1])}

[[disturbance]]
kind = "step"
time = {STEPS_AT["w1"]}
after = 0.3

[[disturbance]]
kind = "constant"
value = 0.0

[[observer]]
name = "uio"
kind = "chen-patton-uio"
gain = "lqe"
{"" if not shift else f"xhat0 = {mat(np.zeros(4))[1:-1]}"}

[controller]
kind = "lqr"
observer = "uio"
track = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]
integral = true
R = [[100.0, 0.0], [0.0, 100.0]]   # 1 kW costs as 10 K: heaters that move gently
{'measured_disturbances = ["T_out"]' if measured else ""}
{BANK if bank else ""}""")
    return path


def signals(tmp_path, scen):
    out = tmp_path / f"{scen.stem}-out"
    p, _ = run(scen, out, tmp_path / "runs")
    assert p.returncode == 0, p.stderr_text
    c = columns(export_csv(next(out.glob("*.rrd")), tmp_path / f"{scen.stem}-csv") / "controller_u.csv")
    u = np.column_stack([c[h] for h in list(c)[2:]])
    cols = lambda f: (lambda c: np.column_stack([c[h] for h in list(c)[2:]]))(columns(tmp_path / f"{scen.stem}-csv" / f))
    return {"u": u, "r": cols("input.csv"), "x": cols("plant_x.csv"), "xhat": cols("observer_uio_xhat.csv"), "stdout": p.stdout_text,
            "rrd": next(out.glob("*.rrd"))}


@pytest.fixture(scope="module")
def loop(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("building")
    return tmp, signals(tmp, scenario(tmp / "building.toml"))


def test_the_controller_does_not_command_a_measured_disturbance(loop):
    _, s = loop
    k = len(s["u"])
    t = np.arange(k) * DT
    want = np.where(t >= STEPS_AT["T_out"], -2.0, 5.0)
    # The plant's T_out is the [[input]] signal itself, at every step, bit for bit.
    assert np.array_equal(s["u"][:, 2], want), s["u"][:5, 2]
    assert np.array_equal(s["r"][:, 2], want)


def test_the_heaters_stay_near_nominal_and_settle_where_the_balance_says(loop):
    _, s = loop
    x_end, q_end = equilibrium(A, B, E, np.array([20.0, 20.0]), -2.0, np.array([0.3, 0.0]))
    q = s["u"][:, :2]
    # At rest at its point until T_out moves: the nominal powers, to rounding.
    rest = np.arange(len(q)) * DT < STEPS_AT["T_out"]
    assert np.abs(q[rest] - Q_OP).max() <= 1e-12 * np.abs(Q_OP).max(), np.abs(q[rest] - Q_OP).max()
    tail = q[-len(q) // 8:]
    err = np.abs(tail - q_end).max()
    print(f"nominal heaters {Q_OP} kW, final balance {q_end} kW; tail max |Qh − balance| {err:.2e} kW;"
          f" run's range Qh1 [{q[:, 0].min():.3f}, {q[:, 0].max():.3f}], Qh2 [{q[:, 1].min():.3f}, {q[:, 1].max():.3f}] kW;"
          f" final air {s['x'][-1, [0, 2]]} °C")
    assert err < 1e-3 * np.abs(q_end).max(), (tail[-1], q_end)
    assert np.abs(s["x"][-1] - x_end).max() < 1e-3
    # Near nominal throughout: within the span of the nominal and final balances, widened by
    # 1 kW for the transients of the two steps (the first try: −20 kW).
    lo, hi = np.minimum(Q_OP, q_end) - 1.0, np.maximum(Q_OP, q_end) + 1.0
    assert (q >= lo).all() and (q <= hi).all(), (q.min(axis=0), q.max(axis=0), lo, hi)


def test_the_gain_is_scipys_lqr_on_the_commanded_columns(tmp_path):
    """G and G_ξ: scipy's DARE on the augmented sampled plant with Γ_c = the heaters' columns
    of Γ_B (the measured T_out's rows zero), to 1e-8 relative."""
    scen = scenario(tmp_path / "building.toml")
    p = subprocess.run([launcher(), "design", "--json", str(scen)], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    c = json.loads(p.stdout)["controller"]
    assert c["measured_disturbances"] == ["T_out"]
    n, l = 4, 2
    M = sla.expm(np.block([[A, B], [np.zeros((3, 7))]]) * DT)
    Phi, Gc = M[:n, :n], M[:n, n:n + l]
    Ct = C
    Pa = np.block([[Phi, np.zeros((n, l))], [-DT * Ct, np.eye(l)]])
    Ga = np.vstack([Gc, np.zeros((l, l))])
    Q, R = np.eye(n + l), 100.0 * np.eye(l)
    X = sla.solve_discrete_are(Pa, Ga, Q, R)
    K = np.linalg.solve(R + Ga.T @ X @ Ga, Ga.T @ X @ Pa)
    G, Gxi = np.array(c["matrices"]["G"]), np.array(c["matrices"]["G_xi"])
    assert G.shape == (3, 4) and Gxi.shape == (3, 2)
    assert not G[2].any() and not Gxi[2].any() and np.array_equal(np.array(c["matrices"]["N"])[2], [0.0, 0.0, 1.0])
    ours = np.hstack([G[:2], Gxi[:2]])
    assert np.abs(ours - K).max() <= 1e-8 * np.abs(K).max(), np.abs(ours - K).max()


def test_the_loop_written_in_deviations_by_hand_is_the_same_loop(loop):
    tmp, s = loop
    d = signals(tmp, scenario(tmp / "by-hand.toml", shift=True))
    scale = np.abs(X_OP).max()
    for name, op in (("x", X_OP), ("xhat", X_OP), ("u", U_OP)):
        gap = np.abs(s[name] - op - d[name]).max()
        print(f"{name}: max |absolute − op − by hand| = {gap:.2e}")
        assert gap < 1e-9 * scale, (name, gap)
    # `uio-launcher export --deviations` of the run at the point is the run written by hand: states,
    # estimates, inputs and references (the thermostats' r_op = C_t x_op, T_out's u_op).
    dev = tmp / "deviations-csv"
    p = subprocess.run([launcher(), "export", "--deviations", "--csv", str(dev), str(s["rrd"])], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    hand = tmp / "by-hand-csv"
    for f in ("plant_x.csv", "observer_uio_xhat.csv", "controller_u.csv", "input.csv", "plant_y.csv", "observer_uio_error.csv"):
        a, b = columns(dev / f), columns(hand / f)
        assert list(a) == list(b), f
        gap = max(np.abs(np.asarray(a[h]) - np.asarray(b[h])).max() for h in list(a)[2:])
        assert gap < 1e-9 * scale, (f, gap)
    p = subprocess.run([launcher(), "plot", "--deviations", "--out", str(tmp / "plots"), str(s["rrd"])], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and list((tmp / "plots").glob("*.png")), p.stderr
    # A recording without a point has nothing to subtract: exit 2, the reason named.
    p = subprocess.run([launcher(), "export", "--deviations", "--csv", str(tmp / "none"), str(d["rrd"])], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "no [plant.operating_point]" in p.stderr and not (tmp / "none").exists(), p.stderr


def test_a_diagnoser_bank_at_the_operating_point_is_the_bank_in_deviations(tmp_path):
    """Bank members run on the absolute signals like the scenario's own observers: their
    residuals, evaluations and decisions equal those of the loop written in deviations by hand
    (residuals to rounding, the detection and isolation of the sensor bias the same)."""
    runs = {}
    for name, shift in (("at-op", None), ("by-hand", True)):
        scen = scenario(tmp_path / f"{name}.toml", shift=shift, bank=True)
        out = tmp_path / f"{name}-out"
        p, _ = run(scen, out, tmp_path / "runs")
        assert p.returncode == 0, p.stderr_text
        csv_dir = export_csv(next(out.glob("*.rrd")), tmp_path / f"{name}-csv")
        residuals = sorted(csv_dir.glob("diagnoser_dos_residual*.csv"))
        assert residuals, sorted(x.name for x in csv_dir.iterdir())
        summary = __import__("json").loads(next(out.glob("*.summary.json")).read_text())
        runs[name] = ({f.name: np.column_stack([v for v in list(columns(f).values())[2:]]) for f in residuals}, summary["diagnosis"])
    (at_op, d_op), (by_hand, d_hand) = runs["at-op"], runs["by-hand"]
    assert at_op.keys() == by_hand.keys()
    for f in at_op:
        gap = np.abs(at_op[f] - by_hand[f]).max()
        assert gap <= 1e-9 * max(np.abs(by_hand[f]).max(), 1.0), (f, gap)
    fault = d_op["faults"][0]
    assert fault["isolated_as"] == "Ta1-bias" and fault["delay"] is not None, fault
    assert d_op["faults"] == d_hand["faults"] and d_op.get("false_alarms") == d_hand.get("false_alarms"), (d_op, d_hand)


@pytest.mark.parametrize("given, says", [('["T_in"]', "not an input"), ('["Qh1", "Qh2", "T_out"]', "command none"),
                                         ('["T_out", "T_out"]', "given twice")])
def test_a_bad_measured_disturbance_is_refused(tmp_path, given, says):
    scen = scenario(tmp_path / "bad.toml", measured=False)
    scen.write_text(scen.read_text() + f"measured_disturbances = {given}\n")
    p = subprocess.run([launcher(), "design", str(scen)], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "controller.measured_disturbances" in p.stderr and says in p.stderr, p.stderr
