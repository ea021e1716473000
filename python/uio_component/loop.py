"""The life of a component: `run(step, setup)` (PROTOCOL.md §1, §5).

1. `launch()`: PR_SET_PDEATHSIG, protocol version, parent, stdin, `$UIO_CONFIG` (exit 2).
2. `setup(config)` once, if given; what it returns is the state passed to every step.
3. The ports: the one `publishes` service and every `reads` service (§4), events if the run's
   `wait` needs them.
4. `ready` on stdout, then `go` on stdin (anything else, or its end: exit 0). stdout is
   stderr from the start: a `print` in the component can neither come before `ready` nor fill
   the launcher's pipe.
5. The steps of §5:
   - plant: step(k, inputs) with the inputs of step k − 1 (zeros at k = 0) → sample k, for
     k = 0 … K − 1; then, once every input (trailing ones too) has delivered step K − 1, the end
     sample K, so the plant's step is called K + 1 times;
   - observer, controller: the step-k samples of every input with `lag` 0 (and at least step
     k − lag of the others) → step(k, inputs) → sample k, for k = 0 … K − 1.
   Exit 0.

Failures: a sample of the wrong step, length or protocol, or none within 10 s → one line
`<name>: step k: …` on stderr, exit 3; an exception in `step` → `<name>: step k: <exception>`,
in `setup` → `<name>: setup: <exception>`, exit 3 (`Diverged` from a plant's step: exit 4). Set
`UIO_TRACEBACK=1` in the launcher's environment to get the traceback too (before that line).
"""

from __future__ import annotations

import math
import os
import time
import sys
import traceback
from typing import Any, Callable, List, Optional

import numpy as np

from .config import (EXIT_DIVERGED, EXIT_FAILED, EXIT_OK, ComponentExit, Config, Diverged,
                     die_with_parent, launch, one_line)
from .wire import Bus, Inlet, Outlet, ProtocolError, Received, now_ns

#: A component's own waits end after this long (PROTOCOL.md §6).
TIMEOUT_S = 10.0


def _describe(e: BaseException) -> str:
    text = str(e)
    return one_line(f"{type(e).__name__}: {text}" if text else type(e).__name__)


class Stepper:
    """The step order of PROTOCOL.md §5 around a step function, on ports already made."""

    def __init__(self, config: Config, outlet: Outlet, inlets: List[Inlet], step: Callable[..., Any],
                 state: Any = None, with_state: bool = False, timeout_s: Optional[float] = None) -> None:
        self.config = config
        self.outlet = outlet
        self.inlets = inlets
        self.lags = [r.lag for r in config.reads]
        self.step_fn = step
        self.state = state
        self.with_state = with_state
        #: How long a wait for an input may last: the configuration's `inlet_timeout_s` (set by
        #: the launcher above its stall limit, PROTOCOL.md §6), else TIMEOUT_S.
        given = config.raw.get("inlet_timeout_s")
        self.timeout_s = timeout_s if timeout_s is not None else (
            float(given) if isinstance(given, (int, float)) and not isinstance(given, bool) and math.isfinite(given) and given > 0 else TIMEOUT_S)
        #: Real-time pacing of a plant (`pace_s`, PROTOCOL.md §5): sample k goes out no earlier
        #: than t0 + k·pace, t0 when sample 0 did.
        pace = config.raw.get("pace_s") if config.role == "plant" else None
        self.pace_ns = int(round(float(pace) * 1e9)) if pace else None
        self.t0 = 0
        #: The latest values of every input, in `reads` order (what the step function gets).
        self.inputs = [np.zeros(r.len) for r in config.reads]
        #: The header of every input's latest sample.
        self.headers: List[Optional[Received]] = [None] * len(inlets)
        #: Steps taken from each input.
        self.done = [0] * len(inlets)

    def take(self, j: int, everything: bool = False) -> int:
        """Reads step j of every input: exactly for `lag` 0; for a trailing input whatever has
        arrived and at least step j − lag (all up to j when `everything`). Returns when the
        step's last exact input was taken (now, with none)."""
        taken = 0
        for i, inlet in enumerate(self.inlets):
            out = self.inputs[i]
            if self.lags[i] == 0:
                # An exact input may still have earlier steps queued only if it trails; take
                # them in order (each is checked), the last one is step j.
                while self.done[i] <= j:
                    h = inlet.take(self.done[i], out, self.timeout_s)
                    self.headers[i] = h
                    self.done[i] += 1
                taken = max(taken, self.headers[i].received_ns)
                continue
            while True:
                h = inlet.try_take(self.done[i], out)
                if h is None:
                    break
                self.headers[i] = h
                self.done[i] += 1
            need = j + 1 if everything else j + 1 - self.lags[i]
            while self.done[i] < need:
                self.headers[i] = inlet.take(self.done[i], out, self.timeout_s)
                self.done[i] += 1
        return taken or now_ns()

    def call(self, k: int) -> np.ndarray:
        """The user's step k, its result as `publishes.len` float64 values."""
        try:
            if self.with_state:
                result = self.step_fn(k, self.inputs, self.state)
            else:
                result = self.step_fn(k, self.inputs)
        except Diverged as e:
            raise ComponentExit(EXIT_DIVERGED, f"step {k}: diverged: {e}") from None
        except ComponentExit:
            raise
        except SystemExit as e:
            # sys.exit() inside a step would end the process with status 0 before the run's end.
            raise ComponentExit(EXIT_FAILED, f"step {k}: the step called sys.exit({e.code!r})") from None
        except Exception as e:  # noqa: BLE001 — any failure of the user's code ends the run
            if os.environ.get("UIO_TRACEBACK"):
                traceback.print_exc()
            raise ComponentExit(EXIT_FAILED, f"step {k}: {_describe(e)}") from None
        try:
            out = np.ascontiguousarray(result, dtype=np.float64).reshape(-1)
        except (TypeError, ValueError) as e:
            raise ComponentExit(EXIT_FAILED, f"step {k}: the step returned no array of numbers ({_describe(e)})") from None
        if out.shape[0] != self.outlet.len:
            raise ComponentExit(EXIT_FAILED, f"step {k}: the step returned {out.shape[0]} values, "
                                             f"'{self.outlet.service}' takes {self.outlet.len}")
        return out

    def _transport(self, k: int, f: Callable[..., Any], *args: Any) -> Any:
        """`f(*args)`, a failure of the transport turned into exit 3 naming step k."""
        try:
            return f(*args)
        except ProtocolError as e:
            raise ComponentExit(EXIT_FAILED, f"step {k}: {e}") from None
        except ComponentExit:
            raise
        except Exception as e:  # noqa: BLE001 — iceoryx2 reports its errors as exceptions
            raise ComponentExit(EXIT_FAILED, f"step {k}: iceoryx2: {_describe(e)}") from None

    def step(self, k: int) -> None:
        """Step k of the ring."""
        dt = self.config.dt
        if self.config.role == "plant":
            taken, sim_time = (0, 0.0) if k == 0 else (self._transport(k, self.take, k - 1), k * dt)
        else:
            taken = self._transport(k, self.take, k)
            # t_k as the first exact (lag 0) input carries it; k·dt with none.
            exact = [h for h, lag in zip(self.headers, self.lags) if lag == 0]
            sim_time = exact[0].sim_time if exact and exact[0] is not None else k * dt
        out = self.call(k)
        self.pace(k)
        self._transport(k, self.outlet.send, k, sim_time, taken, out)

    def pace(self, k: int) -> None:
        """A paced plant waits until t0 + k·pace before it publishes sample k."""
        if self.pace_ns is None:
            return
        if k == 0:
            self.t0 = now_ns()
            return
        while True:
            left = self.t0 + k * self.pace_ns - now_ns()
            if left <= 0:
                return
            time.sleep(left * 1e-9)

    def finish(self) -> None:
        """After step K − 1: the plant's end sample K, once every input has delivered K − 1."""
        if self.config.role != "plant":
            return
        k = self.config.steps
        taken = 0 if k == 0 else self._transport(k, self.take, k - 1, True)
        out = self.call(k)
        self.pace(k)
        self._transport(k, self.outlet.send, k, k * self.config.dt, taken, out)

    def run(self) -> None:
        """Every step, then the end sample."""
        for k in range(self.config.steps):
            self.step(k)
        self.finish()


def open_ports(config: Config, bus: Bus):
    """The outlet of `publishes` and an inlet per `reads` entry (PROTOCOL.md §4)."""
    outlet = bus.outlet(config.publishes.service, config.publishes.len)
    inlets = [bus.inlet(r.service, r.len, r.sleep_us) for r in config.reads]
    return outlet, inlets


def divert_stdout() -> int:
    """Points fd 1 and `sys.stdout` at stderr, so that nothing the component prints reaches the
    launcher's pipe (it could fill it, or come before `ready`); returns a descriptor of the
    pipe, for `ready` (kept open, like the stdout of our Rust components)."""
    sys.stdout.flush()
    pipe = os.dup(1)
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    return pipe


def ready_then_wait_for_go(pipe: int) -> bool:
    """Writes `ready` on the launcher's pipe, waits for `go` (PROTOCOL.md §5.2); False when the
    run was stopped (anything else on stdin, or its end)."""
    os.write(pipe, b"ready\n")
    return sys.stdin.buffer.readline() == b"go\n"


def run(step: Callable[..., Any], setup: Optional[Callable[[Config], Any]] = None) -> None:
    """Runs this process as a component of a launched run; never returns (exits).

    `step(k, inputs)` — or `step(k, inputs, state)` when `setup` is given, with what `setup`
    returned — gets the step number k and `inputs`, one float64 numpy array per entry of the
    configuration's `reads`, in that order (the kit's buffers: copy what you keep), and returns
    the `publishes.len` values of its sample k (any array-like of floats).

    `setup(config)` is called once, before `ready`, with the `Config`.
    """
    name = os.environ.get("UIO_NAME") or os.path.splitext(os.path.basename(sys.argv[0] or "component"))[0]
    code, message = EXIT_OK, None
    bus = None
    try:
        die_with_parent()
        pipe = divert_stdout()
        config = launch()
        name = config.name
        try:
            state = setup(config) if setup is not None else None
        except ComponentExit:
            raise
        except Exception as e:  # noqa: BLE001
            if os.environ.get("UIO_TRACEBACK"):
                traceback.print_exc()
            raise ComponentExit(EXIT_FAILED, f"setup: {_describe(e)}") from None
        try:
            bus = Bus(config.prefix, config.root, config.name, config.wait)
            outlet, inlets = open_ports(config, bus)
        except Exception as e:  # noqa: BLE001 — iceoryx2 reports as exceptions
            raise ComponentExit(EXIT_FAILED, f"iceoryx2: {_describe(e)}") from None
        stepper = Stepper(config, outlet, inlets, step, state, with_state=setup is not None)
        try:
            go = ready_then_wait_for_go(pipe)
        except OSError as e:
            raise ComponentExit(EXIT_FAILED, f"handshake: {_describe(e)}") from None
        if go:
            stepper.run()
    except ComponentExit as e:
        code, message = e.code, e.message
    except KeyboardInterrupt:
        code, message = EXIT_FAILED, "interrupted"
    if message is not None:
        sys.stderr.write(f"{name}: {message}\n")
        sys.stderr.flush()
    if bus is not None:
        bus.close()
    sys.exit(code)
