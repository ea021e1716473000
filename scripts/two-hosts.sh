#!/usr/bin/env bash
# Two "hosts" on one machine: network namespaces joined by a veth pair with private test
# addresses (10.77.0.1 ↔ 10.77.0.2). Host B runs an agent (`uio-launcher agent`); host A runs the
# launcher with the seed 002 closed loop whose plant and Luenberger observer are placed on B
# (`[hosts]`, `host = …`).
# Traffic stays between the two namespaces; both are removed on exit, also on failure.
#
#   scripts/two-hosts.sh run             the two-host run equals the single-host run bit for bit
#   scripts/two-hosts.sh kill-component  the plant is killed on B: the run stops within 2 s
#   scripts/two-hosts.sh kill-agent      B's agent is killed: the run stops within 2 s
#   scripts/two-hosts.sh cut-link        the link goes down: the run stops within 2 s
#   scripts/two-hosts.sh kill-local      the controller is killed on A: B removes its side too
#   scripts/two-hosts.sh refused         peers without the user's credentials are kept out
#   scripts/two-hosts.sh attacks         a peer with the user's own launcher credential, during
#                                        a run, cannot read, forge, intercept or exhaust it
#   scripts/two-hosts.sh concurrent      two runs at once through one agent
#   scripts/two-hosts.sh insecure        plain TCP: refused unless the agent says --insecure
#
# Links are mutual TLS with credentials made by `uio-launcher agent init` (one CA; the agent's and
# the launcher's certificates), except in the insecure case.
# Each case checks its own outcome and that neither host keeps a process, a run directory or a
# shared-memory file; it prints "ok <case>: …" and exits 0, or says why and exits 1. Without
# root or `ip netns` it prints "skipped: …" and exits 77.
set -euo pipefail
case_name="${1:-run}"
repo="$(cd "$(dirname "$0")/.." && pwd)"
bin="${CARGO_TARGET_DIR:-$repo/target}/release"
launcher="$bin/uio-launcher"
intruder="$bin/examples/intruder"
[ -x "$launcher" ] && [ -x "$bin/uio-bridge" ] || { echo "two-hosts: build first (cargo build --release --workspace)"; exit 1; }

if [ "$(id -u)" -ne 0 ] || ! command -v ip >/dev/null || ! ip netns list >/dev/null 2>&1; then
  echo "skipped: network namespaces need root and iproute2's ip netns"; exit 77
fi
case "$case_name" in refused|attacks) [ -x "$intruder" ] || { echo "two-hosts: build the intruder first (cargo build --release -p bridge --examples)"; exit 1; } ;; esac
tag="$$"
nsa="uioa$tag"; nsb="uiob$tag"; va="uva$tag"; vb="uvb$tag"
if ! ip netns add "$nsa" 2>/dev/null; then echo "skipped: ip netns add is not allowed here"; exit 77; fi
work="$(mktemp -d /tmp/uio2h.XXXXXX)"
agent_pid=""
cleanup() {
  [ -n "$agent_pid" ] && kill -KILL "$agent_pid" 2>/dev/null || true
  [ -n "${KEEP:-}" ] && cp -r "$work" "$KEEP" 2>/dev/null || true
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
endpoint="${TWO_HOSTS_ENDPOINT:-quic/10.77.0.2:7447}"
[ "$case_name" = insecure ] && endpoint="tcp/10.77.0.2:7447"
mkdir -p -m 700 "$work/a" "$work/b" "$work/out1" "$work/out2" "$work/out3"
# The user's credentials (both hosts read the same directory here), and another CA's.
export UIO_CREDENTIALS="$work/cred"
"$launcher" agent init >/dev/null || { echo "two-hosts: agent init failed"; exit 1; }
"$launcher" agent init --dir "$work/other" >/dev/null
shm_before="$(ls /dev/shm | sort)"

fail() { echo "two-hosts $case_name: $*"; for f in "$work/launcher.err" "$work"/out*/launcher.err; do [ -f "$f" ] && tail -3 "$f"; done; [ -f "$work/agent.err" ] && tail -3 "$work/agent.err"; exit 1; }

# The agent on B: listens on B's address only.
agent_args=(--host rig --listen "$endpoint" --max-workers 4)
# A wildcard address (every interface) is refused before anything listens, unless asked for.
for wild in "${endpoint%%/*}/0.0.0.0:7447" "${endpoint%%/*}/[::]:7447"; do
  rc=0; "$launcher" agent --host rig --listen "$wild" 2>"$work/wildcard.err" || rc=$?
  [ "$rc" -eq 2 ] && grep -q "add --all-interfaces" "$work/wildcard.err" || { echo "two-hosts $case_name: --listen $wild exited $rc: $(cat "$work/wildcard.err")"; exit 1; }
done
if [ "$case_name" = insecure ]; then
  # Plain TCP without --insecure is refused before anything listens.
  rc=0; "$launcher" agent "${agent_args[@]}" 2>"$work/refusal.err" || rc=$?
  [ "$rc" -eq 2 ] && grep -q "add --insecure" "$work/refusal.err" || { echo "two-hosts insecure: plain TCP without --insecure exited $rc: $(cat "$work/refusal.err")"; exit 1; }
  agent_args+=(--insecure)
elif [ "${endpoint%%/*}" = tcp ]; then
  agent_args+=(--insecure)  # TWO_HOSTS_ENDPOINT=tcp/…: the same cases over plain TCP, to compare
fi
ip netns exec "$nsb" env UIO_RUNS_DIR="$work/b" RUST_LOG="${AGENT_LOG:-error}" "$launcher" agent "${agent_args[@]}" >"$work/agent.out" 2>"$work/agent.err" &
agent_pid=$!
disown "$agent_pid"
# It says so once its token and its queryable are declared.
for _ in $(seq 100); do
  grep -q "listening on" "$work/agent.err" 2>/dev/null && break
  sleep 0.05
done
grep -q "listening on" "$work/agent.err" || fail "the agent did not start"
ip netns exec "$nsb" ss -ltnuH | grep -q '10.77.0.2:7447' || fail "the agent is not listening on $endpoint"
listeners="$(ip netns exec "$nsb" ss -ltnuH | awk '{print $1 " " $5}' | sort -u | tr '\n' ' ')"

# The scenario: seed 002 with its plant and its Luenberger observer on B (two components there,
# one reading the other), the UIO and the controller on A.
scenario() {  # $1: duration, s
  sed -e "s/^duration = .*/duration = $1/" -e '0,/^name = .*/s//name = "two-hosts"/' "$repo/scenarios/seed002-sine.toml" \
    | sed -e '/^\[plant\]/a host = "rig"' -e '/^kind = "luenberger"/a host = "rig"'
  printf '\n[hosts]\nrig = "%s"\n' "$endpoint"
}
# Without its [expect] table, for runs too short for it.
bare() { sed '/^\[expect\]/,/^\[hosts\]/{/^\[hosts\]/!d}'; }
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
  # A run's files are named uio<launcher pid>x…: another program's run on this machine may hold
  # some now. Ours have all ended here, so what a live launcher holds is not this test's.
  left=""
  for f in $new; do pid="${f#uio}"; pid="${pid%%x*}"; [ -d "/proc/$pid" ] || left="$left $f"; done
  [ -z "$left" ] || fail "shared memory left:$left"
}

now() { date +%s.%N; }

# The intruder on A, with the given credentials.
mine=(--ca "$work/cred/ca.pem" --cert "$work/cred/launcher.pem" --key "$work/cred/launcher.key")
other=(--ca "$work/other/ca.pem" --cert "$work/other/launcher.pem" --key "$work/other/launcher.key")
intrude() { ip netns exec "$nsa" "$intruder" "$@"; }

# A run on A in the background: $1 its scenario, $2 its output folder, $3.. more arguments;
# its pid in $started.
start_run() {
  local toml="$1" out="$2"; shift 2
  ip netns exec "$nsa" env UIO_RUNS_DIR="$work/a" RUST_LOG="${AGENT_LOG:-error}" "$launcher" run "$toml" --out "$out" --force "$@" >"$out/launcher.out" 2>"$out/launcher.err" &
  started=$!
}

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
      pgrep -f "^$bin/uio-plant --run" >/dev/null && break
      sleep 0.05
    done
    sleep 1.5
    kill -0 "$run_pid" 2>/dev/null || fail "the run ended before the fault"
    t0="$(now)"
    case "$case_name" in
      kill-component) pkill -KILL -f "^$bin/uio-plant --run" || fail "no plant on B" ;;
      kill-agent) kill -KILL "$agent_pid"; agent_pid="" ;;
      cut-link) ip -n "$nsa" link set "$va" down ;;
      kill-local) pkill -KILL -f "^$bin/uio-controller --run" || fail "no controller on A" ;;
    esac
    rc=0; wait "$run_pid" || rc=$?
    t1="$(now)"
    took="$(python3 -c "print(f'{$t1 - $t0:.2f}')")"
    [ "$rc" -eq 3 ] || fail "uio-launcher run exited $rc, not 3"
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
  insecure)
    scenario 2.0 | bare > "$work/two.toml"; single 2.0 | bare > "$work/one.toml"
    ip netns exec "$nsa" env UIO_RUNS_DIR="$work/a" "$launcher" run "$work/two.toml" --out "$work/out2" --force >"$work/launcher.out" 2>"$work/launcher.err" || fail "the --insecure TCP run failed"
    "$launcher" run "$work/one.toml" --out "$work/out1" --force >/dev/null 2>&1 || fail "the single-host run failed"
    "$launcher" compare "$work/out1/two-hosts.rrd" "$work/out2/two-hosts.rrd" >"$work/compare.out" 2>&1 || fail "$(cat "$work/compare.out")"
    check_clean
    echo "ok insecure: without --insecure: $(head -1 "$work/refusal.err"); with it: $(cat "$work/compare.out")"
    ;;
  refused)
    anon="$(intrude --ca "$work/cred/ca.pem" "$endpoint" open)"
    foreign="$(intrude "${other[@]}" "$endpoint" open)"
    plain="$(intrude "tcp/${endpoint#*/}" open)"
    tls="$(intrude "${mine[@]}" "tls/${endpoint#*/}" open)"
    for r in "$anon" "$foreign" "$plain" "$tls"; do [[ "$r" == refused* ]] || fail "a peer without the user's credentials got in: $r"; done
    # The launcher with another CA's credentials cannot reach the agent; with its own it runs.
    scenario 2.0 | bare > "$work/two.toml"
    rc=0; ip netns exec "$nsa" env UIO_RUNS_DIR="$work/a" UIO_CREDENTIALS="$work/other" "$launcher" run "$work/two.toml" --out "$work/out2" --force >/dev/null 2>"$work/foreign.err" || rc=$?
    [ "$rc" -eq 3 ] && grep -q "cannot reach its agent" "$work/foreign.err" || fail "a launcher with another CA's certificate: exit $rc: $(tail -2 "$work/foreign.err")"
    ip netns exec "$nsa" env UIO_RUNS_DIR="$work/a" "$launcher" run "$work/two.toml" --out "$work/out2" --force >/dev/null 2>"$work/launcher.err" || fail "the agent no longer serves its own launcher"
    check_clean
    echo "ok refused: no certificate: $anon; another CA's: $foreign; plain TCP: $plain; tls/ with the right certificate: $tls; launcher with another CA's: $(grep -m1 'cannot reach' "$work/foreign.err")"
    ;;
  attacks)
    # A paced run (40 s) that every attack below happens during; its recording must come out as
    # a single-host run's, bit for bit.
    scenario 40.0 | bare > "$work/two.toml"; single 40.0 | bare > "$work/one.toml"
    start_run "$work/two.toml" "$work/out2" --realtime; run_pid=$started
    for _ in $(seq 200); do grep -q "worker for plant: this host" "$work/agent.err" 2>/dev/null && break; sleep 0.05; done
    sleep 0.5
    # 1. Subscribing to everything is refused; to a run's outputs gives only sealed bytes.
    all="$(intrude "${mine[@]}" "$endpoint" listen 'uio/**' 1.5)"
    outs="$(intrude "${mine[@]}" "$endpoint" listen 'uio/run/*/c/*/out' 1.5)"
    [[ "$all" == "received 0 "* ]] || fail "a subscriber to uio/** got: $all"
    read -r _ n _ plain _ key <<<"$outs"
    [ "$n" -gt 0 ] && [ "$plain" -eq 0 ] || fail "a run's outputs as another launcher sees them: $outs"
    run="$(echo "$key" | cut -d/ -f3)"
    # 2. Forged inputs for the plant and a forged status: refused, the run goes on.
    forged_in="$(intrude "${mine[@]}" "$endpoint" put "uio/run/$run/c/plant/in/controller" 300 1)"
    forged_status="$(intrude "${mine[@]}" "$endpoint" put "uio/run/$run/c/plant/status" 5 0)"
    # 3. A start request for run '**', and one for the running run's plant: refused by name.
    cp "$(ls -d "$work"/a/*/ | head -1)plant.json" "$work/plant.json"
    wild="$(intrude "${mine[@]}" "$endpoint" start rig '**' "$work/plant.json")"
    again="$(intrude "${mine[@]}" "$endpoint" start rig "$run" "$work/plant.json")"
    [[ "$wild" == "reply err: "*"not a run id"* ]] || fail "a start for run '**': $wild"
    [[ "$again" == "reply err: "*"already has"* ]] || fail "a second start for the running plant: $again"
    # … and one whose plant would publish 10⁹ values a sample, or read a service named '**'.
    python3 -c 'import json,sys; c=json.load(open(sys.argv[1])); c["publishes"]["len"]=10**9; json.dump(c,open(sys.argv[2],"w"))' "$work/plant.json" "$work/huge.json"
    python3 -c 'import json,sys; c=json.load(open(sys.argv[1])); c["reads"][0]["service"]="**"; json.dump(c,open(sys.argv[2],"w"))' "$work/plant.json" "$work/wildsvc.json"
    huge="$(intrude "${mine[@]}" "$endpoint" start rig 1x0x1 "$work/huge.json")"
    wildsvc="$(intrude "${mine[@]}" "$endpoint" start rig 1x0x2 "$work/wildsvc.json")"
    [[ "$huge" == "reply err: "*"at most"* ]] || fail "a start with 10⁹ values a sample: $huge"
    [[ "$wildsvc" == "reply err: "*"not a service name"* ]] || fail "a start reading service '**': $wildsvc"
    # 4. A queryable that would intercept start requests: refused, so it sees none.
    intrude "${mine[@]}" "$endpoint" queryable 'uio/agent/rig/start' 2 >"$work/queryable.out" &
    qpid=$!
    sleep 0.5
    after="$(intrude "${mine[@]}" "$endpoint" start rig 1x0x3 "$work/plant.json")"
    wait "$qpid"
    [ "$(cat "$work/queryable.out")" = "intercepted 0" ] || fail "a queryable on the agent's key: $(cat "$work/queryable.out")"
    # 5. One 200 MB query: dropped (the limit is 128 MiB); the agent stays small.
    big="$(intrude "${mine[@]}" "$endpoint" big rig 200)"
    rss_kb="$(awk '/VmRSS/ {print $2}' "/proc/$agent_pid/status")"
    [ "$rss_kb" -lt 262144 ] || fail "the agent holds $rss_kb kB after a 200 MB query"
    # 6. Twelve start requests: at most --max-workers (4) components at once, the run's two
    # included.
    for i in $(seq 12); do intrude "${mine[@]}" "$endpoint" start rig "2x${i}x1" "$work/plant.json"; done >"$work/flood.out"
    workers="$(ip netns pids "$nsb" | xargs -r ps -o args= -p | grep -c 'uio-bridge worker' || true)"
    [ "$workers" -le 4 ] || fail "$workers workers after a flood of start requests (the limit is 4)"
    grep -q "already has" "$work/flood.out" && fail "unexpected: $(cat "$work/flood.out")"
    refused_flood="$(grep -c 'runs 4 components already' "$work/flood.out" || true)"
    [ "$refused_flood" -ge 9 ] || fail "only $refused_flood of 12 start requests refused at the limit: $(sort "$work/flood.out" | uniq -c)"
    sleep 5.5  # the flood's workers give up waiting for proxies that never come (5 s)
    # 7. 200 peers that open a connection and say nothing more (junk QUIC datagrams from 200
    # ports, again and again): a second run started meanwhile still gets through.
    ip netns exec "$nsa" python3 -c '
import os, socket, time
s = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(200)]
end = time.time() + 6
while time.time() < end:
    for x in s: x.sendto(bytes([0xc3]) + os.urandom(1199), ("10.77.0.2", 7447))
    time.sleep(0.05)' >"$work/idle.out" &
    idle_pid=$!
    sleep 1
    scenario 1.0 | bare | sed '0,/^name = .*/s//name = "during-flood"/' > "$work/flood.toml"
    rc=0; ip netns exec "$nsa" env UIO_RUNS_DIR="$work/a" "$launcher" run "$work/flood.toml" --out "$work/out3" --force >/dev/null 2>"$work/flood-run.err" || rc=$?
    kill "$idle_pid" 2>/dev/null || true; wait "$idle_pid" 2>/dev/null || true
    kill -0 "$run_pid" 2>/dev/null || fail "the attacked run ended before the last attack"
    [ "$rc" -eq 0 ] || fail "a run during 200 junk peers exited $rc: $(tail -2 "$work/flood-run.err")"
    rc=0; wait "$run_pid" || rc=$?
    [ "$rc" -eq 0 ] || { tail -3 "$work/out2/launcher.err"; fail "the attacked run exited $rc"; }
    "$launcher" run "$work/one.toml" --out "$work/out1" --force >/dev/null 2>&1 || fail "the single-host run failed"
    "$launcher" compare "$work/out1/two-hosts.rrd" "$work/out2/two-hosts.rrd" >"$work/compare.out" 2>&1 || fail "the attacked run differs: $(cat "$work/compare.out")"
    check_clean
    ignored="$(grep -c 'ignored a message' "$work/agent.err" || true)"
    [ "$ignored" -ge 1 ] || fail "the forged inputs were not refused by the plant's worker (no 'ignored a message' on B)"
    echo "ok attacks: uio/**: $all; outputs: $outs; forged: $forged_in, $forged_status (ignored-message reports on B: $ignored); start '**': $wild; start again: $again; 10⁹ values: $huge; service '**': $wildsvc; queryable: $(cat "$work/queryable.out") (start meanwhile: $after); 200 MB query: $big, agent RSS $((rss_kb / 1024)) MB; flood of 12 starts: $refused_flood refused, $workers workers; during 200 junk QUIC peers a run passed; the attacked run: $(cat "$work/compare.out")"
    ;;
  concurrent)
    scenario 10.0 | bare > "$work/two.toml"
    scenario 10.0 | bare | sed '0,/^name = .*/s//name = "two-hosts-b"/' > "$work/two-b.toml"
    start_run "$work/two.toml" "$work/out2"; p1=$started
    start_run "$work/two-b.toml" "$work/out3" --wait block; p2=$started
    r1=0; wait "$p1" || r1=$?
    r2=0; wait "$p2" || r2=$?
    [ "$r1" -eq 0 ] && [ "$r2" -eq 0 ] || fail "two runs at once exited $r1 and $r2: $(tail -2 "$work/out2/launcher.err") / $(tail -2 "$work/out3/launcher.err")"
    single 10.0 | bare > "$work/one.toml"
    "$launcher" run "$work/one.toml" --out "$work/out1" --force >/dev/null 2>&1 || fail "the single-host run failed"
    "$launcher" compare "$work/out1/two-hosts.rrd" "$work/out2/two-hosts.rrd" >"$work/compare.out" 2>&1 || fail "run A differs: $(cat "$work/compare.out")"
    check_clean
    echo "ok concurrent: both runs passed (A: the default wait, B: --wait block); run A: $(cat "$work/compare.out")"
    ;;
  *) echo "usage: $0 run|kill-component|kill-agent|cut-link|kill-local|refused|attacks|concurrent|insecure"; exit 2 ;;
esac
