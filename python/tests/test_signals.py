"""The signal generators against hand values (lti::signal's rules)."""

import math

import pytest

from uio_component.signals import Signal, Signals, in_effect


def test_constant():
    s = Signal({"kind": "constant", "value": -2.5})
    assert s.at_step(0, 0.001) == -2.5
    assert s.at_step(123456, 0.001) == -2.5


def test_step_switches_on_its_sample_as_the_decimals_written():
    s = Signal({"kind": "step", "time": 5.0, "before": 1.0, "after": 3.0})
    assert s.at_step(4999, 0.001) == 1.0
    assert s.at_step(5000, 0.001) == 3.0
    # 0.07 / 0.01 = 7.000000000000001 in binary; as decimals 0.07 is sample 7.
    assert 0.07 / 0.01 > 7
    s = Signal({"kind": "step", "time": 0.07, "after": 1.0})
    assert (s.at_step(6, 0.01), s.at_step(7, 0.01)) == (0.0, 1.0)
    # 3 × 0.7 = 2.0999999999999996 < 2.1 in binary; as decimals 2.1 is sample 3.
    assert 3 * 0.7 < 2.1
    s = Signal({"kind": "piecewise", "times": [2.1], "values": [1.0]})
    assert (s.at_step(2, 0.7), s.at_step(3, 0.7)) == (0.0, 1.0)


def test_a_switch_inside_a_step_shows_from_the_next_sample():
    s = Signal({"kind": "step", "time": 5.0000000000001, "before": 0.0, "after": 1.0})
    assert s.at_step(5000, 0.001) == 0.0
    assert s.at_step(5001, 0.001) == 1.0


def test_step_before_defaults_to_zero_and_times_at_or_before_zero_are_in_effect():
    assert Signal({"kind": "step", "time": 1.0, "after": 2.0}).at_step(0, 0.01) == 0.0
    assert Signal({"kind": "step", "time": 0.0, "before": 7.0, "after": 2.0}).at_step(0, 0.01) == 2.0
    assert in_effect(-1.0, 0, 0.001)


def test_sine():
    s = Signal({"kind": "sine", "amplitude": 2.0, "frequency_hz": 0.5, "phase": 0.25, "offset": 1.0})
    assert s.at_step(0, 0.001) == pytest.approx(2.0 * math.sin(0.25) + 1.0, abs=0)
    # t = 0.5 s: 2·sin(π/2 + 0.25) + 1
    assert s.at_step(500, 0.001) == 2.0 * math.sin(2.0 * math.pi * 0.5 * (500 * 0.001) + 0.25) + 1.0
    assert s.at_step(500, 0.001) == pytest.approx(2.0 * math.cos(0.25) + 1.0, rel=1e-15)
    # phase and offset default to 0
    s = Signal({"kind": "sine", "amplitude": 1.0, "frequency_hz": 1.0})
    assert s.at_step(250, 0.001) == pytest.approx(1.0, rel=1e-15)
    assert s.at_step(0, 0.001) == 0.0


def test_piecewise_holds_each_value_from_its_time_on():
    s = Signal({"kind": "piecewise", "times": [0.0, 5.0, 10.0, 15.0], "values": [0.0, 1.0, -0.5, 2.0]})
    dt = 0.001
    assert [s.at_step(k, dt) for k in (0, 4999, 5000, 9999, 10000, 14999, 15000, 20000)] == \
        [0.0, 0.0, 1.0, 1.0, -0.5, -0.5, 2.0, 2.0]
    late = Signal({"kind": "piecewise", "times": [1.0], "values": [4.0]})
    assert late.at_step(999, dt) == 0.0  # 0 before the first time
    assert late.at_step(1000, dt) == 4.0


def test_value_at_any_time():
    s = Signal({"kind": "piecewise", "times": [1.0, 2.0], "values": [3.0, 4.0]})
    assert (s.value(0.5), s.value(1.0), s.value(1.5), s.value(2.5)) == (0.0, 3.0, 3.0, 4.0)


def test_bad_signals_are_refused():
    with pytest.raises(ValueError):
        Signal({"kind": "ramp"})
    with pytest.raises(ValueError):
        Signal({"kind": "piecewise", "times": [1.0, 1.0], "values": [1.0, 2.0]})
    with pytest.raises(KeyError):
        Signal({"kind": "constant"})


def test_signals_of_a_configuration():
    sig = Signals({"disturbances": [{"kind": "constant", "value": 1.5}],
                   "measurement_disturbances": [],
                   "inputs": [{"kind": "step", "time": 1.0, "after": 0.5}, {"kind": "constant", "value": -1.0}]}, 0.01)
    assert sig.w(0).tolist() == [1.5]
    assert sig.v(3).shape == (0,)
    assert sig.r(99).tolist() == [0.0, -1.0]
    assert sig.r(100).tolist() == [0.5, -1.0]
