"""Shared fixtures: the kit from this checkout, and a private corner for a fake run."""

import glob
import os
import pathlib
import shutil
import sys
import tempfile
import uuid

import pytest

PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REPO = os.path.dirname(PYTHON_DIR)
COMPONENTS = os.path.join(REPO, "components")
TEST_COMPONENTS = os.path.join(PYTHON_DIR, "tests", "components")

# The tests exercise the kit of this checkout, installed or not.
sys.path.insert(0, PYTHON_DIR)
sys.path.insert(0, COMPONENTS)


@pytest.fixture
def run_space():
    """A run id, its directory (owner.pid = this process), iceoryx2 prefix and root; the run's
    directory and shared memory are removed afterwards. The directory is short, under /tmp:
    iceoryx2's event sockets live in the root and a Unix socket path has at most 107 bytes."""
    run = f"{os.getpid()}x0x{uuid.uuid4().int % 10**9}"
    runs_dir = pathlib.Path(tempfile.mkdtemp(prefix="uiot", dir="/tmp"))
    run_dir = runs_dir / run
    (run_dir / "iox2").mkdir(parents=True)
    (run_dir / "owner.pid").write_text(f"{os.getpid()}\n")
    prefix = f"uio{run}_"
    space = {
        "run": run,
        "runs_dir": str(runs_dir),
        "dir": str(run_dir),
        "prefix": prefix,
        "root": str(run_dir / "iox2") + "/",
    }
    yield space
    shutil.rmtree(runs_dir, ignore_errors=True)
    for f in glob.glob(f"/dev/shm/{prefix}*"):
        try:
            os.unlink(f)
        except OSError:
            pass


def shm_files(prefix):
    """The shared-memory files of a prefix."""
    return glob.glob(f"/dev/shm/{prefix}*")
