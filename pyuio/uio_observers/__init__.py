"""uio-observers from Python: the design library, runs and recordings as NumPy arrays.

    design(A, B, C, E, kind="chen-patton-uio", poles=[...] | gain="lqe", dt=0.001)
    design(sys, E=E, ...)               # sys: a python-control StateSpace (its A, B, C; with a dt, discrete)
    design(Phi, Gamma_B, C, Gamma_E, time="discrete", dt=0.1, ...)   # an identified, per-step model
    run("seed002-sine")                 # a scenario file or a shipped scenario's name
    read("runs/seed002-sine.rrd")
    sweep("seed002-actuator-faults", runs=1000, client=dask_client)   # Monte Carlo, on Dask or here

Every number comes from the Rust library the launcher runs (`uio-launcher design --json`,
`uio-launcher run --mode in-process`, the export's table of a recording), so it equals the CLI's
bit for bit. Bad input raises ValueError, a failed run RuntimeError, with the launcher's message.
"""

import json
import os
import tempfile

import numpy as np

from . import _native

__all__ = ["design", "design_scenario", "run", "read", "sweep", "Design", "Recording", "RunResult", "VaryResult",
           "SweepResult"]


def _toml_number(v):
    v = float(v)
    if not np.isfinite(v):
        raise ValueError(f"{v} is not a finite number")
    return repr(v)


def _toml_matrix(name, m):
    m = np.atleast_2d(np.asarray(m, dtype=float))
    if m.ndim != 2:
        raise ValueError(f"{name}: a matrix (2-D), not {m.ndim}-D")
    return "[" + ", ".join("[" + ", ".join(_toml_number(v) for v in row) + "]" for row in m) + "]"


def _toml_list(v):
    return "[" + ", ".join(_toml_number(x) for x in np.ravel(v)) + "]"


def _toml_poles(poles):
    """Poles as a scenario writes them: a complex pair once, as [re, im] (its conjugate implied)."""
    out, pairs = [], []
    for p in poles:
        p = complex(p)
        if p.imag == 0:
            out.append(_toml_number(p.real))
        elif p.conjugate() in pairs:
            pairs.remove(p.conjugate())
        else:
            pairs.append(p)
            out.append(f"[{_toml_number(p.real)}, {_toml_number(p.imag)}]")
    return "[" + ", ".join(out) + "]"


# The launcher's limits (scenario/src/untrusted.rs, scenario/src/matrix_file.rs): a scenario's
# text and a matrix file. Checked here before anything is built: a 10⁴ × 10⁴ A as TOML text
# took gigabytes and aborted the interpreter.
MAX_SCENARIO_BYTES = 1 << 20
MAX_MATRIX_FILE_BYTES = 1 << 30
# Matrices above this many entries go to the launcher as .npy files (exact bits, no text).
_INLINE_MAX = 256


def _checked(name, m):
    m = np.atleast_2d(np.asarray(m, dtype=float))
    if m.ndim != 2:
        raise ValueError(f"{name}: a matrix (2-D), not {m.ndim}-D")
    if m.nbytes + 128 > MAX_MATRIX_FILE_BYTES:
        raise ValueError(f"{name}: {m.shape[0]} × {m.shape[1]} is {m.nbytes} bytes of doubles, more than the "
                         f"{MAX_MATRIX_FILE_BYTES} bytes (1 GiB) a matrix may hold")
    if not np.all(np.isfinite(m)):
        raise ValueError(f"{name}: holds {m[~np.isfinite(m)][0]}, not a finite number")
    return m


def _matrices(sys, A, B, C, dt, time):
    """(A, B, C, dt, discrete): a continuous model (A, B, C) sampled at dt, or a discrete one
    (Φ, Γ_B, C) of one step of dt — a python-control StateSpace with a numeric dt (an identified
    model, from n4sid or MATLAB's ssest), or time="discrete"."""
    if time not in ("continuous", "discrete"):
        raise ValueError(f'time: "continuous" or "discrete", not {time!r}')
    discrete = time == "discrete"
    if sys is not None:
        if any(m is not None for m in (A, B, C)):
            raise ValueError("give the plant either as sys (a StateSpace) or as A, B, C, not both")
        sys_dt = getattr(sys, "dt", 0)
        if sys_dt is True:
            raise ValueError("sys.dt is True (a discrete model of unspecified period): give it its sample period, "
                             "control.ss(A, B, C, D, dt)")
        if sys_dt not in (0, None):
            if dt is not None and float(dt) != float(sys_dt):
                raise ValueError(f"dt: {dt} differs from sys.dt = {sys_dt} (a discrete model runs at its own period)")
            dt, discrete = float(sys_dt), True
        A, B, C = sys.A, sys.B, sys.C
    if A is None or B is None or C is None:
        raise ValueError("the plant needs A, B and C (or sys)")
    if dt is None:
        raise ValueError("dt: the sample period is needed (or a discrete-time sys, which carries its own)")
    return [np.atleast_2d(np.asarray(m, dtype=float)) for m in (A, B, C)] + [dt, discrete]


def design_scenario(A=None, B=None, C=None, E=None, *, sys=None, D=None, kind="chen-patton-uio", poles=None,
                    gain=None, Q=None, R=None, placement=None, dt=None, time="continuous", x0=None, name="design",
                    files=None, **keys):
    """The scenario text `design` designs: the plant and one observer named `observer`; extra
    keyword arguments become keys of the `[[observer]]` table (e.g. decay=1.0, H=[[...]]).
    A discrete-time plant (a StateSpace with a numeric dt, or time="discrete" with A, B, E the
    per-step Φ, Γ_B, Γ_E) is written as such (`[plant] time = "discrete"`).
    With `files` (a folder), plant matrices of more than 256 entries are written there as
    `<name>.npy` and the text names them (as a scenario beside its matrix files does)."""
    A, B, C, dt, discrete = _matrices(sys, A, B, C, dt, time)
    column = lambda m: None if m is None else np.asarray(m, dtype=float).reshape(len(m), -1)  # noqa: E731 (a 1-D E is one column)
    E, D = column(E), column(D)
    plant = {k: _checked(k, m) for k, m in (("A", A), ("B", B), ("C", C), ("E", E), ("D", D)) if m is not None and (m.size or k in "ABC")}
    n = plant["A"].shape[0]

    def entry(k, m):
        if files is not None and m.size > _INLINE_MAX:
            np.save(os.path.join(files, f"{k}.npy"), m)
            return f'{k} = "{k}.npy"'
        return f"{k} = {_toml_matrix(k, m)}"

    lines = [f'name = "{name}"', f"dt = {_toml_number(dt)}", f"duration = {_toml_number(dt)}", "", "[plant]"]
    if discrete:
        lines.append('time = "discrete"')
    # A discrete plant's matrices are named as the scenario format names them: Φ, Γ_B, Γ_E.
    key = {"A": "Phi", "B": "Gamma_B", "E": "Gamma_E"} if discrete else {}
    lines += [entry(key.get(k, k), m) for k, m in plant.items()]
    lines.append(f"x0 = {_toml_list(np.zeros(n) if x0 is None else x0)}")
    # A design needs no signals, but a scenario names one per column of B, E and D.
    for table, m in (("input", B), ("disturbance", E), ("measurement_disturbance", D)):
        for _ in range(0 if m is None or not m.size else m.shape[1]):
            lines += ["", f"[[{table}]]", 'kind = "constant"', "value = 0.0"]
    lines += ["", "[[observer]]", 'name = "observer"', f'kind = "{kind}"']
    if poles is not None:
        lines.append(f"poles = {_toml_poles(poles)}")
    if gain is not None:
        lines.append(f'gain = "{gain}"')
    if Q is not None:
        lines.append(f"Q = {_toml_matrix('Q', Q)}")
    if R is not None:
        lines.append(f"R = {_toml_matrix('R', R)}")
    if placement is not None:
        lines.append(f'placement = "{placement}"')
    for k, v in keys.items():
        if isinstance(v, str):
            lines.append(f'{k} = "{v}"')
        elif np.ndim(v) == 2:
            lines.append(f"{k} = {_toml_matrix(k, v)}")
        elif np.ndim(v) == 1:
            lines.append(f"{k} = {_toml_list(v)}")
        else:
            lines.append(f"{k} = {_toml_number(v)}")
    return "\n".join(lines) + "\n"


class Design:
    """An observer's design: `continuous` (the design's own matrices, e.g. N, L, G, H for a
    Chen–Patton UIO), `sampled` (F, G, K, P, Q of z⁺ = Fz + Gu + Ky, x̂ = Pz + Qy at `dt`),
    `poles`, `discrete_poles`, `fixed_modes` (complex arrays), `conditions` [(name, ok, detail)],
    `report` (the launcher's text) and `json` (its JSON, as `uio-launcher design --json` prints it)."""

    def __init__(self, report, text, args=(), kw=None):
        self.json = report
        self.report = text
        self._args, self._kw, self._freq = args, kw or {}, None
        o = report["observers"][0]
        self.kind = o["kind"]
        self.conditions = [(c["name"], c["ok"], c["detail"]) for c in o["conditions"]]
        self.continuous = {k: np.array(v, dtype=float).reshape(len(v), -1) if len(v) else np.zeros((0, 0)) for k, v in o["matrices"].items()}
        s = o["sampled"]
        self.dt = s["dt"]
        self.sampled = {k: np.array(s[k], dtype=float).reshape(len(s[k]), -1) if len(s[k]) else np.zeros((0, 0)) for k in "FGKPQ"}
        c = lambda pairs: np.array([complex(re, im) for re, im in pairs])  # noqa: E731
        self.poles, self.discrete_poles, self.fixed_modes = c(o["poles"]), c(o["discrete_poles"]), c(o["fixed_modes"])

    def statespace(self):
        """The sampled observer as a python-control system from [u; y] to x̂ (dt = self.dt), its
        inputs named u1 … u_l, y1 … y_p (the known inputs, then the measurements) and its outputs
        xhat1 … xhat_n (the estimates)."""
        import control

        F, G, K, P, Q = (self.sampled[k] for k in "FGKPQ")
        names = [f"u{i + 1}" for i in range(G.shape[1])] + [f"y{j + 1}" for j in range(K.shape[1])]
        return control.ss(F, np.hstack([G, K]), P, np.hstack([np.zeros((P.shape[0], G.shape[1])), Q]), self.dt,
                          inputs=names, outputs=[f"xhat{i + 1}" for i in range(P.shape[0])], name="observer")

    def freq(self):
        """The frequency responses of `uio-launcher design --freq` as NumPy arrays: `omega` (rad/s,
        up to Nyquist) and per transfer "w_e", "v_e", "w_r", "v_r" (None without unknown inputs) a
        dict of `sigma_max`, `sigma_min` (arrays over omega), `hinf`, `hinf_omega`, `dc` (the DC
        gain matrix, None at a plant integrator the observer's own coordinates cannot remove) and
        `decoupled` (w → e at rounding level: a UIO)."""
        if self._freq is None:
            with tempfile.TemporaryDirectory(prefix="uio-design-") as files:
                text = design_scenario(*self._args, files=files, **self._kw)
                _, report, _ = _native.design(os.path.join(files, "design.toml"), text, True)
            self._freq = json.loads(report)["freq"]
        f = self._freq
        s = f["systems"][0]

        def arrays(r, key):
            if r is None:
                return None
            dc = None if r["dc"] is None else np.array(r["dc"], dtype=float)
            return {"sigma_max": np.array(r["sigma_max"]), "sigma_min": np.array(r["sigma_min"]),
                    "hinf": r["hinf"], "hinf_omega": r["hinf_omega"], "dc": dc,
                    "decoupled": bool(s["w_decoupled"]) and key.startswith("w")}

        out = {"omega": np.array(f["omega"])}
        out.update({k: arrays(s[k], k) for k in ("w_e", "v_e", "w_r", "v_r")})
        return out

    def __repr__(self):
        return f"Design({self.kind}, dt={self.dt}, discrete poles {np.round(self.discrete_poles, 6).tolist()})"


def _argument_error(message):
    """The launcher's message about the scenario `design` wrote, told in the arguments' terms:
    "…/design.toml:36:8: observer[1].poles: …" becomes "poles: …", "plant.A: …" becomes "A: …" —
    the file is a generated one the caller never saw."""
    import re

    m = re.match(r"^.*?design\.toml(?::\d+:\d+)?: (.*)$", message, re.S)
    if not m:
        return message
    rest = m.group(1)
    rest = re.sub(r"^observer\[1\]\.", "", rest)
    rest = re.sub(r"^observer\[1\]: ", "", rest)
    rest = re.sub(r"^plant\.", "", rest)
    # A discrete plant's matrices are the arguments A, B and E.
    return re.sub(r"^(Phi|Gamma_B|Gamma_E)\b", lambda k: {"Phi": "A", "Gamma_B": "B", "Gamma_E": "E"}[k.group(1)], rest)


def design(A=None, B=None, C=None, E=None, **kw):
    """Designs one observer of `kind` for ẋ = Ax + Bu + Ew, y = Cx (+ Dv) sampled at `dt`; see
    `design_scenario` for the keywords. Raises ValueError, with the launcher's reason, when the
    design's conditions do not hold."""
    with tempfile.TemporaryDirectory(prefix="uio-design-") as files:
        text = design_scenario(A, B, C, E, files=files, **kw)
        if len(text.encode()) > MAX_SCENARIO_BYTES:
            raise ValueError(f"the design's scenario text is {len(text.encode())} bytes, more than the "
                             f"{MAX_SCENARIO_BYTES} a scenario may hold (its lists grow with the model's order)")
        try:
            ok, report, lines = _native.design(os.path.join(files, "design.toml"), text)
        except ValueError as e:
            raise ValueError(_argument_error(str(e))) from None
    report = json.loads(report)
    if not ok:
        o = report["observers"][0]
        raise ValueError(o.get("error") or next((ln.strip() for ln in lines.splitlines() if "FAIL" in ln), lines.strip()))
    return Design(report, lines, (A, B, C, E), kw)


class Recording:
    """A recording's signals: `t` and `step` (one row per recorded step) and, per entity group,
    a steps × members array (`groups["/observer/uio/xhat"]`, also `recording["observer_uio_xhat"]`),
    NaN where a member has no value at a step; `names[group]` and `labels[group]` name the
    columns as the CSV export heads them."""

    def __init__(self, path):
        steps, dt, groups = _native.read(os.fspath(path))
        self.path = os.fspath(path)
        self.step = np.frombuffer(steps, dtype="<i8").copy()
        self.dt = dt
        self.t = self.step * dt if dt is not None else None
        self.groups, self.names, self.labels = {}, {}, {}
        for group, names, labels, values in groups:
            self.groups[group] = np.frombuffer(values, dtype="<f8").reshape(len(self.step), len(names)).copy()
            self.names[group], self.labels[group] = names, labels

    def __getitem__(self, key):
        g = key if key.startswith("/") else "/" + key.replace("_", "/")
        if key in self.groups:
            return self.groups[key]
        for path, values in self.groups.items():
            if path.strip("/").replace("/", "_") == key or path == g:
                return values
        raise KeyError(key)

    def __repr__(self):
        return f"Recording({self.path!r}, {len(self.step)} steps, {len(self.groups)} groups)"


def read(path):
    """Reads a `.rrd` recording (ValueError for a missing, damaged or foreign file)."""
    return Recording(path)


class RunResult(Recording):
    """A finished run: its recording's signals, `summary` (the summary JSON as a dict) and `ok`
    (completed, every expectation met)."""

    def __init__(self, rrd, summary, ok):
        super().__init__(rrd)
        self.summary, self.ok = json.loads(summary), ok


def run(scenario, out=None, force=True):
    """Runs a scenario (a file, or a shipped scenario's name) in this process, recording it to
    `out`; returns a RunResult. Without `out` the recording goes to a temporary folder that is
    removed once its signals are read (the result's `path` is then None: pass `out` to keep the
    `.rrd`). External components (`kind = "process"`, `[plant.process]`, an FMU plant) need
    `uio-launcher run` across processes."""
    if out is not None:
        rrd, summary, ok = _native.run(os.fspath(scenario), os.fspath(out), force)
        return RunResult(rrd, summary, ok)
    with tempfile.TemporaryDirectory(prefix="uio-run-") as tmp:
        rrd, summary, ok = _native.run(os.fspath(scenario), tmp, force)
        result = RunResult(rrd, summary, ok)
    result.path = None
    return result


class SweepResult:
    """A merged sweep: `summary` (`<name>.sweep.json` as a dict: per fault detections, delays and
    isolation, false alarms, per residual the measured false-alarm probability, per observer the
    tail error, `kept` the worst seeds), `table` (what `uio-launcher sweep` prints) and `path` (the
    summary file)."""

    def __init__(self, summary, table, path):
        self.summary, self.table, self.path = json.loads(summary), table, path

    def __repr__(self):
        return self.table


def _shard(scenario, runs, seed, k, n, keep_worst, jobs, out):
    """One shard, where it runs (a Dask worker, or here): the path of its shard file."""
    from uio_observers import _native as native  # a worker imports the package itself

    folder = os.path.join(out, f"shard-{k}-of-{n}")
    return native.sweep_shard(scenario, runs, seed, k, n, keep_worst, jobs, folder)


class VaryResult:
    """A variation (`sweep(…, vary=…)`): `summary` (`<name>.vary.json` as a dict: per point its
    values, status and figures; per figure its worst point), `table` (what `uio-launcher sweep
    --vary` prints) and `path` (the folder holding the CSV, JSON and PNGs, None when temporary)."""

    def __init__(self, summary, table, path):
        self.summary, self.table, self.path = json.loads(summary), table, path

    def __repr__(self):
        return self.table


def _vary(scenario, vary, points, seed, jobs, out):
    if isinstance(vary, str):
        vary = [vary]
    if out is not None:
        folder = os.path.abspath(os.fspath(out))
        os.makedirs(folder, exist_ok=True)
        return VaryResult(*_native.vary(scenario, list(vary), points, seed, jobs, folder), folder)
    with tempfile.TemporaryDirectory(prefix="uio-vary-") as tmp:
        return VaryResult(*_native.vary(scenario, list(vary), points, seed, jobs, tmp), None)


def sweep(scenario, runs=100, *, seed=None, keep_worst=0, shards=None, client=None, out=None,
          jobs=1, vary=None, points=20):
    """Monte Carlo over the noise, as `uio-launcher sweep` (realisation i has seed S + i, S = `seed`
    or the scenario's): returns a SweepResult equal to `uio-launcher sweep`'s, field by field but the
    wall time and the jobs.

    With `vary` (one `--vary` text or a list of them, e.g. `"A[2,3] *= 0.8..1.2:5"` or
    `"plant.fmu.parameters.J *= [0.5, 2]"`), the plant is varied instead, as `uio-launcher sweep
    --vary` (`points` draws of a distribution, `jobs` threads): returns a VaryResult equal to its
    JSON. A variation runs here (`runs`, `keep_worst`, `shards` and `client` are a noise sweep's).

    The realisations run in `shards` shards (`uio-launcher sweep --shard K/N`), each in one process
    with `jobs` threads: on `client`'s workers when it is a `dask.distributed.Client` (one task
    per shard; `shards` defaults to four per worker), else here one after another (`shards`
    defaults to 1). Each shard writes its file and its worst realisations' recordings in
    `out/shard-K-of-N/`, and the merge (`uio-launcher sweep merge`) writes `out/<name>.sweep.json`
    with the worst recordings: so `out` must be a folder every worker reaches (always true of a
    `LocalCluster`; a shared file system for a cluster of machines), and so must `scenario`.
    Without `out` a temporary folder holds the shards and the result (`path` None after)."""
    scenario = os.path.abspath(os.fspath(scenario)) if os.path.exists(os.fspath(scenario)) \
        else os.fspath(scenario)
    if vary is not None:
        if client is not None or shards is not None or keep_worst or runs != 100:
            raise ValueError("vary: a variation runs each point once, here; runs, keep_worst, shards "
                             "and client are a noise sweep's")
        return _vary(scenario, vary, points, seed, jobs, out)
    if shards is None:
        shards = 1 if client is None else 4 * max(1, len(client.scheduler_info().get("workers", {})))
    shards = max(1, min(int(shards), int(runs)))

    def merged(folder):
        ks = range(1, shards + 1)
        args = [(scenario, runs, seed, k, shards, keep_worst, jobs, folder) for k in ks]
        if client is None:
            files = [_shard(*a) for a in args]
        else:
            futures = [client.submit(_shard, *a, pure=False) for a in args]
            files = client.gather(futures)
        summary, table, path = _native.sweep_merge(files, folder)
        return SweepResult(summary, table, path)

    if out is not None:
        folder = os.path.abspath(os.fspath(out))
        os.makedirs(folder, exist_ok=True)
        return merged(folder)
    with tempfile.TemporaryDirectory(prefix="uio-sweep-") as tmp:
        result = merged(tmp)
    result.path = None
    return result

