"""The scenario's signals, for plants that generate their own disturbances and inputs.

A signal is the scenario's JSON form (docs/scenario-format.md):

- `{"kind": "constant", "value": v}`
- `{"kind": "step", "time": T, "before": b, "after": a}` (`before` defaults to 0)
- `{"kind": "sine", "amplitude": a, "frequency_hz": f, "phase": φ, "offset": c}` (φ, c default
  to 0): a·sin(2π·f·t + φ) + c
- `{"kind": "piecewise", "times": [...], "values": [...]}`: each value holds from its time on,
  0 before the first

The value at sample k is the one the built-in plant publishes (`lti::signal`): the sine at
t_k = k·dt, and a switch at time T is in effect from sample k on when T ≤ k·dt **comparing the
decimals written** (the shortest round-trip decimal of each double, as Python's `repr`), so
`time = 5.0` with `dt = 0.001` switches at sample 5000 although 5000 × 0.001 is not 5.0 in
binary.
"""

from __future__ import annotations

import math
from decimal import Context, Decimal
from typing import Any, Dict, Sequence

import numpy as np


#: Enough digits for k·dt exactly (k < 2⁶⁴, dt of ≤ 17 digits).
_EXACT = Context(prec=60)


def _decimal(x: float) -> Decimal:
    """The decimal written: the shortest decimal that reads back as x."""
    return Decimal(repr(float(x)))


def in_effect(time: float, k: int, dt: float) -> bool:
    """Whether a switch at `time` is in effect at sample k: time ≤ k·dt as decimals, exactly."""
    if math.isnan(time) or time <= 0.0:
        return True
    q = time / dt
    tol = 1e-12 * max(q, 1.0)
    if q < k - tol:
        return True
    if q > k + tol:
        return False
    return _decimal(time) <= _EXACT.multiply(Decimal(k), _decimal(dt))


class Signal:
    """One scalar signal of time."""

    def __init__(self, spec: Dict[str, Any]) -> None:
        kind = spec.get("kind")
        self.kind = kind
        self.spec = dict(spec)
        if kind == "constant":
            self.value_ = float(spec["value"])
        elif kind == "step":
            self.time = float(spec["time"])
            self.before = float(spec.get("before", 0.0))
            self.after = float(spec["after"])
        elif kind == "sine":
            self.amplitude = float(spec["amplitude"])
            self.frequency_hz = float(spec["frequency_hz"])
            self.phase = float(spec.get("phase", 0.0))
            self.offset = float(spec.get("offset", 0.0))
            if self.frequency_hz < 0:
                raise ValueError("sine: frequency_hz must be ≥ 0")
        elif kind == "piecewise":
            self.times = [float(t) for t in spec["times"]]
            self.values = [float(v) for v in spec["values"]]
            if not self.times or len(self.times) != len(self.values):
                raise ValueError("piecewise: times and values must be non-empty and of equal length")
            if any(b <= a for a, b in zip(self.times, self.times[1:])):
                raise ValueError("piecewise: times must be strictly increasing")
        else:
            raise ValueError(f"signal kind {kind!r} is not constant, step, sine or piecewise")

    def _sine(self, t: float) -> float:
        # As lti::signal: ω = 2π·f first, then a·sin(ω·t + φ).
        if self.kind != "sine" or self.amplitude == 0.0:
            return 0.0
        w = 2.0 * math.pi * self.frequency_hz
        return self.amplitude * math.sin(w * t + self.phase)

    def held_at_step(self, k: int, dt: float) -> float:
        """The piecewise-constant part at sample k."""
        if self.kind == "constant":
            return self.value_
        if self.kind == "sine":
            return self.offset
        if self.kind == "step":
            return self.after if in_effect(self.time, k, dt) else self.before
        for i in range(len(self.times) - 1, -1, -1):
            if in_effect(self.times[i], k, dt):
                return self.values[i]
        return 0.0

    def at_step(self, k: int, dt: float) -> float:
        """The value at sample k (t_k = k·dt)."""
        return self._sine(k * dt) + self.held_at_step(k, dt)

    def value(self, t: float) -> float:
        """s(t) at any time, switching times compared as binary numbers (for plots)."""
        if self.kind == "constant":
            held = self.value_
        elif self.kind == "sine":
            held = self.offset
        elif self.kind == "step":
            held = self.before if t < self.time else self.after
        else:
            held = 0.0
            for ti, vi in zip(self.times, self.values):
                if ti <= t:
                    held = vi
        return self._sine(t) + held


class Signals:
    """The `signals` of a plant's configuration: disturbances w, measurement disturbances v and
    known inputs r, each sampled as a vector."""

    def __init__(self, spec: Dict[str, Any], dt: float) -> None:
        spec = spec or {}
        self.dt = dt
        self.disturbances = [Signal(s) for s in spec.get("disturbances", [])]
        self.measurement_disturbances = [Signal(s) for s in spec.get("measurement_disturbances", [])]
        self.inputs = [Signal(s) for s in spec.get("inputs", [])]

    @staticmethod
    def _vector(signals: Sequence[Signal], k: int, dt: float) -> np.ndarray:
        return np.array([s.at_step(k, dt) for s in signals], dtype=np.float64)

    def w(self, k: int) -> np.ndarray:
        """Unknown inputs w(t_k)."""
        return self._vector(self.disturbances, k, self.dt)

    def v(self, k: int) -> np.ndarray:
        """Measurement disturbances v(t_k)."""
        return self._vector(self.measurement_disturbances, k, self.dt)

    def r(self, k: int) -> np.ndarray:
        """Known inputs / references r(t_k)."""
        return self._vector(self.inputs, k, self.dt)

