#!/usr/bin/env bash
# Two "hosts" on one machine: network namespaces joined by a veth pair with private test
# addresses (10.77.0.1 ↔ 10.77.0.2). Host B runs an agent (`launcher agent`); host A runs the
# launcher with the seed 002 closed loop whose plant and Luenberger observer are placed on B
# (`[hosts]`, `host = …`).
# Traffic stays between the two namespaces; both are removed on exit, also on failure.
#
#   scripts/two-hosts.sh run             the two-host run equals the single-host run bit for bit
#   scripts/two-hosts.sh kill-component  the plant is killed on B: the run stops within 2 s
#   scripts/two-hosts.sh kill-agent      B's agent is killed: the run stops within 2 s
#   scripts/two-hosts.sh cut-link        the link goes down: the run stops within 2 s
#   scripts/two-hosts.sh kill-local      the controller is killed on A: B removes its side too
#
# Each case checks its own outcome and that neither host keeps a process, a run directory or a
# shared-memory file; it prints "ok <case>: …" and exits 0, or says why and exits 1. Without
# root or `ip netns` it prints "skipped: …" and exits 77.
set -euo pipefail
case_name="${1:-run}"
repo="$(cd "$(dirname "$0")/.." && pwd)"
bin="${CARGO_TARGET_DIR:-$repo/target}/release"
launcher="$bin/launcher"
[ -x "$launcher" ] && [ -x "$bin/uio-bridge" ] || { echo "two-hosts: build first (cargo build --release --workspace)"; exit 1; }

if [ "$(id -u)" -ne 0 ] || ! command -v ip >/dev/null || ! ip netns list >/dev/null 2>&1; then
  echo "skipped: network namespaces need root and iproute2's ip netns"; exit 77
fi
tag="$$"
nsa="uioa$tag"; nsb="uiob$tag"; va="uva$tag"; vb="uvb$tag"
if ! ip netns add "$nsa" 2>/dev/null; then echo "skipped: ip netns add is not allowed here"; exit 77; fi
work="$(mktemp -d /tmp/uio2h.XXXXXX)"
agent_pid=""
cleanup() {
  [ -n "$agent_pid" ] && kill -KILL "$agent_pid" 2>/dev/null || true
  for ns in "$nsa" "$nsb"; do
    for p in $(ip netns pids "$ns" 2>/dev/null); do kill -KILL "$p" 2>/dev/null || true; done
  done
  sleep 0.2
  ip netns del "$nsa" 2>/dev/null || true
  ip netns del "$nsb" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
ip netns add "$nsb"
ip link add "$va" type veth peer name "$vb"
ip link set "$va" netns "$nsa"; ip link set "$vb" netns "$nsb"
ip -n "$nsa" addr add 10.77.0.1/30 dev "$va"; ip -n "$nsb" addr add 10.77.0.2/30 dev "$vb"
for ns in "$nsa" "$nsb"; do ip -n "$ns" link set lo up; done
ip -n "$nsa" link set "$va" up; ip -n "$nsb" link set "$vb" up
endpoint="tcp/10.77.0.2:7447"
mkdir -p "$work/a" "$work/b" "$work/out1" "$work/out2"
shm_before="$(ls /dev/shm | sort)"

fail() { echo "two-hosts $case_name: $*"; [ -f "$work/launcher.err" ] && tail -3 "$work/launcher.err"; [ -f "$work/agent.err" ] && tail -3 "$work/agent.err"; exit 1; }

# The agent on B: listens on B's address only.
ip netns exec "$nsb" env UIO_RUNS_DIR="$work/b" "$launcher" agent --host rig --listen "$endpoint" 2>"$work/agent.err" &
agent_pid=$!
disown "$agent_pid"
# It says so once its token and its queryable are declared.
for _ in $(seq 100); do
  grep -q "listening on" "$work/agent.err" 2>/dev/null && break
  sleep 0.05
done
grep -q "listening on" "$work/agent.err" || fail "the agent did not start"
ip netns exec "$nsb" ss -ltn | grep -q '10.77.0.2:7447' || fail "the agent is not listening on $endpoint"
listeners="$(ip netns exec "$nsb" ss -ltnH | awk '{print $4}' | sort -u | tr '\n' ' ')"

# The scenario: seed 002 with its plant and its Luenberger observer on B (two components there,
# one reading the other), the UIO and the controller on A.
scenario() {  # $1: duration, s
  sed -e "s/^duration = .*/duration = $1/" -e '0,/^name = .*/s//name = "two-hosts"/' "$repo/scenarios/seed002-sine.toml" \
    | sed -e '/^\[plant\]/a host = "rig"' -e '/^kind = "luenberger"/a host = "rig"'
  printf '\n[hosts]\nrig = "%s"\n' "$endpoint"
}
single() {  # the same scenario on one host
  sed -e "s/^duration = .*/duration = $1/" -e '0,/^name = .*/s//name = "two-hosts"/' "$repo/scenarios/seed002-sine.toml"
}

# Nothing of the run left on either host: processes, run directories, shared memory.
check_clean() {
  sleep 0.3
  for ns in "$nsa" "$nsb"; do
    left="$(ip netns pids "$ns" | grep -vx "$agent_pid" || true)"
    [ -z "$left" ] || fail "processes left in $ns: $(ps -o comm= -p $left | tr '\n' ' ')"
  done
  [ -z "$(ls -A "$work/a" "$work/b" 2>/dev/null | grep -v ':$' | grep -v '^$' || true)" ] || fail "run directories left: $(ls -A "$work/a" "$work/b")"
  shm_after="$(ls /dev/shm | sort)"
  new="$(comm -13 <(echo "$shm_before") <(echo "$shm_after") | grep '^uio' || true)"
  [ -z "$new" ] || fail "shared memory left: $new"
}

now() { date +%s.%N; }

case "$case_name" in
  run)
    scenario 20.0 > "$work/two.toml"; single 20.0 > "$work/one.toml"
    ip netns exec "$nsa" env UIO_RUNS_DIR="$work/a" "$launcher" run "$work/two.toml" --out "$work/out2" --force >"$work/launcher.out" 2>"$work/launcher.err" || fail "the two-host run failed"
    env UIO_RUNS_DIR="$work/a" "$launcher" run "$work/one.toml" --out "$work/out1" --force >"$work/single.out" 2>&1 || fail "the single-host run failed"
    "$launcher" compare "$work/out1/two-hosts.rrd" "$work/out2/two-hosts.rrd" >"$work/compare.out" 2>&1 || { cat "$work/compare.out"; fail "the recordings differ"; }
    grep -q "bit for bit" "$work/compare.out" || fail "$(cat "$work/compare.out")"
    check_clean
    lat() { python3 -c 'import json,sys; l=json.load(open(sys.argv[1]))["latency_ns"]; f=lambda s: "p50 %.1f µs, p99 %.1f µs" % (s["p50"] / 1e3, s["p99"] / 1e3); print("step " + f(l["step"]) + "; hops: " + "; ".join(k + " " + f(v) for k, v in sorted(l["hops"].items())))' "$1"; }
    # One clock on both "hosts": the estimated offset must be within its own error bound.
    clock="$(grep -m1 'worker for plant: this host' "$work/agent.err")" || fail "no clock offset reported"
    read -r theta bound < <(echo "$clock" | sed -E 's/.*reads (-?[0-9]+) ns ahead.*± ([0-9]+) ns.*/\1 \2/')
    [ "${theta#-}" -le "$bound" ] || fail "clock offset $theta ns on one machine, beyond its bound ± $bound ns"
    echo "ok run: $(cat "$work/compare.out"); clock offset $theta ns (± $bound ns); B listens on: $listeners"
    echo "  two hosts: $(lat "$work/out2/two-hosts.summary.json")"
    echo "  one host:  $(lat "$work/out1/two-hosts.summary.json")"
    ;;
  kill-component|kill-agent|cut-link|kill-local)
    scenario 60.0 > "$work/two.toml"
    ip netns exec "$nsa" env UIO_RUNS_DIR="$work/a" "$launcher" run "$work/two.toml" --out "$work/out2" --force --realtime >"$work/launcher.out" 2>"$work/launcher.err" &
    run_pid=$!
    for _ in $(seq 200); do
      grep -q . "$work/launcher.out" 2>/dev/null && break
      pgrep -f "^$bin/plant --run" >/dev/null && break
      sleep 0.05
    done
    sleep 1.5
    kill -0 "$run_pid" 2>/dev/null || fail "the run ended before the fault"
    t0="$(now)"
    case "$case_name" in
      kill-component) pkill -KILL -f "^$bin/plant --run" || fail "no plant on B" ;;
      kill-agent) kill -KILL "$agent_pid"; agent_pid="" ;;
      cut-link) ip -n "$nsa" link set "$va" down ;;
      kill-local) pkill -KILL -f "^$bin/controller --run" || fail "no controller on A" ;;
    esac
    rc=0; wait "$run_pid" || rc=$?
    t1="$(now)"
    took="$(python3 -c "print(f'{$t1 - $t0:.2f}')")"
    [ "$rc" -eq 3 ] || fail "launcher run exited $rc, not 3"
    python3 -c "import sys; sys.exit(0 if $t1 - $t0 <= 2.0 else 1)" || fail "the run took $took s to stop"
    why="$(grep -m1 -E 'error|stopped' "$work/launcher.err" || tail -1 "$work/launcher.err")"
    # A lost agent or link is noticed by whichever of B's components' proxies sees it first.
    case "$case_name" in
      kill-component) lost="plant (on host rig)" ;;
      kill-local) lost="controller" ;;
      *) lost="(on host rig)" ;;
    esac
    echo "$why" | grep -q "$lost" || fail "the message does not name $lost: $why"
    [ -f "$work/out2/two-hosts.rrd" ] || fail "no recording was finalized"
    if [ "$case_name" = cut-link ]; then ip -n "$nsa" link set "$va" up; fi
    # B's worker notices too (the link's lease, 1 s) and removes the plant and its run space.
    sleep 1.5
    check_clean
    echo "ok $case_name: stopped in $took s: $why"
    ;;
  *) echo "usage: $0 run|kill-component|kill-agent|cut-link|kill-local"; exit 2 ;;
esac
