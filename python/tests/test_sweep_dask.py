"""The Python package's sweep, here and on Dask workers, gives `uio-launcher sweep`'s result: every
field of `<name>.sweep.json` but the wall time and the jobs, and its worst realisations'
recordings the same runs bit for bit (`uio-launcher compare`). The shards run in worker processes of
a `distributed.LocalCluster` (each imports the package and runs its shards in-process), and the
merge is `uio-launcher sweep merge`'s."""

import json
import os
import subprocess

import pytest

import uio_observers as uo
from test_diagnosis_scipy import launcher

SCENARIO = "seed002-actuator-faults"
RUNS, KEEP = 7, 2


def cli_sweep(tmp_path):
    out = tmp_path / "cli"
    done = subprocess.run([launcher(), "sweep", SCENARIO, "--runs", str(RUNS), "--keep-worst", str(KEEP),
                           "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    with open(out / f"{SCENARIO}.sweep.json") as f:
        return out, json.load(f)


def same_sweep(want_dir, want, got):
    for key, value in want.items():
        if key in ("wall_s", "jobs"):
            continue
        assert got.summary[key] == value, key
    assert len(want["kept"]) == KEEP
    for seed in want["kept"]:
        name = f"{SCENARIO}-seed{seed}.rrd"
        done = subprocess.run([launcher(), "compare", str(want_dir / name), os.path.join(os.path.dirname(got.path), name)],
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0 and "bit for bit" in done.stdout, done.stdout + done.stderr


def test_a_sweep_in_shards_here_is_the_launchers_sweep(tmp_path):
    want_dir, want = cli_sweep(tmp_path)
    got = uo.sweep(SCENARIO, runs=RUNS, keep_worst=KEEP, shards=3, out=tmp_path / "here")
    same_sweep(want_dir, want, got)
    assert "realisations" in repr(got)


def test_a_sweep_on_dask_workers_is_the_launchers_sweep(tmp_path):
    distributed = pytest.importorskip("distributed")
    want_dir, want = cli_sweep(tmp_path)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        with distributed.get_task_stream(client) as stream:
            got = uo.sweep(SCENARIO, runs=RUNS, keep_worst=KEEP, client=client, out=tmp_path / "dask")
        workers = set(client.scheduler_info()["workers"])
        shards = sorted(os.listdir(tmp_path / "dask"))
    # Four shards per worker by default (seven: no more than the realisations), each a task that
    # ran on one of the cluster's worker processes.
    assert [s for s in shards if s.startswith("shard-")] == [f"shard-{k}-of-7" for k in range(1, 8)], shards
    tasks = [t for t in stream.data if "_shard" in str(t["key"])]
    assert len(tasks) == 7 and {t["worker"] for t in tasks} <= workers, stream.data
    same_sweep(want_dir, want, got)


def test_a_sweep_without_out_leaves_no_folder_behind(tmp_path):
    got = uo.sweep(SCENARIO, runs=2)
    assert got.path is None and got.summary["runs"] == 2


def test_a_bad_scenario_raises_the_launchers_reason(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = \"bad\"\ndt = -1.0\n")
    with pytest.raises(ValueError, match="bad.toml:1:1: missing field `duration`"):
        uo.sweep(bad, runs=2)


def test_a_worker_killed_mid_sweep_changes_nothing(tmp_path):
    """A worker process killed (SIGKILL) while it runs a shard: Dask's nanny restarts it and
    the scheduler runs the lost shards again; the merged sweep is still the launcher's."""
    distributed = pytest.importorskip("distributed")
    import signal
    import threading
    import time

    scenario, runs = "seed002-sine", 8
    out = tmp_path / "cli"
    done = subprocess.run([launcher(), "sweep", scenario, "--runs", str(runs), "--out", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    with open(out / f"{scenario}.sweep.json") as f:
        want = json.load(f)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        pids = client.run(os.getpid)
        result = {}
        worker = threading.Thread(target=lambda: result.update(
            got=uo.sweep(scenario, runs=runs, shards=runs, client=client, out=tmp_path / "dask")))
        worker.start()
        victim, killed = sorted(pids)[0], False
        stop = time.monotonic() + 120
        while worker.is_alive() and time.monotonic() < stop and not killed:
            if client.processing().get(victim):
                os.kill(pids[victim], signal.SIGKILL)
                killed = True
            time.sleep(0.005)
        worker.join(timeout=300)
    assert killed, "the sweep ended before a task reached the worker to kill"
    got = result["got"]
    for key, value in want.items():
        if key not in ("wall_s", "jobs"):
            assert got.summary[key] == value, key
