"""The kit's wire layer on iceoryx2 alone: a publisher and a subscriber made by the kit's own
service-opening code, in a private prefix and root, samples round-tripped with their header."""

import ctypes

import numpy as np
import pytest

from conftest import shm_files

from uio_component import PROTOCOL_VERSION
from uio_component.wire import Bus, Header, ProtocolError, Waiter, now_ns


def test_one_sample_round_trips_with_its_header(run_space):
    sender = Bus(run_space["prefix"], run_space["root"], "sender")
    receiver = Bus(run_space["prefix"], run_space["root"], "receiver")
    outlet = sender.outlet("observer/mine", 5)
    inlet = receiver.inlet("observer/mine", 5)
    assert shm_files(run_space["prefix"]), "the run's shared memory carries the prefix"
    values = np.array([1.0, -2.5, 3.25, 1e-300, -0.0])
    before = now_ns()
    sent_ns = outlet.send(7, 0.007, 123456789, values)
    out = np.full(5, np.nan)
    got = inlet.try_take(7, out)
    assert got is not None
    assert (got.step, got.sim_time, got.taken_ns) == (7, 0.007, 123456789)
    assert got.sent_ns == sent_ns and before <= sent_ns <= got.received_ns
    assert out.tobytes() == values.tobytes()  # bit for bit, −0.0 included
    assert inlet.try_take(8, out) is None  # nothing more
    sender.close()
    receiver.close()
    del outlet, inlet, sender, receiver
    # Closed ports and nodes leave only iceoryx2's node counter (the launcher removes it).
    assert [f for f in shm_files(run_space["prefix"]) if not f.endswith(".global_mgmt")] == []


def test_the_header_as_it_lies_in_shared_memory(run_space):
    """The subscriber sees the 40 bytes of §4 (read through iceoryx2's own API)."""
    sender = Bus(run_space["prefix"], run_space["root"], "sender")
    receiver = Bus(run_space["prefix"], run_space["root"], "receiver")
    outlet = sender.outlet("plant", 3)
    inlet = receiver.inlet("plant", 3)
    outlet.send(2**40 + 3, 1.5, 42, np.array([4.0, 5.0, 6.0]))
    sample = inlet.subscriber.receive()
    raw = ctypes.string_at(sample.user_header_ptr, 40)
    assert int.from_bytes(raw[0:8], "little") == 2**40 + 3
    assert np.frombuffer(raw[8:16], "<f8")[0] == 1.5
    assert int.from_bytes(raw[24:32], "little") == 42
    assert int.from_bytes(raw[32:36], "little") == PROTOCOL_VERSION
    assert int.from_bytes(raw[36:40], "little") == 0
    assert sample.header.number_of_elements == 3
    assert np.frombuffer(ctypes.string_at(sample.payload_ptr, 24), "<f8").tolist() == [4.0, 5.0, 6.0]
    del sample
    sender.close()
    receiver.close()


def test_wrong_step_and_length_are_refused(run_space):
    sender = Bus(run_space["prefix"], run_space["root"], "sender")
    receiver = Bus(run_space["prefix"], run_space["root"], "receiver")
    outlet = sender.outlet("controller", 2)
    right = receiver.inlet("controller", 2)
    wrong_len = receiver.inlet("controller", 3)
    outlet.send(1, 0.001, 0, np.array([1.0, 2.0]))
    with pytest.raises(ProtocolError, match=r"'controller': sample of step 1, expected step 0"):
        right.try_take(0, np.zeros(2))
    with pytest.raises(ProtocolError, match=r"'controller': sample of step 1 holds 2 values, expected 3"):
        wrong_len.try_take(1, np.zeros(3))
    with pytest.raises(ValueError):
        outlet.send(2, 0.002, 0, np.zeros(3))  # the publisher's own length is fixed
    sender.close()
    receiver.close()


def test_a_wait_times_out(run_space):
    receiver = Bus(run_space["prefix"], run_space["root"], "receiver")
    inlet = receiver.inlet("plant", 1)
    start = now_ns()
    with pytest.raises(ProtocolError, match=r"no sample on 'plant' for 0.05 s \(step 0\)"):
        inlet.take(0, np.zeros(1), 0.05)
    assert now_ns() - start >= 50_000_000
    receiver.close()


@pytest.mark.parametrize("wait", ["block", "waitset", "spin-then-block:20"])
def test_events_wake_a_blocked_reader(run_space, wait):
    sender = Bus(run_space["prefix"], run_space["root"], "sender", wait)
    receiver = Bus(run_space["prefix"], run_space["root"], "receiver", wait)
    outlet = sender.outlet("observer/uio", 2)
    inlet = receiver.inlet("observer/uio", 2)
    assert outlet.notifier is not None and inlet.waiter.listener is not None
    out = np.zeros(2)
    for k in range(3):
        outlet.send(k, k * 0.001, 0, np.array([k, -k], dtype=float))
        assert inlet.take(k, out, 1.0).step == k
        assert out.tolist() == [k, -k]
    sender.close()
    receiver.close()


def test_polling_strategies_make_no_events(run_space):
    bus = Bus(run_space["prefix"], run_space["root"], "poller", "yield")
    outlet = bus.outlet("plant", 1)
    assert outlet.notifier is None
    bus.close()
    with pytest.raises(ValueError):
        Waiter("busy")
    assert Waiter("sleep:200").sleep_s == pytest.approx(200e-6)


def test_the_header_structure():
    assert ctypes.sizeof(Header) == 40 and ctypes.alignment(Header) == 8
    assert Header.type_name() == "uio_observers::Header"
