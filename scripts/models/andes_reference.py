#!/usr/bin/env python3
"""Reference values (numpy / scipy) for the ANDES power-system plants in fixtures/andes/<case>/.

Reads A, B, C, E (.npy), states.txt and meta.json as scripts/models/andes_case.py writes them
(continuous time: x' = A x + B u + E w, y = C x) and writes fixtures/andes/<case>/reference.json
with, for the continuous model,

  eig_A            all eigenvalues of A (numpy.linalg.eigvals), sorted by (Re, Im);
  modes_re_ge_0    the eigenvalues with Re >= -RE_TOL, clustered (|difference| <= CLUSTER_TOL
                   max(1, |lambda|)), conjugate pairs listed once (Im >= 0), each with its PBH
                   test: s = singular values of [A - lambda I; C] (numpy.linalg.svd), relative
                   sigma_min / sigma_max and the next one up (the gap the decision rests on),
                   the dimension of its unobservable part (the number of s_i <= PBH_TOL s_max)
                   and the states that carry it: the largest row norms of
                   the null vectors of [A - lambda I; C] when unobservable, else of the right
                   eigenvectors of A in the cluster (names from states.txt, vectors scaled to
                   max |entry| = 1);
  detectable       (A, C) has no unobservable mode with Re >= -RE_TOL;

and, for each sample time dt in DTS (zero-order hold),

  Phi, Gamma_E     Phi = expm(A dt), Gamma_E = int_0^dt e^{A s} ds E, both blocks of
                   scipy.linalg.expm([[A, E], [0, 0]] dt); Phi is summarised (Frobenius norm,
                   max |entry|, trace, spectral radius, Phi @ ones), Gamma_E written whole;
  rank_C_Gamma_E   numpy.linalg.matrix_rank(C Gamma_E) (numpy's default tolerance
                   s_max max(p, q) eps), its singular values, and whether it equals q (the UIO
                   matching condition, with rank Gamma_E = q);
  invariant_zeros  the finite invariant zeros of the sampled triple (Phi, Gamma_E, C): the pencil
                   P(z) = [[Phi - z I, Gamma_E], [C, 0]] is (n + p) x (n + q), tall, so it is
                   squared down twice, [[Phi, G], [K C, 0]] - z [[I, 0], [0, 0]] with
                   K = (C G)^+ and with K a seeded Gaussian q x p matrix, each solved by
                   scipy.linalg.eigvals(M, N) (finite: |beta| > 1e-10 max(|alpha|, |beta|));
                   a zero is a value found by both (within ZERO_MATCH max(1, |z|)) at which the
                   tall pencil loses rank: sigma_(n+q) / sigma_1 <= PBH_TOL. G = Gamma_E with
                   unit-norm columns (zeros do not depend on the input scaling; the rank test
                   does). zeros_outside lists those with |z| >= 1 - UNIT_TOL. near_zeros lists
                   the common candidates with PBH_TOL < sigma_(n+q) / sigma_1 <= NEAR_TOL:
                   approximate zeros (a continuous zero that sampling does not keep exactly,
                   e.g. a governor behind the disturbed shaft: Kundur's -1/T1, -1/T3 sit at
                   1e-11..1e-9) or the floor that a badly scaled A puts under every sigma (WECC:
                   |A| ~ 5e5), so they are information, never a verdict;
  uio              Chen-Patton UIO in sampled form: H = Gamma_E (C Gamma_E)^+, T = I - H C,
                   A1 = T Phi; it exists when rank C Gamma_E = rank Gamma_E = q and (A1, C) is
                   detectable: PBH (PBH_TOL) at every eigenvalue of A1 with |z| >= 1 - UNIT_TOL.
                   If it exists: P = scipy.linalg.solve_discrete_are(A1', C', I, LQE_R I), the
                   predictor gain K = A1 P C' (C P C' + R)^-1, rho(A1 - K C), trace P, the DARE's
                   relative residual, and scipy's time (time.perf_counter, best of TIMING_RUNS);
  kalman           the same on (Phi, C): detectable, DARE, rho(Phi - K C), time.

Consistency: with the matching condition, the unobservable modes of (A1, C) are the invariant
zeros of (Phi, Gamma_E, C), so "uio exists" must agree with "no zero outside"; the script
records both and flags a disagreement (near-tolerance cases).

The timings run single-threaded: OPENBLAS_NUM_THREADS and OMP_NUM_THREADS are set to 1 before
numpy loads unless already set (run with OPENBLAS_NUM_THREADS=2 to time two threads); the
machine's load average is recorded beside them.

Usage (numpy 2.4.6, scipy 1.17.1; the venv of scripts/models/andes_case.py will do):

    /work/andes-venv/bin/python scripts/models/andes_reference.py               # every case found
    /work/andes-venv/bin/python scripts/models/andes_reference.py ieee14 npcc   # some cases
"""

import argparse
import json
import os
import sys
import time

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ.setdefault(_var, "1")   # before numpy loads: the DARE timings are single-threaded

import numpy as np
import scipy
import scipy.linalg as sla

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
FIXTURES = os.path.join(ROOT, "fixtures", "andes")

DTS = (0.001, 0.01)
RE_TOL = 1e-6        # Re(lambda) >= -RE_TOL counts as "Re >= 0" (ANDES's EIG.config.tol)
CLUSTER_TOL = 1e-6   # eigenvalues closer than this (relative) are one mode
PBH_TOL = 1e-12      # rank loss: sigma_i <= PBH_TOL sigma_max (PBH matrices, the zeros' pencil)
NEAR_TOL = 1e-8      # near_zeros: PBH_TOL < sigma_(n+q) / sigma_1 <= NEAR_TOL (information only)
UNIT_TOL = 1e-9      # discrete: |z| >= 1 - UNIT_TOL counts as "outside" (not strictly inside)
ZERO_MATCH = 1e-6    # two square-downs agree on a zero candidate (relative)
LQE_R = 0.01         # R = LQE_R I, Q = I for both DAREs
TIMING_RUNS = 3
TOP_STATES = 6       # states named per mode
SEED = 20240601      # the random square-down


def cplx(z):
    return [float(np.real(z)), float(np.imag(z))]


def sort_cplx(v):
    v = np.asarray(v, dtype=complex)
    return v[np.lexsort((v.imag, v.real))]


def clusters(lam, tol=CLUSTER_TOL):
    """Groups of indices of `lam` whose values agree within tol max(1, |lambda|)."""
    left, out = list(np.argsort(lam.real)), []
    while left:
        i = left.pop(0)
        group = [i] + [j for j in left if abs(lam[j] - lam[i]) <= tol * max(1.0, abs(lam[i]))]
        left = [j for j in left if j not in group]
        out.append(group)
    return out


def pbh(a, c, lam):
    """Singular values and right singular vectors of [A - lambda I; C]."""
    n = a.shape[0]
    _, s, vh = np.linalg.svd(np.vstack([a - lam * np.eye(n), c]))
    return s, vh


def top_states(vectors, names, k=TOP_STATES):
    """Largest row norms of `vectors` (n x r, each column scaled to max |entry| = 1)."""
    v = vectors / np.abs(vectors).max(axis=0, keepdims=True)
    w = np.linalg.norm(v, axis=1)
    order = np.argsort(-w)[:k]
    return [[names[i], round(float(w[i]), 4)] for i in order if w[i] >= 1e-3]


def unobservable(a, c, lam):
    """(dimension of the unobservable part at lam, the two smallest relative singular values,
    null vectors)."""
    s, vh = pbh(a, c, lam)
    small = s <= PBH_TOL * s[0]
    return int(small.sum()), [float(s[-1] / s[0]), float(s[-2] / s[0])], vh[small].conj().T


def continuous_modes(a, c, names):
    lam, vec = np.linalg.eig(a)
    modes = []
    for group in clusters(lam):
        z = lam[group].mean()
        if z.real < -RE_TOL or z.imag < -CLUSTER_TOL * max(1.0, abs(z)):
            continue
        dim, sigma, null = unobservable(a, c, z)
        carriers = top_states(null if dim else vec[:, group], names)
        modes.append({"lambda": cplx(z), "multiplicity": len(group), "unobservable_dim": dim,
                      "pbh_sigma_rel": sigma[0], "pbh_sigma_rel_next": sigma[1], "states": carriers})
    return lam, modes


def sample(a, e, dt):
    n, q = e.shape
    big = np.zeros((n + q, n + q))
    big[:n, :n], big[:n, n:] = a, e
    f = sla.expm(big * dt)
    return f[:n, :n], f[:n, n:]


def square_down_zeros(phi, g, k):
    n, q = g.shape
    m = np.block([[phi, g], [k, np.zeros((q, q))]])
    nn = np.zeros_like(m)
    nn[:n, :n] = np.eye(n)
    alpha, beta = sla.eigvals(m, nn, homogeneous_eigvals=True)
    finite = np.abs(beta) > 1e-10 * np.maximum(np.abs(alpha), np.abs(beta))
    return alpha[finite] / beta[finite]


def tall_sigma(phi, g, c, z):
    n, q, p = phi.shape[0], g.shape[1], c.shape[0]
    s = np.linalg.svd(np.block([[phi - z * np.eye(n), g], [c, np.zeros((p, q))]]), compute_uv=False)
    return float(s[n + q - 1] / s[0])


def invariant_zeros(phi, ge, c, rng):
    g = ge / np.linalg.norm(ge, axis=0)
    cg = c @ g
    first = square_down_zeros(phi, g, np.linalg.pinv(cg) @ c)
    second = square_down_zeros(phi, g, rng.standard_normal((g.shape[1], c.shape[0])) @ c)
    common = [z for z in first if second.size and np.min(np.abs(second - z)) <= ZERO_MATCH * max(1.0, abs(z))]
    zeros, near = [], []
    for z in sort_cplx(common):
        sigma = tall_sigma(phi, g, c, z)
        if sigma <= PBH_TOL:
            zeros.append((z, sigma))
        elif sigma <= NEAR_TOL:
            near.append((z, sigma))
    return zeros, near, len(first), len(second), len(common)


def detectability(f, c):
    """PBH at the eigenvalues of F with |z| >= 1 - UNIT_TOL (clustered, conjugates kept):
    {"outside": every such mode with its test, "unobservable_outside": the failing ones,
    "detectable": none fails}."""
    lam = np.linalg.eigvals(f)
    outside = lam[np.abs(lam) >= 1 - UNIT_TOL]
    modes = []
    for group in clusters(outside):
        z = outside[group].mean()
        dim, sigma, _ = unobservable(f, c, z)
        modes.append({"z": cplx(z), "abs": float(abs(z)), "multiplicity": len(group), "unobservable_dim": dim,
                      "pbh_sigma_rel": sigma[0], "pbh_sigma_rel_next": sigma[1]})
    bad = [md for md in modes if md["unobservable_dim"]]
    return {"outside": modes, "unobservable_outside": bad, "detectable": not bad}


def dare(f, c, dt):
    n, p = f.shape[0], c.shape[0]
    q, r = np.eye(n), LQE_R * np.eye(p)
    times = []
    try:
        for _ in range(TIMING_RUNS):
            t0 = time.perf_counter()
            x = sla.solve_discrete_are(f.T, c.T, q, r)
            times.append(time.perf_counter() - t0)
    except (np.linalg.LinAlgError, ValueError) as err:
        return {"error": f"{type(err).__name__}: {err}"}
    s = c @ x @ c.T + r
    k = f @ x @ c.T @ np.linalg.inv(s)
    res = f @ x @ f.T - x - f @ x @ c.T @ np.linalg.solve(s, c @ x @ f.T) + q
    rho = float(np.abs(np.linalg.eigvals(f - k @ c)).max())
    return {"time_s": min(times), "times_s": times, "load_average": list(os.getloadavg()),
            "rho_closed": rho, "slowest_time_constant_s": float(-dt / np.log(rho)) if rho < 1 else None,
            "trace_P": float(np.trace(x)), "max_abs_P": float(np.abs(x).max()),
            "residual_rel": float(np.abs(res).max() / np.abs(x).max())}


def discrete(a, c, e, dt, rng):
    n, q = e.shape
    phi, ge = sample(a, e, dt)
    cge = c @ ge
    sv = np.linalg.svd(cge, compute_uv=False)
    rank, rank_ge = int(np.linalg.matrix_rank(cge)), int(np.linalg.matrix_rank(ge))
    zeros, near, n1, n2, nc = invariant_zeros(phi, ge, c, rng)
    outside = [(z, s) for z, s in zeros if abs(z) >= 1 - UNIT_TOL]
    out = {
        "Phi": {"fro": float(np.linalg.norm(phi)), "max_abs": float(np.abs(phi).max()),
                "trace": float(np.trace(phi)), "rho": float(np.abs(np.linalg.eigvals(phi)).max()),
                "times_ones": phi.sum(axis=1).tolist()},
        "Gamma_E": ge.tolist(),
        "rank_C_Gamma_E": rank, "rank_Gamma_E": rank_ge, "sv_C_Gamma_E": sv.tolist(),
        "matching": rank == q and rank_ge == q,
        "invariant_zeros": [{"z": cplx(z), "abs": float(abs(z)), "sigma_rel": s} for z, s in zeros],
        "zero_candidates": {"square_down_pinv": n1, "square_down_random": n2, "common": nc},
        "zeros_outside": [{"z": cplx(z), "abs": float(abs(z)), "sigma_rel": s} for z, s in outside],
        "near_zeros": [{"z": cplx(z), "abs": float(abs(z)), "sigma_rel": s} for z, s in near],
    }
    uio = {}
    if out["matching"]:
        h = ge @ np.linalg.pinv(cge)
        a1 = (np.eye(n) - h @ c) @ phi
        uio = detectability(a1, c)
        uio["exists"] = uio["detectable"]
        if uio["exists"]:
            uio["dare"] = dare(a1, c, dt)
    else:
        uio = {"exists": False, "reason": "rank C Gamma_E < q"}
    uio["agrees_with_zeros"] = uio["exists"] == (out["matching"] and not outside)
    out["uio"] = uio
    kf = detectability(phi, c)
    if kf["detectable"]:
        kf["dare"] = dare(phi, c, dt)
    out["kalman"] = kf
    return out


def reference(folder):
    load = lambda k: np.load(os.path.join(folder, f"{k}.npy"))
    a, b, c, e = (load(k) for k in "ABCE")
    with open(os.path.join(folder, "states.txt")) as fh:
        names = fh.read().split()
    with open(os.path.join(folder, "meta.json")) as fh:
        meta = json.load(fh)
    n, p, q, m = a.shape[0], c.shape[0], e.shape[1], b.shape[1]
    assert len(names) == n and (meta["n"], meta["p"], meta["q"], meta["m"]) == (n, p, q, m)
    lam, modes = continuous_modes(a, c, names)
    doc = {
        "_meta": {
            "generated_by": f"scripts/models/andes_reference.py, numpy {np.__version__}, scipy {scipy.__version__}",
            "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
            "tolerances": {"RE_TOL": RE_TOL, "CLUSTER_TOL": CLUSTER_TOL, "PBH_TOL": PBH_TOL, "NEAR_TOL": NEAR_TOL,
                           "UNIT_TOL": UNIT_TOL, "ZERO_MATCH": ZERO_MATCH, "SEED": SEED},
            "lqe": f"Q = I, R = {LQE_R} I; scipy.linalg.solve_discrete_are(F', C', Q, R), K = F P C' (C P C' + R)^-1",
            "conventions": "complex numbers as [re, im]; matrices row-major nested lists",
        },
        "case": meta.get("case"), "n": n, "p": p, "q": q, "m": m,
        "eig_A": [cplx(z) for z in sort_cplx(lam)],
        "eig_A_summary": {"max_re": float(lam.real.max()), "min_re": float(lam.real.min()),
                          "max_abs": float(np.abs(lam).max()), "n_re_ge_0": int(np.sum(lam.real >= -RE_TOL))},
        "modes_re_ge_0": modes,
        "unobservable_re_ge_0": [md for md in modes if md["unobservable_dim"]],
        "detectable": not any(md["unobservable_dim"] for md in modes),
        "dt": {},
    }
    rng = np.random.default_rng(SEED)
    for dt in DTS:
        doc["dt"][repr(dt)] = discrete(a, c, e, dt, rng)
    return doc


def fmt_modes(mds):
    if not mds:
        return "none"
    return "; ".join(f"{md['lambda'][0]:+.4g}{md['lambda'][1]:+.4g}j x{md['unobservable_dim']} "
                     f"({', '.join(s for s, _ in md['states'][:3])})" for md in mds)


def table(docs):
    print(f"\n{'case':8} {'n':>4} {'p':>3} {'q':>2} {'m':>3}  {'dt':>6} {'rank CGe':>8} {'zeros':>5} {'near':>4} "
          f"{'|z|>=1':>6} {'UIO':>4} {'UIO DARE s':>10} {'KF det':>6} {'KF DARE s':>9}")
    for name, d in docs.items():
        for dt, r in d["dt"].items():
            u, k = r["uio"], r["kalman"]
            ut = f"{u['dare']['time_s']:.4f}" if "time_s" in u.get("dare", {}) else u.get("dare", {}).get("error", "-")[:10]
            kt = f"{k['dare']['time_s']:.4f}" if "time_s" in k.get("dare", {}) else k.get("dare", {}).get("error", "-")[:9]
            print(f"{name:8} {d['n']:>4} {d['p']:>3} {d['q']:>2} {d['m']:>3}  {dt:>6} {r['rank_C_Gamma_E']:>8} "
                  f"{len(r['invariant_zeros']):>5} {len(r['near_zeros']):>4} {len(r['zeros_outside']):>6} {'yes' if u['exists'] else 'no':>4} "
                  f"{ut:>10} {'yes' if k['detectable'] else 'no':>6} {kt:>9}"
                  + ("" if u["agrees_with_zeros"] else "   (UIO verdict and zeros disagree)"))
    print()
    for name, d in docs.items():
        s = d["eig_A_summary"]
        print(f"{name}: max Re eig(A) = {s['max_re']:.6g}, {s['n_re_ge_0']} with Re >= -{RE_TOL:g}; "
              f"unobservable with Re >= 0: {fmt_modes(d['unobservable_re_ge_0'])}")
        for dt, r in d["dt"].items():
            if r["zeros_outside"]:
                print(f"  dt = {dt}: zeros with |z| >= 1: "
                      + ", ".join(f"{z['z'][0]:.12g}{z['z'][1]:+.3g}j" for z in r["zeros_outside"]))
            if r["uio"].get("unobservable_outside"):
                print(f"  dt = {dt}: (A1, C) unobservable, |z| >= 1: "
                      + ", ".join(f"{b['z'][0]:.12g}{b['z'][1]:+.3g}j (sigma {b['pbh_sigma_rel']:.1e})"
                                  for b in r["uio"]["unobservable_outside"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cases", nargs="*", help="case folders under fixtures/andes/ (default: all)")
    ap.add_argument("--root", default=FIXTURES, help="folder of the case folders (default: %(default)s)")
    args = ap.parse_args()
    cases = args.cases or sorted(d for d in os.listdir(args.root) if os.path.isfile(os.path.join(args.root, d, "A.npy")))
    if not cases:
        sys.exit(f"no case folders in {args.root}")
    docs = {}
    for name in cases:
        folder = os.path.join(args.root, name)
        t0 = time.perf_counter()
        docs[name] = reference(folder)
        with open(os.path.join(folder, "reference.json"), "w") as fh:
            json.dump(docs[name], fh, indent=1)
            fh.write("\n")
        print(f"{name}: wrote {os.path.join(folder, 'reference.json')} ({time.perf_counter() - t0:.1f} s)", flush=True)
    table(docs)


if __name__ == "__main__":
    main()
