"""`run()` as a launched process, with this test as the launcher: the start checks of §1, the
handshake and the step order of §5 for an observer and for the plant (trailing input, end
sample), and the exit codes of every failure."""

import json
import os
import select
import subprocess
import sys
import time

import numpy as np
import pytest

from conftest import COMPONENTS, PYTHON_DIR, TEST_COMPONENTS

import cartpole
from uio_component.wire import Bus

DT = 0.001


def base_config(space, name, role, publishes, reads, steps, wait="yield", **extra):
    return {
        "protocol": 1, "run": space["run"], "name": name, "role": role,
        "iceoryx2": {"prefix": space["prefix"], "root": space["root"]},
        "wait": wait, "dt": DT, "steps": steps, "publishes": publishes, "reads": reads,
        "model": {}, "params": {}, **extra,
    }


class Launched:
    """A component started the way the launcher starts it (PROTOCOL.md §1)."""

    def __init__(self, space, config, script, env=None):
        path = os.path.join(space["dir"], f"{config['name']}.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(config, f)
        os.chmod(path, 0o600)
        e = dict(os.environ, UIO_PROTOCOL="1", UIO_RUN=space["run"], UIO_NAME=config["name"],
                 UIO_ROLE=config["role"], UIO_CONFIG=path, UIO_RUNS_DIR=space["runs_dir"])
        e["PYTHONPATH"] = PYTHON_DIR + os.pathsep + e.get("PYTHONPATH", "")
        e.update(env or {})
        self.proc = subprocess.Popen([sys.executable, script], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, env=e, cwd=os.path.dirname(script))

    def ready(self, timeout=20.0):
        r, _, _ = select.select([self.proc.stdout], [], [], timeout)
        assert r, "no ready"
        return self.proc.stdout.readline()

    def go(self, line=b"go\n"):
        self.proc.stdin.write(line)
        self.proc.stdin.flush()

    def finish(self, timeout=20.0):
        try:
            code = self.proc.wait(timeout)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
        return code, self.proc.stdout.read(), self.proc.stderr.read().decode()


def plant_sample(k):
    """10 values: the layout of a 4-state, 3-output, 1-w, 0-v, 1-input plant."""
    return np.arange(10, dtype=float) + 0.5 * k


@pytest.mark.parametrize("wait", ["yield", "block"])
def test_an_observer_reads_step_k_and_publishes_step_k(run_space, wait):
    K = 50
    bus = Bus(run_space["prefix"], run_space["root"], "launcher", wait)
    plant = bus.outlet("plant", 10)
    echo = bus.inlet("observer/echo", 4)
    cfg = base_config(run_space, "echo", "observer", {"service": "observer/echo", "len": 4},
                      [{"service": "plant", "len": 10, "lag": 0, "fields": {"x": [0, 4], "y": [4, 7]}}], K, wait,
                      params={"gain": 2.0, "print": True})
    c = Launched(run_space, cfg, os.path.join(TEST_COMPONENTS, "echo.py"))
    assert c.ready() == b"ready\n"
    c.go()
    out = np.zeros(4)
    for k in range(K):
        sent = plant.send(k, k * DT, 0, plant_sample(k))
        h = echo.take(k, out, 10.0)
        assert out.tolist() == (2.0 * plant_sample(k)[:4]).tolist()
        assert h.sim_time == k * DT and h.step == k
        assert sent <= h.taken_ns <= h.sent_ns <= h.received_ns
    code, stdout, stderr = c.finish()
    assert code == 0, stderr
    assert stdout == b""  # prints went to stderr, not into the launcher's pipe
    assert "step 49" in stderr
    bus.close()


def test_the_plant_publishes_k_from_step_k_minus_1_and_ends_with_step_K(run_space):
    K, LAG = 20, 3
    bus = Bus(run_space["prefix"], run_space["root"], "launcher")
    controller = bus.outlet("controller", 1)
    slow = bus.outlet("observer/slow", 4)
    plant = bus.inlet("plant", 10)
    model = {"A": cartpole.linearisation(1.0, 0.1, 0.5, 9.81)[0].tolist(), "B": [[0.0], [1.0], [0.0], [-2.0]],
             "C": [[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]], "D": [], "E": [[0.0], [1.0], [0.0], [-2.0]],
             "x0": [0.0, 0.0, 0.1, 0.0]}
    signals = {"disturbances": [{"kind": "step", "time": 0.005, "after": 1.0}], "measurement_disturbances": [],
               "inputs": [{"kind": "constant", "value": 0.0}]}
    cfg = base_config(run_space, "plant", "plant", {"service": "plant", "len": 10},
                      [{"service": "observer/slow", "len": 4, "lag": LAG}, {"service": "controller", "len": 1, "lag": 0}],
                      K, model=model, signals=signals,
                      params={"cart_mass": 1.0, "pole_mass": 0.1, "length": 0.5, "gravity": 9.81})
    c = Launched(run_space, cfg, os.path.join(COMPONENTS, "cartpole.py"))
    assert c.ready() == b"ready\n"
    c.go()
    out = np.zeros(10)
    x = (0.0, 0.0, 0.1, 0.0)
    sent_slow = 0
    for k in range(K):
        h = plant.take(k, out, 10.0)
        assert h.step == k and h.sim_time == k * DT
        assert (h.taken_ns == 0) == (k == 0)
        np.testing.assert_array_equal(out[:4], x)
        u = -0.5 * k
        controller.send(k, k * DT, 0, np.array([u]))
        w = 1.0 if k >= 5 else 0.0
        x = cartpole.rk4(x, u + w, DT / 4, 4, 1.0, 0.1, 0.5, 9.81)
        if k % 4 == 3 and k < K - 1:  # the slow observer delivers in batches, trailing up to LAG
            while sent_slow <= k:
                slow.send(sent_slow, sent_slow * DT, 0, np.zeros(4))
                sent_slow += 1
    # The end sample waits for every input, the trailing one included, to deliver step K − 1.
    time.sleep(0.2)
    assert plant.try_take(K, out) is None
    while sent_slow < K:
        slow.send(sent_slow, sent_slow * DT, 0, np.zeros(4))
        sent_slow += 1
    h = plant.take(K, out, 10.0)
    assert h.step == K and h.sim_time == K * DT
    np.testing.assert_array_equal(out[:4], x)
    assert out[9] == -0.5 * (K - 1)  # u_{K−1}
    code, _, stderr = c.finish()
    assert code == 0, stderr
    bus.close()


def start_echo(space, K=10, params=None, env=None, reads_len=10, **cfg_extra):
    cfg = base_config(space, "echo", "observer", {"service": "observer/echo", "len": 4},
                      [{"service": "plant", "len": reads_len, "lag": 0}], K, params=params or {}, **cfg_extra)
    return Launched(space, cfg, os.path.join(TEST_COMPONENTS, "echo.py"), env)


def last_line(stderr):
    return stderr.strip().splitlines()[-1]


def drive(space, c, steps, length=10, first=0):
    """Ready, go, then plant samples first, first + 1, … of `length` values."""
    bus = Bus(space["prefix"], space["root"], "launcher")
    plant = bus.outlet("plant", length)
    echo = bus.inlet("observer/echo", 4)
    assert c.ready() == b"ready\n"
    c.go()
    out = np.zeros(4)
    for k in range(first, first + steps):
        plant.send(k, k * DT, 0, np.zeros(length))
        deadline = time.monotonic() + 10.0
        while echo.try_take(k - first, out) is None and c.proc.poll() is None and time.monotonic() < deadline:
            time.sleep(1e-4)
        if c.proc.poll() is not None:
            break
    result = c.finish()
    bus.close()
    return result


def test_a_sample_of_the_wrong_step_exits_3_naming_service_and_step(run_space):
    code, _, stderr = drive(run_space, start_echo(run_space), 3, first=1)
    assert code == 3
    assert last_line(stderr) == "echo: step 0: 'plant': sample of step 1, expected step 0"


def test_a_sample_of_the_wrong_length_exits_3(run_space):
    code, _, stderr = drive(run_space, start_echo(run_space), 3, length=11)
    assert code == 3
    assert last_line(stderr) == "echo: step 0: 'plant': sample of step 0 holds 11 values, expected 10"


def test_an_exception_in_the_step_exits_3_naming_the_step(run_space):
    code, _, stderr = drive(run_space, start_echo(run_space, params={"raise_at": 3}), 10)
    assert code == 3
    assert last_line(stderr) == "echo: step 3: ZeroDivisionError: division by zero"


def test_a_step_returning_the_wrong_count_exits_3(run_space):
    code, _, stderr = drive(run_space, start_echo(run_space, params={"bad_len_at": 2}), 10)
    assert code == 3
    assert last_line(stderr) == "echo: step 2: the step returned 5 values, 'observer/echo' takes 4"


def test_diverged_exits_4(run_space):
    code, _, stderr = drive(run_space, start_echo(run_space, params={"diverge_at": 1}), 10)
    assert code == 4
    assert last_line(stderr) == "echo: step 1: diverged: x1 = inf"


def test_a_failing_setup_exits_3_before_ready(run_space):
    c = start_echo(run_space, params={"fail_setup": True})
    code, stdout, stderr = c.finish()
    assert (code, stdout) == (3, b"")
    assert last_line(stderr) == "echo: setup: RuntimeError: no such gain"


def test_anything_but_go_exits_0(run_space):
    for line in (b"stop\n", b""):
        c = start_echo(run_space)
        assert c.ready() == b"ready\n"
        if line:
            c.go(line)
        c.proc.stdin.close()
        code, _, stderr = c.finish()
        assert code == 0, stderr


def test_another_protocol_version_exits_2(run_space):
    code, stdout, stderr = start_echo(run_space, env={"UIO_PROTOCOL": "2"}).finish()
    assert (code, stdout) == (2, b"")
    assert stderr.strip() == "echo: the run speaks protocol version 2, this component 1"


def test_a_parent_that_is_not_the_launcher_exits_2(run_space):
    with open(os.path.join(run_space["dir"], "owner.pid"), "w") as f:
        f.write("1\n")
    code, _, stderr = start_echo(run_space).finish()
    assert code == 2
    assert "is not the launcher of run" in stderr and len(stderr.strip().splitlines()) == 1


def test_a_fifo_or_symlink_as_owner_pid_is_refused_without_blocking(run_space):
    # A planted FIFO made readers hang in open(); a symlink could point anywhere.
    owner = os.path.join(run_space["dir"], "owner.pid")
    elsewhere = os.path.join(run_space["dir"], "elsewhere")
    with open(elsewhere, "w") as f:
        f.write(f"{os.getpid()}\n")
    for plant in (lambda: os.mkfifo(owner), lambda: os.symlink(elsewhere, owner)):
        os.remove(owner)
        plant()
        t0 = time.monotonic()
        code, _, stderr = start_echo(run_space).finish()
        assert time.monotonic() - t0 < 10
        assert code == 2 and "owner.pid is missing or not a regular file" in stderr, stderr
    # A symlink standing in for the run directory is refused too.
    os.remove(owner)
    with open(owner, "w") as f:
        f.write(f"{os.getpid()}\n")
    real, link = run_space["dir"], run_space["dir"] + "-link"
    os.rename(real, link + "-real")
    os.symlink(link + "-real", real)
    try:
        code, _, stderr = start_echo(run_space).finish()
        assert code == 2 and "owner.pid is missing or not a regular file" in stderr, stderr
    finally:
        os.remove(real)
        os.rename(link + "-real", real)


def test_a_configuration_of_another_version_exits_2(run_space):
    cfg = base_config(run_space, "echo", "observer", {"service": "observer/echo", "len": 4},
                      [{"service": "plant", "len": 10}], 1)
    cfg["protocol"] = 7
    code, _, stderr = Launched(run_space, cfg, os.path.join(TEST_COMPONENTS, "echo.py")).finish()
    assert code == 2
    assert "configuration of protocol version 7" in stderr
