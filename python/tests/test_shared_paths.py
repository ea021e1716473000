"""Shared paths no other user can block.

* Two users side by side: root and `nobody` run at the same time with the default runs and
  iceoryx2 folders (no `UIO_RUNS_DIR`, no `XDG_RUNTIME_DIR`). Before, `/tmp/uio-observers`
  belonged to whoever made it first and the other user was refused (exit 2).
* The node-counter race: root's runs while `nobody` watches /dev/shm for iceoryx2's node-counter
  segments (`…global_mgmt`, set to 0666 by iceoryx2 itself) and writes into any it can open.
  Before, such a watcher broke 20 of 20 runs (`UnableToGenerateUniqueNodeId`, exit 3); the
  launcher now runs in a /dev/shm of its own that no other process can see.

Runs only as root with `runuser` and a `nobody` account (skipped otherwise, and said so).
"""

import os
import pwd
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

from test_diagnosis_scipy import launcher

REPO = Path(__file__).resolve().parents[2]
SCENARIO = """name = "shared"
dt = 0.01
duration = 0.5

[plant]
A = [[0.0, 1.0], [-2.0, -3.0]]
B = [[0.0], [1.0]]
C = [[1.0, 0.0]]
x0 = [1.0, 0.0]

[[input]]
kind = "constant"
value = 0.0

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-5.0, -6.0]
"""

pytestmark = pytest.mark.skipif(
    os.geteuid() != 0 or shutil.which("runuser") is None or not any(p.pw_name == "nobody" for p in pwd.getpwall()),
    reason="needs root, runuser and a 'nobody' account to act as another user",
)

@pytest.fixture
def public():
    """A folder of /tmp that nobody may enter and write (pytest's own is root's alone)."""
    base = Path(tempfile.mkdtemp(prefix="uio-shared-"))
    base.chmod(0o777)
    (base / "shared.toml").write_text(SCENARIO)
    (base / "shared.toml").chmod(0o644)
    yield base
    shutil.rmtree(base, ignore_errors=True)


def clean_env():
    return {k: v for k, v in os.environ.items() if k not in ("UIO_RUNS_DIR", "XDG_RUNTIME_DIR")}


def test_two_users_run_side_by_side_with_the_default_folders(public):
    env = clean_env()
    (public / "nobody-out").mkdir()
    shutil.chown(public / "nobody-out", "nobody", "nogroup")
    root = subprocess.Popen([launcher(), "run", str(public / "shared.toml"), "--out", str(public / "root-out")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    other = subprocess.Popen(["runuser", "-u", "nobody", "--", "env", "-u", "UIO_RUNS_DIR", "-u", "XDG_RUNTIME_DIR",
                              launcher(), "run", str(public / "shared.toml"), "--out", str(public / "nobody-out")],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    r, o = root.communicate(timeout=120), other.communicate(timeout=120)
    assert root.returncode == 0, r[1]
    assert other.returncode == 0, o[1]
    uid = pwd.getpwnam("nobody").pw_uid
    for who, path in ((0, "/tmp/uio-observers-0"), (uid, f"/tmp/uio-observers-{uid}")):
        st = os.lstat(path)
        assert st.st_uid == who and st.st_mode & 0o777 == 0o700, (path, oct(st.st_mode))


WATCHER = r"""
import os, sys, time
stop = time.monotonic() + float(sys.argv[1])
seen, written = set(), 0
while time.monotonic() < stop and not os.path.exists(sys.argv[2]):
    for name in os.listdir("/dev/shm"):
        if name.startswith("uio"):
            seen.add(name)
            if name.endswith("global_mgmt"):
                try:
                    with open("/dev/shm/" + name, "r+b") as f:
                        f.write(b"\xff" * 16)
                    written += 1
                except OSError:
                    pass
print(len(seen), written)
"""


def test_a_watcher_as_nobody_neither_sees_nor_breaks_twenty_runs(public):
    """20 runs as root while a `nobody` process scans /dev/shm without pause for the runs'
    segments: every run ends with exit 0, and the watcher never saw a file of theirs."""
    (public / "watcher.py").write_text(WATCHER)
    (public / "watcher.py").chmod(0o644)
    done = public / "done"
    watcher = subprocess.Popen(["runuser", "-u", "nobody", "--", "/usr/bin/python3", str(public / "watcher.py"), "300", str(done)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(0.5)
        failed = []
        for i in range(20):
            run = subprocess.run([launcher(), "run", str(public / "shared.toml"), "--out", str(public / f"out{i}")],
                                 capture_output=True, text=True, env=clean_env(), timeout=120)
            if run.returncode != 0:
                failed.append((i, run.returncode, run.stderr.strip().splitlines()[-1:]))
    finally:
        done.write_text("")
        out, err = watcher.communicate(timeout=60)
    assert watcher.returncode == 0, err
    seen, written = map(int, out.split())
    assert failed == [], failed
    assert (seen, written) == (0, 0), f"the watcher saw {seen} run file(s) in /dev/shm and wrote into {written}"


def scan_while(proc, prefix):
    """Names in the machine's /dev/shm starting with `prefix`, seen while `proc` runs."""
    seen = set()
    while proc.poll() is None:
        seen.update(n for n in os.listdir("/dev/shm") if n.startswith(prefix))
    return seen


@pytest.mark.skipif(shutil.which("setpriv") is None, reason="needs setpriv to run the launcher as nobody")
def test_a_run_by_another_user_keeps_its_segments_out_of_the_machines_dev_shm(public):
    """Runs as `nobody` (not root) move to a user namespace and a /dev/shm of their own too: a
    scan of the machine's /dev/shm while each runs sees none of its segments (the node counter's
    0666 window included), and every run completes. With UIO_SHARED_SHM=1 the same scan sees
    them: the scan is able to."""
    out = public / "nobody-runs"
    out.mkdir()
    shutil.chown(out, "nobody", "nogroup")

    def runs(extra_env):
        found = []
        for i in range(5):
            env = dict(clean_env(), **extra_env)
            p = subprocess.Popen(["setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups", launcher(), "run",
                                  str(public / "shared.toml"), "--out", str(out / f"{len(extra_env)}-{i}")],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
            # setpriv execs the launcher: the run's segments are named uio<its pid>x…
            seen = scan_while(p, f"uio{p.pid}x")
            _, err = p.communicate(timeout=120)
            assert p.returncode == 0, err
            found.append(len(seen))
        return found

    assert runs({}) == [0] * 5
    assert any(n > 0 for n in runs({"UIO_SHARED_SHM": "1"}))
