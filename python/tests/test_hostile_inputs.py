"""Readers bounded by what they read: hostile logs built here, each refused
with exit 2 and one line, quickly, within a memory bound, and leaving no process behind.

* A 1.7 KB MCAP whose zstd chunk declares 2^62 bytes uncompressed: before, `uio-replay-plant
  --check` spun at 100 % CPU forever. Now refused from the chunk header (≤ 64 MiB a chunk).
* SIGINT while the pre-flight check reads a 200 MB CSV: exit 130 at once, the check stopped
  (before, the launcher ignored the interrupt while it waited).
* An MCAP whose one message has a 20 MiB field name, and a CSV whose header is a 20 MiB line:
  "did you mean" built an edit-distance table of every pair of words (2.7 GB, 24 GB for 1 GiB)
  and the messages were 20–99 MB lines. Now: the peak RSS of the launcher and its children
  stays under 200 MB and the message under 1 000 characters.
"""

import json
import os
import resource
import struct
import subprocess
import sys
import time

import pytest

from test_diagnosis_scipy import launcher

SCENARIO = """name = "hostile"
dt = 0.1
duration = 1.0

[plant]
A = [[-1.0]]
B = [[1.0]]
C = [[1.0]]
x0 = [0.0]

[plant.replay]
path = "{path}"
time = "t"
inputs = ["u"]
outputs = ["y"]
{extra}

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-2.0]
"""


def measured(args, cwd):
    """Runs `args` from a fresh Python process: (exit code, stderr, seconds, peak RSS in MB of
    the largest of its descendants)."""
    code = (
        "import resource, subprocess, sys, json, time\n"
        "t = time.monotonic()\n"
        f"p = subprocess.run({args!r}, capture_output=True, text=True, timeout=120)\n"
        "print(json.dumps([p.returncode, p.stderr, time.monotonic() - t, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd, timeout=300)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def leftovers(marker):
    """Processes whose command line holds `marker` (this test's own folder)."""
    found = []
    for pid in os.listdir("/proc"):
        if pid.isdigit():
            try:
                if marker in open(f"/proc/{pid}/cmdline", "rb").read().decode(errors="replace"):
                    found.append(pid)
            except OSError:
                pass
    return found


def write_mcap(path, payload, compression="zstd"):
    from mcap.writer import CompressionType, Writer

    with open(path, "wb") as f:
        w = Writer(f, compression=CompressionType.ZSTD if compression == "zstd" else CompressionType.NONE, enable_crcs=False)
        w.start()
        schema = w.register_schema(name="s", encoding="jsonschema", data=b"{}")
        ch = w.register_channel(topic="/plant", message_encoding="json", schema_id=schema)
        for k in range(11):
            w.add_message(channel_id=ch, log_time=k * 100_000_000, publish_time=k * 100_000_000, data=payload(k))
        w.finish()


def chunk_lie(path):
    """A normal zstd-chunked log, then its chunk header's uncompressed size set to 2^62."""
    write_mcap(path, lambda k: json.dumps({"t": k * 0.1, "u": 0.0, "y": 0.0}).encode())
    data = bytearray(path.read_bytes())
    at = 8
    while at < len(data):
        op, length = data[at], struct.unpack_from("<Q", data, at + 1)[0]
        if op == 0x06:  # Chunk: start, end, uncompressed_size, uncompressed_crc, …
            struct.pack_into("<Q", data, at + 9 + 16, 1 << 62)
            struct.pack_into("<I", data, at + 9 + 24, 0)
            break
        at += 9 + length
    else:
        raise AssertionError("no chunk record")
    path.write_bytes(bytes(data))


def test_a_chunk_that_lies_about_its_size_is_refused_at_once(tmp_path):
    log = tmp_path / "lie.mcap"
    chunk_lie(log)
    assert log.stat().st_size < 4096
    (tmp_path / "s.toml").write_text(SCENARIO.format(path="lie.mcap", extra='channel = "/plant"'))
    code, err, seconds, rss = measured([launcher(), "run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "out")], tmp_path)
    print(f"chunk declaring 2^62 bytes: exit {code} in {seconds:.2f} s, peak RSS {rss:.0f} MB: {err.strip()}")
    assert code == 2 and "declares 4611686018427387904 bytes uncompressed" in err, err
    assert len(err.strip().splitlines()) == 1 and seconds < 20
    assert leftovers(str(tmp_path)) == []
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []


@pytest.mark.parametrize("kind", ["mcap", "csv"])
def test_a_20_mib_name_costs_no_more_than_200_mb(tmp_path, kind):
    long = "f" * (20 << 20)
    if kind == "mcap":
        # The first message carries the name (the mapping is read off it), as the 90 KB log.
        write_mcap(tmp_path / "long.mcap", lambda k: json.dumps({long: 1.0, "tt": k * 0.1} if k == 0 else {"tt": k * 0.1}).encode())
        extra = 'channel = "/plant"'
    else:
        (tmp_path / "long.csv").write_text(f"{long},tt,uu,yy\n" + "".join(f"0,{k * 0.1},0,0\n" for k in range(11)))
        extra = ""
    size = (tmp_path / f"long.{kind}").stat().st_size
    (tmp_path / "s.toml").write_text(SCENARIO.format(path=f"long.{kind}", extra=extra))
    code, err, seconds, rss = measured([launcher(), "run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "out")], tmp_path)
    print(f"{kind} of {size / 1024:.0f} KB with a 20 MiB name: exit {code} in {seconds:.2f} s, peak RSS {rss:.0f} MB, message {len(err)} characters")
    assert code == 2 and len(err) < 1000 and "(20971520 characters)" in err, err[:2000]
    assert rss < 200, rss
    assert leftovers(str(tmp_path)) == []


def children(pid):
    try:
        return [int(c) for c in open(f"/proc/{pid}/task/{pid}/children").read().split()]
    except OSError:
        return []


def cmdline(pid):
    try:
        return open(f"/proc/{pid}/cmdline", "rb").read()
    except OSError:
        return b""


def big_log(tmp_path):
    """A 200 MB CSV log (12 million rows) and a scenario replaying it: its pre-flight check,
    which reads every row, takes seconds."""
    with open(tmp_path / "big.csv", "w") as f:
        f.write("t,u,y\n")
        for k in range(60):
            f.write("".join(f"{0.1 * (k * 200_000 + i):.1f},0.25,0.5\n" for i in range(200_000)))
    (tmp_path / "s.toml").write_text(SCENARIO.format(path="big.csv", extra=""))


def test_an_interrupt_during_the_preflight_stops_it_at_once(tmp_path):
    """A 200 MB CSV log: its pre-flight check (`uio-replay-plant --check`, which reads every row)
    takes seconds. SIGINT to the launcher while the check runs: before, the launcher ignored
    it while it waited. Now exit 130 at once, naming the check, and the check is gone."""
    big_log(tmp_path)
    launched = subprocess.Popen([launcher(), "run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "out")],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check = None
    deadline = time.monotonic() + 20
    while check is None and time.monotonic() < deadline:
        check = next((c for c in children(launched.pid) if b"--check" in cmdline(c)), None)
        time.sleep(0.01)
    assert check is not None, "no pre-flight check seen"
    time.sleep(0.3)
    assert launched.poll() is None, "the check ended before the interrupt: make the log larger"
    t = time.monotonic()
    launched.send_signal(2)
    _, err = launched.communicate(timeout=30)
    seconds = time.monotonic() - t
    print(f"interrupted pre-flight: exit {launched.returncode} after {seconds:.3f} s: {err.strip()}")
    assert launched.returncode == 130 and "interrupted by SIGINT during uio-replay-plant --check" in err, err
    assert seconds < 5
    assert b"uio-replay-plant" not in cmdline(check)
    assert leftovers(str(tmp_path)) == []
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []


def test_a_preflight_past_its_time_limit_is_stopped_and_named(tmp_path):
    """The same 200 MB log under a 1 s limit (UIO_CHECK_TIMEOUT; 120 s by default): the check
    is stopped with its process group, exit 2 with one line naming it, nothing left."""
    big_log(tmp_path)
    env = dict(os.environ, UIO_CHECK_TIMEOUT="1")
    t = time.monotonic()
    done = subprocess.run([launcher(), "run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "out")], capture_output=True, text=True, env=env, timeout=60)
    seconds = time.monotonic() - t
    print(f"pre-flight past 1 s: exit {done.returncode} after {seconds:.2f} s: {done.stderr.strip()}")
    assert done.returncode == 2 and "uio-replay-plant --check did not answer within 1 s; it was stopped" in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and seconds < 10
    assert leftovers(str(tmp_path)) == []
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []
    bad = subprocess.run([launcher(), "run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "out")], capture_output=True, text=True,
                         env=dict(os.environ, UIO_CHECK_TIMEOUT="0"), timeout=60)
    assert bad.returncode == 2 and "UIO_CHECK_TIMEOUT='0': the pre-flight limit is a whole number of seconds from 1 to 3600" in bad.stderr, bad.stderr
