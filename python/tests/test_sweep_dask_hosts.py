"""A sweep on a Dask cluster of two "hosts" — network namespaces joined by a veth pair, as
scripts/two-hosts.sh makes them: the scheduler and one worker on A (10.79.0.1), one worker on B
(10.79.0.2), the client on A — equals `uio-launcher sweep` on this machine bit for bit (every
field of `<name>.sweep.json` but the wall time and the jobs), with shards run on both hosts; and
when B's worker is killed while it runs a shard, Dask runs that shard again on A and the result
is still the same. Needs root and `ip netns`: skipped without them."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import pytest

from test_diagnosis_scipy import launcher

SCENARIO = "seed002-actuator-faults"
VENV_BIN = os.path.dirname(sys.executable)

CLIENT = r"""
import json, os, sys, threading, time
import distributed
import uio_observers as uo

scheduler, scenario, runs, out, report, kill = sys.argv[1:7]
with distributed.Client(scheduler, timeout=60) as client:
    client.wait_for_workers(2, timeout=60)
    workers = {info["name"]: addr for addr, info in client.scheduler_info()["workers"].items()}
    done = {}

    def run():
        with distributed.get_task_stream(client) as stream:
            done["result"] = uo.sweep(scenario, runs=int(runs), client=client, shards=6, out=out)
        done["hosts"] = sorted({t["worker"].split("://")[1].split(":")[0] for t in stream.data})

    t = threading.Thread(target=run)
    t.start()
    if kill == "kill":
        # Say when B's worker is running a shard; the test kills it then.
        while t.is_alive():
            if client.processing(workers=[workers["b"]]).get(workers["b"]):
                print("b busy", flush=True)
                break
            time.sleep(0.005)
    t.join()
    json.dump({"summary": done["result"].summary, "hosts": done["hosts"]}, open(report, "w"))
"""


def ip(*args):
    subprocess.run(["ip", *args], check=True, capture_output=True, timeout=30)


@pytest.fixture
def hosts(tmp_path):
    """(namespace A, namespace B, the processes started in them)."""
    if os.geteuid() != 0 or shutil.which("ip") is None:
        pytest.skip("network namespaces need root and iproute2's ip netns")
    tag = str(os.getpid())
    nsa, nsb, va, vb = f"udka{tag}", f"udkb{tag}", f"udva{tag}", f"udvb{tag}"
    if subprocess.run(["ip", "netns", "add", nsa], capture_output=True).returncode != 0:
        pytest.skip("ip netns add is not allowed here")
    procs = []
    try:
        ip("netns", "add", nsb)
        ip("link", "add", va, "type", "veth", "peer", "name", vb)
        ip("link", "set", va, "netns", nsa)
        ip("link", "set", vb, "netns", nsb)
        ip("-n", nsa, "addr", "add", "10.79.0.1/30", "dev", va)
        ip("-n", nsb, "addr", "add", "10.79.0.2/30", "dev", vb)
        for ns, dev in ((nsa, va), (nsb, vb)):
            ip("-n", ns, "link", "set", "lo", "up")
            ip("-n", ns, "link", "set", dev, "up")
        yield nsa, nsb, procs
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
            p.wait(timeout=30)
        for ns in (nsa, nsb):
            pids = subprocess.run(["ip", "netns", "pids", ns], capture_output=True, text=True).stdout.split()
            for pid in pids:
                try:
                    os.kill(int(pid), signal.SIGKILL)
                except ProcessLookupError:
                    pass
            subprocess.run(["ip", "netns", "del", ns], capture_output=True)


def start(procs, ns, tmp_path, name, *args):
    log = open(tmp_path / f"{name}.log", "w")
    p = subprocess.Popen(["ip", "netns", "exec", ns, *args], stdout=log, stderr=subprocess.STDOUT,
                         cwd=tmp_path, start_new_session=True)
    procs.append(p)
    return p


def cluster(hosts, tmp_path):
    nsa, nsb, procs = hosts
    dask = os.path.join(VENV_BIN, "dask")
    start(procs, nsa, tmp_path, "scheduler", dask, "scheduler", "--host", "10.79.0.1", "--port", "8786",
          "--no-dashboard")
    worker = ["worker", "tcp://10.79.0.1:8786", "--nthreads", "1", "--no-nanny", "--no-dashboard"]
    start(procs, nsa, tmp_path, "worker-a", dask, *worker, "--name", "a", "--host", "10.79.0.1")
    b = start(procs, nsb, tmp_path, "worker-b", dask, *worker, "--name", "b", "--host", "10.79.0.2")
    return nsa, b


def cli_sweep(tmp_path, runs):
    out = tmp_path / "cli"
    done = subprocess.run([launcher(), "sweep", SCENARIO, "--runs", str(runs), "--out", str(out)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    with open(out / f"{SCENARIO}.sweep.json") as f:
        return json.load(f)


def same(want, got):
    for key, value in want.items():
        if key not in ("wall_s", "jobs"):
            assert got[key] == value, key


def client(hosts, tmp_path, runs, kill):
    nsa, b = cluster(hosts, tmp_path)
    (tmp_path / "client.py").write_text(CLIENT)
    report = tmp_path / "report.json"
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    p = subprocess.Popen(["ip", "netns", "exec", nsa, sys.executable, str(tmp_path / "client.py"),
                          "tcp://10.79.0.1:8786", SCENARIO, str(runs), str(tmp_path / "dask"), str(report),
                          "kill" if kill else "keep"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path, env=env)
    hosts[2].append(p)
    killed = False
    if kill:
        line = p.stdout.readline()
        if line.strip() == "b busy":
            b.send_signal(signal.SIGKILL)
            killed = True
    try:
        _, err = p.communicate(timeout=600)
    except subprocess.TimeoutExpired:
        p.kill()
        raise
    assert p.returncode == 0, err + "".join((tmp_path / f).read_text() for f in ("scheduler.log", "worker-a.log"))
    return json.loads(report.read_text()), killed


def test_a_sweep_across_two_hosts_is_the_local_sweep(hosts, tmp_path):
    want = cli_sweep(tmp_path, 24)
    got, _ = client(hosts, tmp_path, 24, kill=False)
    same(want, got["summary"])
    assert got["hosts"] == ["10.79.0.1", "10.79.0.2"], got["hosts"]


def test_a_worker_killed_during_its_shard_leaves_the_result_the_same(hosts, tmp_path):
    want = cli_sweep(tmp_path, 60)
    got, killed = client(hosts, tmp_path, 60, kill=True)
    assert killed, "worker b never ran a shard"
    same(want, got["summary"])
