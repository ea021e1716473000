"""A recording of layout 2 is a valid Rerun 0.36 file for Rerun's own CLI.

`rerun rrd verify` (the rerun-sdk 0.36.3 package's CLI, installed by scripts/test.sh) decodes
every chunk of the file and checks it against the types it knows, independently of our reader:
recordings of both modes, with a diagnosis bank and faults (seed002-actuator-faults), pass it;
a file cut short does not.
"""

import shutil
import subprocess
from pathlib import Path

import pytest

from test_diagnosis_scipy import launcher

REPO = Path(__file__).resolve().parents[2]


def rerun():
    path = shutil.which("rerun")
    if path is None:
        pytest.fail("the rerun CLI (pip rerun-sdk==0.36.3) is not installed; scripts/test.sh installs it")
    return path


@pytest.mark.parametrize("mode", ["in-process", "processes"])
def test_rerun_verifies_our_recordings(tmp_path, mode):
    scenario = REPO / "scenarios" / "seed002-actuator-faults.toml"
    text = scenario.read_text().replace("duration = 20.0", "duration = 6.0").split("\n[expect]")[0]
    path = tmp_path / "s.toml"
    path.write_text(text)
    run = subprocess.run([launcher(), "run", str(path), "--mode", mode, "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    rrd = tmp_path / "out" / "seed002-actuator-faults.rrd"
    ok = subprocess.run([rerun(), "rrd", "verify", str(rrd)], capture_output=True, text=True, timeout=300)
    assert ok.returncode == 0, ok.stdout + ok.stderr
    assert "verified without error" in ok.stdout + ok.stderr
    cut = tmp_path / "cut.rrd"
    data = rrd.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    bad = subprocess.run([rerun(), "rrd", "verify", str(cut)], capture_output=True, text=True, timeout=300)
    assert bad.returncode != 0, bad.stdout + bad.stderr
