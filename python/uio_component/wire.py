"""The wire format and the ports, on iceoryx2's own Python binding (PROTOCOL.md §2 and §4).

Every service is publish–subscribe with a slice of f64 as payload (`iox2.Slice[ctypes.c_double]`,
iceoryx2 type name `f64`, dynamic size) behind the user header `Header`
(`uio_observers::Header`, 40 bytes). `Bus` joins a run's iceoryx2 world and opens services
with exactly the settings of §4; an `Outlet` publishes one sample per step, an `Inlet` takes
the sample of an expected step and checks it.

The binding's `Slice.len()` on a sample counts bytes, not elements (iceoryx2 0.10.0), so the
element count is read from the sample's iceoryx2 header (`number_of_elements`) and the values
are copied with `ctypes.memmove` from `payload_ptr`.
"""

from __future__ import annotations

import ctypes
import os
import time
from typing import List, NamedTuple, Optional

import numpy as np
import iceoryx2 as iox2

from .config import PROTOCOL_VERSION

#: Service settings of PROTOCOL.md §4.
MAX_PUBLISHERS = 1
MAX_SUBSCRIBERS = 8
MAX_NODES = 16
HISTORY_SIZE = 0
SUBSCRIBER_MAX_BUFFER_SIZE = 4098
#: The buffer of a lockstep subscriber.
SUBSCRIBER_BUFFER_SIZE = 4098
#: Loaned samples a publisher may hold.
MAX_LOANED_SAMPLES = 1
#: Event services `<service>/wake`.
EVENT_MAX_NOTIFIERS = 1
EVENT_MAX_LISTENERS = 8
EVENT_MAX_NODES = 16

#: Wait strategies whose publishers notify `<service>/wake` after each sample.
EVENT_WAITS = ("block", "waitset", "spin-then-block")


class Header(ctypes.Structure):
    """The user header of every sample (PROTOCOL.md §4): `#[repr(C)]`, 40 bytes, align 8."""

    _fields_ = [
        ("step", ctypes.c_uint64),
        ("sim_time", ctypes.c_double),
        ("sent_ns", ctypes.c_uint64),
        ("taken_ns", ctypes.c_uint64),
        ("protocol", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name, shared with the Rust side."""
        return "uio_observers::Header"


#: The payload type: a slice of f64.
Payload = iox2.Slice[ctypes.c_double]


class ProtocolError(Exception):
    """A sample broke the protocol, or none came in time (the component exits with 3)."""


class Received(NamedTuple):
    """The header of a taken sample, plus when this process took it."""

    step: int
    sim_time: float
    sent_ns: int
    taken_ns: int
    received_ns: int


def now_ns() -> int:
    """CLOCK_MONOTONIC in ns, the clock of the Rust side (`time.monotonic_ns` on Linux)."""
    return time.monotonic_ns()


def needs_events(wait: str) -> bool:
    """Whether the run's wait strategy (`block`, `waitset`, `spin-then-block[:µs]`) makes
    publishers notify `<service>/wake` after each sample."""
    return wait.split(":", 1)[0] in EVENT_WAITS


def iceoryx2_config(prefix: str, root: str) -> "iox2.config.Config":
    """iceoryx2's defaults (no config file) with `global.prefix` and `global.root_path` set
    (PROTOCOL.md §2)."""
    config = iox2.config.default()
    config.global_cfg.prefix = iox2.FileName.new(prefix)
    config.global_cfg.root_path = iox2.Path.new(root)
    return config


def quiet_iceoryx2() -> None:
    """Shows only iceoryx2's errors, unless `IOX2_LOG_LEVEL` says otherwise: a component's last
    line of stderr is what the launcher quotes when it fails."""
    iox2.set_log_level_from_env_or(iox2.LogLevel.Error)


class Waiter:
    """How an inlet waits between polls (PROTOCOL.md §4, the run's `wait`).

    With events (`block`, `waitset`, `spin-then-block[:µs]`) it blocks on the `<service>/wake`
    listener in slices of at most 100 ms (after yielding for the spin time); a WaitSet over a
    single listener would do the same. Otherwise it polls: `sched_yield` for the first
    millisecond of a wait, then sleeps 50 µs between polls, so a long wait does not hold a core
    (`sleep:µs` sleeps that long from the start).
    """

    YIELD_NS = 1_000_000
    SLEEP_S = 50e-6

    def __init__(self, wait: str, listener: Optional["iox2.Listener"] = None, sleep_us: Optional[int] = None) -> None:
        kind, _, arg = wait.partition(":")
        self.listener = listener
        self.spin_ns = 0
        self.sleep_s: Optional[float] = None
        if sleep_us is not None:
            self.listener, self.sleep_s = None, sleep_us * 1e-6
        elif kind == "sleep":
            self.sleep_s = (int(arg) if arg else 100) * 1e-6
        elif kind == "spin-then-block":
            self.spin_ns = (int(arg) if arg else 50) * 1000
        elif kind in ("block", "waitset"):
            self.spin_ns = 0
        elif kind in ("yield", "spin-then-yield"):
            self.listener = None
        else:
            raise ValueError(f"'{wait}' is not a wait strategy (yield, block, waitset, "
                             "spin-then-block[:µs], spin-then-yield:ns, sleep:µs)")

    def pause(self, waited_ns: int, remaining_ns: int) -> None:
        """One pause between two polls, `waited_ns` into a wait that has `remaining_ns` left."""
        if self.listener is not None and waited_ns >= self.spin_ns:
            slice_ns = max(1, min(remaining_ns, 100_000_000))
            self.listener.timed_wait(iox2.Duration.from_nanos(slice_ns))
        elif self.sleep_s is not None:
            time.sleep(self.sleep_s)
        elif waited_ns < self.YIELD_NS or self.listener is not None:
            os.sched_yield()
        else:
            time.sleep(self.SLEEP_S)


class Outlet:
    """Publishes one sample of `length` values per step (and notifies `<service>/wake` when the
    run's wait strategy needs events)."""

    def __init__(self, service: str, length: int, publisher: "iox2.Publisher", notifier: Optional["iox2.Notifier"]) -> None:
        self.service = service
        self.len = length
        self.publisher = publisher
        self.notifier = notifier
        self._nbytes = 8 * length

    def send(self, step: int, sim_time: float, taken_ns: int, values: np.ndarray) -> int:
        """Loans a sample, writes header and values in place, sends it; returns the send time.
        `values` must be a C-contiguous float64 array of `len` values."""
        if values.shape != (self.len,) or values.dtype != np.float64 or not values.flags.c_contiguous:
            raise ValueError(f"{self.service}: {values.size} values, the service takes {self.len} float64")
        sample = self.publisher.loan_slice_uninit(self.len)
        header = Header.from_address(sample.user_header_ptr)
        sent_ns = now_ns()
        header.step = step
        header.sim_time = sim_time
        header.sent_ns = sent_ns
        header.taken_ns = taken_ns
        header.protocol = PROTOCOL_VERSION
        header.reserved = 0
        ctypes.memmove(sample.payload_ptr, values.ctypes.data, self._nbytes)
        sample.assume_init().send()
        if self.notifier is not None:
            self.notifier.notify()
        return sent_ns


class Inlet:
    """Takes the samples of one service in step order, checking step, length and protocol."""

    def __init__(self, service: str, length: int, subscriber: "iox2.Subscriber", waiter: Waiter) -> None:
        self.service = service
        self.len = length
        self.subscriber = subscriber
        self.waiter = waiter
        self._nbytes = 8 * length

    def try_take(self, step: int, out: np.ndarray) -> Optional[Received]:
        """Takes a pending sample, if any: it must be of `step`, hold `len` values and speak this
        protocol (else ProtocolError); its values are copied into `out`."""
        sample = self.subscriber.receive()
        if sample is None:
            return None
        received_ns = now_ns()
        h = Header.from_address(sample.user_header_ptr)
        got = Received(h.step, h.sim_time, h.sent_ns, h.taken_ns, received_ns)
        protocol = h.protocol
        count = sample.header.number_of_elements
        if protocol != PROTOCOL_VERSION:
            raise ProtocolError(f"'{self.service}': sample of protocol version {protocol}, this component speaks {PROTOCOL_VERSION}")
        if got.step != step:
            raise ProtocolError(f"'{self.service}': sample of step {got.step}, expected step {step}")
        if count != self.len:
            raise ProtocolError(f"'{self.service}': sample of step {step} holds {count} values, expected {self.len}")
        ctypes.memmove(out.ctypes.data, sample.payload_ptr, self._nbytes)
        del h, sample  # releases the sample to the publisher
        return got

    def take(self, step: int, out: np.ndarray, timeout_s: float) -> Received:
        """Waits up to `timeout_s` for the sample of `step` (see `try_take`)."""
        start = now_ns()
        limit = int(timeout_s * 1e9)
        while True:
            got = self.try_take(step, out)
            if got is not None:
                return got
            waited = now_ns() - start
            if waited > limit:
                raise ProtocolError(f"no sample on '{self.service}' for {timeout_s:g} s (step {step}): is the peer still running?")
            self.waiter.pause(waited, limit - waited)


class Bus:
    """A process's node in a run's iceoryx2 world and the ports it made.

    `Bus(prefix, root, name, wait)` joins the run whose iceoryx2 configuration is `prefix`/`root`
    (PROTOCOL.md §2) as node `name`; `wait` is the run's wait strategy (§4).
    """

    def __init__(self, prefix: str, root: str, name: str, wait: str = "yield") -> None:
        quiet_iceoryx2()
        Waiter(wait)  # refuses an unknown strategy before anything is made
        self.wait = wait
        self.events = needs_events(wait)
        self.node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(name))
            .config(iceoryx2_config(prefix, root))
            .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
            .create(iox2.ServiceType.Ipc)
        )
        self._ports: List[object] = []
        self._services: List[object] = []

    def publish_subscribe(self, service: str) -> "iox2.PortFactoryPublishSubscribe":
        """Opens (or creates) `service` with the settings of PROTOCOL.md §4."""
        factory = (
            self.node.service_builder(iox2.ServiceName.new(service))
            .publish_subscribe(Payload)
            .user_header(Header)
            .max_publishers(MAX_PUBLISHERS)
            .max_subscribers(MAX_SUBSCRIBERS)
            .max_nodes(MAX_NODES)
            .history_size(HISTORY_SIZE)
            .subscriber_max_buffer_size(SUBSCRIBER_MAX_BUFFER_SIZE)
            .enable_safe_overflow(False)
            .open_or_create()
        )
        self._services.append(factory)
        return factory

    def event(self, service: str) -> "iox2.PortFactoryEvent":
        """Opens (or creates) `<service>/wake` with the settings of PROTOCOL.md §4."""
        factory = (
            self.node.service_builder(iox2.ServiceName.new(f"{service}/wake"))
            .event()
            .max_notifiers(EVENT_MAX_NOTIFIERS)
            .max_listeners(EVENT_MAX_LISTENERS)
            .max_nodes(EVENT_MAX_NODES)
            .open_or_create()
        )
        self._services.append(factory)
        return factory

    def outlet(self, service: str, length: int) -> Outlet:
        """The publishing end of `service`, `length` values per sample."""
        publisher = (
            self.publish_subscribe(service)
            .publisher_builder()
            .initial_max_slice_len(length)
            .backpressure_strategy(iox2.BackpressureStrategy.RetryUntilDelivered)
            .max_loaned_samples(MAX_LOANED_SAMPLES)
            .create()
        )
        self._ports.append(publisher)
        notifier = None
        if self.events:
            notifier = self.event(service).notifier_builder().create()
            self._ports.append(notifier)
        return Outlet(service, length, publisher, notifier)

    def inlet(self, service: str, length: int, sleep_us: Optional[int] = None) -> Inlet:
        """A lockstep reading end of `service`, `length` values per sample."""
        subscriber = self.publish_subscribe(service).subscriber_builder().buffer_size(SUBSCRIBER_BUFFER_SIZE).create()
        self._ports.append(subscriber)
        listener = None
        if self.events:
            listener = self.event(service).listener_builder().create()
            self._ports.append(listener)
        return Inlet(service, length, subscriber, Waiter(self.wait, listener, sleep_us))

    def close(self) -> None:
        """Releases every port, then the services and the node."""
        for port in reversed(self._ports):
            try:
                port.delete()
            except Exception:  # noqa: BLE001 — best effort at the end of a run
                pass
        self._ports.clear()
        self._services.clear()
        self.node = None
