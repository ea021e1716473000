"""How a component is started and what it is told (PROTOCOL.md §1–§3).

`launch()` does the checks of §1 — the protocol version in `$UIO_PROTOCOL`, the parent being
the run's launcher (`$UIO_RUNS_DIR/$UIO_RUN/owner.pid`), stdin not a terminal, PR_SET_PDEATHSIG
— and reads `$UIO_CONFIG` (§3) into a `Config`. Every refusal is a `ComponentExit` with exit
code 2 and one line of text.
"""

from __future__ import annotations

import ctypes
import json
import math
import os
import re
import signal
import stat
import sys
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

#: The protocol version this kit speaks (PROTOCOL.md §9).
PROTOCOL_VERSION = 1

#: Exit codes (PROTOCOL.md §1, §6).
EXIT_OK = 0
EXIT_USAGE = 2
EXIT_FAILED = 3
EXIT_DIVERGED = 4

#: Where run directories live when `$UIO_RUNS_DIR` is not set and there is no usable
#: `$XDG_RUNTIME_DIR` (the launcher's rule: see `default_runs_dir`): one per user.
DEFAULT_RUNS_DIR = f"/tmp/uio-observers-{os.geteuid()}"


def default_runs_dir(env):
    """`$XDG_RUNTIME_DIR/uio-observers` when that is an absolute real directory of ours, else
    `DEFAULT_RUNS_DIR` — the launcher's own rule (lockstep's run_dir.rs)."""
    xdg = env.get("XDG_RUNTIME_DIR")
    if xdg and os.path.isabs(xdg):
        try:
            st = os.lstat(xdg)
            if stat.S_ISDIR(st.st_mode) and st.st_uid == os.geteuid():
                return os.path.join(xdg, "uio-observers")
        except OSError:
            pass
    return DEFAULT_RUNS_DIR


def read_owner(path):
    """The pid in a run's `owner.pid`, opened without following a symlink and without blocking
    (a FIFO planted there is refused, not waited on); only a regular file of ours, in a run
    directory and a runs directory that are real directories of ours (not symlinks), counts."""
    run_dir = os.path.dirname(path)
    for d in (run_dir, os.path.dirname(run_dir)):
        st = os.lstat(d)
        if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.geteuid():
            raise ValueError(f"{d} is not a real directory of this user")
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_uid != os.geteuid():
            raise ValueError("not a regular file of this user")
        return int(os.read(fd, 64).decode("ascii").strip())
    finally:
        os.close(fd)


class ComponentExit(Exception):
    """Ends the component with `code`, writing `message` (one line) on stderr."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code
        self.message = one_line(message)


class Diverged(Exception):
    """Raise it from a plant's step when the state diverged: the component exits with 4."""


def one_line(text: str) -> str:
    """`text` on one line: the launcher quotes a failed component's last line of stderr."""
    return " ".join(str(text).split())


@dataclass(frozen=True)
class Publish:
    """`publishes`: the one service the component publishes on."""

    service: str
    len: int
    names: List[str] = field(default_factory=list)


@dataclass(frozen=True)
class Read:
    """One entry of `reads`."""

    service: str
    len: int
    lag: int = 0
    #: Named ranges [start, end) of the values (the plant's sample layout), e.g. {"y": (3, 5)}.
    fields: Dict[str, Tuple[int, int]] = field(default_factory=dict)
    #: Not part of the protocol: a hint to poll this input with this sleep (µs).
    sleep_us: Optional[int] = None

    def field(self, values: np.ndarray, name: str) -> np.ndarray:
        """The named range of `values` (a view)."""
        start, end = self.fields[name]
        return values[start:end]


@dataclass(frozen=True)
class Model:
    """`model`: the scenario's design model. Matrices are 2-D numpy arrays; `D` and `E` may have
    no columns (p×0, n×0), `B` none either (n×0)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    E: np.ndarray
    x0: np.ndarray

    @property
    def n(self) -> int:
        """States."""
        return self.A.shape[0]

    @property
    def p(self) -> int:
        """Outputs (rows of C)."""
        return self.C.shape[0]

    @property
    def q(self) -> int:
        """Unknown inputs (columns of E)."""
        return self.E.shape[1]

    @property
    def r(self) -> int:
        """Measurement disturbances (columns of D)."""
        return self.D.shape[1]

    @property
    def l(self) -> int:  # noqa: E743 — the papers' name for the number of known inputs
        """Known inputs (columns of B)."""
        return self.B.shape[1]

    def plant_fields(self) -> Dict[str, Tuple[int, int]]:
        """The ranges of the plant's sample (PROTOCOL.md §4):
        `[x (n) | y (p) | w (q) | v (r) | r (l) | u_prev (l)]`."""
        sizes = [("x", self.n), ("y", self.p), ("w", self.q), ("v", self.r), ("r", self.l), ("u_prev", self.l)]
        out, start = {}, 0
        for name, size in sizes:
            out[name] = (start, start + size)
            start += size
        return out

    def plant_len(self) -> int:
        """Values in the plant's sample: n + p + q + r + 2l."""
        return self.n + self.p + self.q + self.r + 2 * self.l


@dataclass(frozen=True)
class Config:
    """The configuration file (PROTOCOL.md §3)."""

    protocol: int
    run: str
    name: str
    role: str
    prefix: str
    root: str
    wait: str
    dt: float
    steps: int
    publishes: Publish
    reads: List[Read]
    model: Optional[Model]
    #: The scenario's signals, for plants: {"disturbances": [...], "measurement_disturbances":
    #: [...], "inputs": [...]}, each signal in the scenario's JSON form (see `signals`).
    signals: Dict[str, Any]
    params: Any
    #: The whole JSON object, for anything a later version adds.
    raw: Dict[str, Any]

    def read_index(self, service: str) -> Optional[int]:
        """Index in `reads` of the input read from `service`, if any."""
        for i, r in enumerate(self.reads):
            if r.service == service:
                return i
        return None


def _matrix(rows: Any, nrows: int, name: str) -> np.ndarray:
    """A matrix given as rows; an absent or empty one is nrows×0."""
    if rows is None or (isinstance(rows, list) and len(rows) == 0):
        return np.zeros((nrows, 0))
    a = np.array(rows, dtype=np.float64)
    if a.ndim != 2:
        raise ValueError(f"model.{name}: not a list of rows of equal length")
    return a


def parse_model(obj: Any) -> Optional[Model]:
    """`model`, or None when the configuration has none."""
    if not obj:
        return None
    a = np.array(obj["A"], dtype=np.float64)
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ValueError("model.A: not square")
    n = a.shape[0]
    c = _matrix(obj.get("C"), 0, "C")
    p = c.shape[0]
    x0 = np.array(obj.get("x0", [0.0] * n), dtype=np.float64).reshape(-1)
    model = Model(A=a, B=_matrix(obj.get("B"), n, "B"), C=c, D=_matrix(obj.get("D"), p, "D"),
                  E=_matrix(obj.get("E"), n, "E"), x0=x0)
    for name, m, rows in (("B", model.B, n), ("D", model.D, p), ("E", model.E, n)):
        if m.shape[0] != rows:
            raise ValueError(f"model.{name}: {m.shape[0]} rows, expected {rows}")
    if c.shape[1] != n or x0.shape[0] != n:
        raise ValueError(f"model: C or x0 do not have n = {n} columns")
    return model


def parse_config(obj: Dict[str, Any]) -> Config:
    """Checks and converts the configuration's JSON object; raises ValueError."""
    try:
        pub = obj["publishes"]
        reads = [
            Read(service=str(r["service"]), len=int(r["len"]), lag=int(r.get("lag", 0)),
                 fields={k: (int(v[0]), int(v[1])) for k, v in (r.get("fields") or {}).items()},
                 sleep_us=r.get("sleep_us"))
            for r in obj.get("reads", [])
        ]
        cfg = Config(
            protocol=int(obj["protocol"]),
            run=str(obj["run"]),
            name=str(obj["name"]),
            role=str(obj["role"]),
            prefix=str(obj["iceoryx2"]["prefix"]),
            root=str(obj["iceoryx2"]["root"]),
            wait=str(obj.get("wait", "yield")),
            dt=float(obj["dt"]),
            steps=int(obj["steps"]),
            publishes=Publish(service=str(pub["service"]), len=int(pub["len"]), names=list(pub.get("names", []))),
            reads=reads,
            model=parse_model(obj.get("model")),
            signals=obj.get("signals") or {},
            params=obj.get("params") if obj.get("params") is not None else {},
            raw=obj,
        )
    except KeyError as e:
        raise ValueError(f"missing key {e}") from None
    except (TypeError, IndexError) as e:
        raise ValueError(str(e)) from None
    if cfg.role not in ("plant", "observer", "controller"):
        raise ValueError(f"role '{cfg.role}' is not plant, observer or controller")
    if not (math.isfinite(cfg.dt) and cfg.dt > 0) or cfg.steps < 0:
        raise ValueError("dt must be > 0 and steps ≥ 0")
    if cfg.publishes.len < 1 or any(r.len < 1 or r.lag < 0 for r in cfg.reads):
        raise ValueError("every service holds at least one value, lags are ≥ 0")
    return cfg


def load_config(path: str) -> Config:
    """Reads and parses a configuration file."""
    with open(path, encoding="utf-8") as f:
        return parse_config(json.load(f))


def die_with_parent() -> None:
    """Asks the kernel to kill this process when its parent (the launcher) dies
    (Linux prctl(PR_SET_PDEATHSIG, SIGKILL); nothing elsewhere)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        PR_SET_PDEATHSIG = 1
        libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):
        pass
    # A parent that died before the flag was set is caught by the owner check: the new parent
    # is then not the run's launcher.


def launch(environ: Optional[Dict[str, str]] = None) -> Config:
    """PROTOCOL.md §1: checks how this process was started and reads its configuration.

    Raises `ComponentExit(2, ...)` when the run speaks another protocol version, when the
    parent is not the run's launcher, when stdin is a terminal, or when the configuration cannot
    be read.
    """
    env = os.environ if environ is None else environ
    how = ("this program is one process of a co-simulation and is started by the launcher, "
           "e.g. `uio-launcher run scenarios/cartpole-python-plant.toml`")
    version = env.get("UIO_PROTOCOL")
    if version is None:
        raise ComponentExit(EXIT_USAGE, f"{how} (UIO_PROTOCOL is not set)")
    if version.strip() != str(PROTOCOL_VERSION):
        raise ComponentExit(EXIT_USAGE, f"the run speaks protocol version {version.strip()}, "
                                        f"this component {PROTOCOL_VERSION}")
    run = env.get("UIO_RUN")
    path = env.get("UIO_CONFIG")
    if not run or not path:
        raise ComponentExit(EXIT_USAGE, f"{how} (UIO_RUN or UIO_CONFIG is not set)")
    if not re.fullmatch(r"[A-Za-z0-9]+", run):
        raise ComponentExit(EXIT_USAGE, f"{how} (run id {run!r} is not letters and digits)")
    owner_file = os.path.join(env.get("UIO_RUNS_DIR") or default_runs_dir(env), run, "owner.pid")
    try:
        owner = read_owner(owner_file)
    except (OSError, ValueError):
        raise ComponentExit(EXIT_USAGE, f"{how} (no run '{run}': {owner_file} is missing or not a regular file of this user)") from None
    parent = os.getppid()
    if parent != owner:
        raise ComponentExit(EXIT_USAGE, f"{how} (its parent, pid {parent}, is not the launcher of run '{run}')")
    if sys.stdin is None or sys.stdin.isatty():
        raise ComponentExit(EXIT_USAGE, f"{how} (stdin is a terminal, not the launcher's pipe)")
    try:
        cfg = load_config(path)
    except (OSError, ValueError) as e:
        raise ComponentExit(EXIT_USAGE, f"{path}: {e}") from None
    if cfg.protocol != PROTOCOL_VERSION:
        raise ComponentExit(EXIT_USAGE, f"configuration of protocol version {cfg.protocol}, "
                                        f"this component speaks {PROTOCOL_VERSION}")
    return cfg
