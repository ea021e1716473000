"""Shared paths no other user can block (issue 32, item 4).

* Two users side by side: root and `nobody` run at the same time with the default runs and
  iceoryx2 folders (no `UIO_RUNS_DIR`, no `XDG_RUNTIME_DIR`). Before, `/tmp/uio-observers`
  belonged to whoever made it first and the other user was refused (exit 2).

Runs only as root with `runuser` and a `nobody` account (skipped otherwise, and said so).
"""

import os
import pwd
import shutil
import subprocess
import tempfile
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
