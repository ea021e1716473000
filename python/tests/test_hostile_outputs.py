"""Outputs that cannot be turned into a write anywhere.

Another local user (`nobody`) who can write the output folder plants symbolic links at every
name a command writes — its temporary names (`<name>.rrd.partial`, `<name>.summary.json.tmp`,
`<name>.sweep.json.tmp`, `.<name>.write-test`) and its outputs themselves (`<name>.summary.json`,
`outputs.png`, `uio_fmi3.fmu`, `Phi.npy`, `plant_x.csv`) — pointing at a file only root may
write. Root then runs `run`, `sweep`, `plot`, `export-fmu`, `linearize` and `export` into that
folder. The victim must keep its content, and every output be a regular file of root's (the link
replaced, never written through). Before, `File::create`/`fs::write` followed the links
and truncated the victim — even a run refused with "already exists" truncated it first.

Runs only as root with `runuser` and a `nobody` account (skipped otherwise, and said so).
"""

import os
import pwd
import shutil
import stat
import subprocess
import tempfile
from pathlib import Path

import pytest

from test_diagnosis_scipy import launcher

REPO = Path(__file__).resolve().parents[2]
SCENARIO = "seed002-piecewise"

pytestmark = pytest.mark.skipif(
    os.geteuid() != 0 or shutil.which("runuser") is None or not any(p.pw_name == "nobody" for p in pwd.getpwall()),
    reason="needs root, runuser and a 'nobody' account to plant links as another user",
)


@pytest.fixture
def folder():
    """(the folder nobody owns, the victim root owns, a function that plants links as nobody),
    under a fresh folder of /tmp that nobody may enter (pytest's own is root's alone)."""
    base = Path(tempfile.mkdtemp(prefix="uio-hostile-"))
    base.chmod(0o755)
    yield from _folder(base)
    shutil.rmtree(base, ignore_errors=True)


def _folder(tmp_path):
    secret = tmp_path / "root-only"
    secret.mkdir(mode=0o700)
    victim = secret / "victim"
    victim.write_text("keep")
    out = tmp_path / "shared"
    out.mkdir()
    shutil.chown(out, "nobody", "nogroup")
    out.chmod(0o755)

    def plant(*names):
        for name in names:
            subprocess.run(["runuser", "-u", "nobody", "--", "ln", "-sf", str(victim), str(out / name)], check=True)
            assert (out / name).is_symlink()

    yield out, victim, plant


def intact(victim, out, *outputs):
    assert victim.read_text() == "keep", "the victim was written through a planted link"
    for name in outputs:
        p = out / name
        assert p.exists() and not p.is_symlink() and p.stat().st_uid == 0, name


def launch(*args):
    return subprocess.run([launcher(), *map(str, args)], capture_output=True, text=True, timeout=600)


def test_a_run_writes_no_output_through_a_planted_link(folder):
    out, victim, plant = folder
    plant(f"{SCENARIO}.rrd", f"{SCENARIO}.rrd.partial", f"{SCENARIO}.summary.json", f"{SCENARIO}.summary.json.tmp", f".{SCENARIO}.write-test")
    # Refused as "already exists": nothing is opened.
    p = launch("run", SCENARIO, "--mode", "in-process", "--out", out)
    assert p.returncode == 2 and "already exists" in p.stderr, p.stderr
    intact(victim, out)
    # With --force the links are replaced by root's own files.
    p = launch("run", SCENARIO, "--mode", "in-process", "--out", out, "--force")
    assert p.returncode == 0, p.stderr
    intact(victim, out, f"{SCENARIO}.rrd", f"{SCENARIO}.summary.json")
    assert not (out / f"{SCENARIO}.rrd.partial").exists()


def test_a_run_across_processes_writes_no_output_through_a_planted_partial(folder):
    out, victim, plant = folder
    plant(f"{SCENARIO}.rrd.partial", f"{SCENARIO}.summary.json.tmp")
    p = launch("run", SCENARIO, "--out", out)
    assert p.returncode == 0, p.stderr
    intact(victim, out, f"{SCENARIO}.rrd", f"{SCENARIO}.summary.json")


def test_plot_export_export_fmu_sweep_and_linearize_write_no_output_through_a_planted_link(folder, tmp_path):
    out, victim, plant = folder
    run = tmp_path / "run"
    assert launch("run", SCENARIO, "--mode", "in-process", "--out", run).returncode == 0
    rrd = run / f"{SCENARIO}.rrd"
    plant("outputs.png", "errors_log.png", "plant_x.csv", "uio_fmi3.fmu", f"{SCENARIO}.sweep.json", f"{SCENARIO}.sweep.json.tmp")
    p = launch("plot", rrd, "--out", out)
    assert p.returncode == 0, p.stderr
    intact(victim, out, "outputs.png", "errors_log.png")
    p = launch("export", rrd, "--csv", out)
    assert p.returncode == 2 and "plant_x.csv: already exists" in p.stderr, p.stderr
    intact(victim, out)
    p = launch("export", rrd, "--csv", out, "--force")
    assert p.returncode == 0, p.stderr
    intact(victim, out, "plant_x.csv")
    p = launch("export-fmu", SCENARIO, "--observer", "uio", "--out", out)
    assert p.returncode == 0, p.stderr
    intact(victim, out, "uio_fmi3.fmu")
    p = launch("sweep", SCENARIO, "--runs", "2", "--out", out)
    assert p.returncode == 0, p.stderr
    intact(victim, out, f"{SCENARIO}.sweep.json")
    # linearize: the linear test FMU's scenario, its .npy files and scenario planted.
    fmus = os.environ.get("UIO_TEST_FMUS")
    if not fmus or not os.path.isfile(os.path.join(fmus, "lti_plant_fmi2.fmu")):
        return
    (tmp_path / "lti.toml").write_text(f"""name = "lti"
dt = 0.1
[plant.operating_point]
x = [0.0, 0.0, 0.0]
[plant.fmu]
path = "{os.path.join(fmus, 'lti_plant_fmi2.fmu')}"
inputs = ["u1", "u2"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]
""")
    plant("Phi.npy", "C.npy", "lti.toml")
    p = launch("linearize", tmp_path / "lti.toml", "--out", out)
    assert p.returncode == 0, p.stderr
    intact(victim, out, "Phi.npy", "C.npy", "lti.toml")


def test_fifos_planted_at_output_names_neither_hang_nor_are_opened(folder, tmp_path):
    """FIFOs (named pipes) made by nobody at a run's and a plot's outputs: before, opening one
    for writing blocked `run` and `plot` forever. Now nothing is opened at an output's name —
    a run refuses ("already exists") or, with --force, renames its file over the FIFO, and so
    does plot; each within the timeout, the FIFO replaced by a regular file of root's."""
    out, _, _ = folder
    fifos = [f"{SCENARIO}.rrd", f"{SCENARIO}.summary.json", "outputs.png", "inputs.png"]
    for name in fifos:
        subprocess.run(["runuser", "-u", "nobody", "--", "mkfifo", str(out / name)], check=True)
    p = subprocess.run([launcher(), "run", SCENARIO, "--mode", "in-process", "--out", str(out)], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "already exists" in p.stderr, p.stderr
    p = subprocess.run([launcher(), "run", SCENARIO, "--out", str(out), "--force"], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    p = subprocess.run([launcher(), "plot", str(out / f"{SCENARIO}.rrd"), "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    for name in fifos:
        st = (out / name).lstat()
        assert stat.S_ISREG(st.st_mode) and st.st_uid == 0 and st.st_size > 0, (name, oct(st.st_mode))
