#!/usr/bin/env bash
# Renders a recording in the real Rerun viewer under a private Xvfb and saves a PNG.
#
#   scripts/viewer-screenshot.sh FILE.rrd OUT.png [WIDTHxHEIGHT]
#
# WIDTHxHEIGHT is the viewer window in logical points (default 1600x1000); the viewer's
# own --screenshot-to renders at 2 pixels per point, so the PNG is twice that in pixels.
# The recording's blueprint decides the layout, timeline and play state.
#
# Finds the viewer as $RERUN, else `rerun` on PATH (the rerun-sdk pip package ships it,
# same version as the SDK that wrote the file: `pip install rerun-sdk==0.36.3`). Set RERUN
# for this command only: the SDKs read an exported RERUN as their on/off switch (a path there
# draws a warning and is ignored), and RERUN=on/off here falls back to PATH.
# Installs nothing. Debian packages it needs:
#   xvfb                 Xvfb
#   mesa-vulkan-drivers  lavapipe, the software Vulkan the viewer renders with (the GL
#                        backend on llvmpipe fails: "does not support ... R32Float")
# VIEWER_TIMEOUT: seconds to wait for the PNG (default 120). VIEWER_KEEP_LOG=FILE: copy the
# viewer's output there.
#
# How: Xvfb picks a free display (-displayfd); the screen is made 4x the window so the
# pointer, which X puts at the screen's centre, is outside the (2x-enlarged) window and
# no hover tooltip lands in the picture. The viewer runs with --port auto (otherwise it
# would hand the file to any viewer already listening on 9876) and RUST_LOG=error (no
# notification toasts over the views). It takes its screenshot about ten frames after
# start, so a very large file may not be fully loaded yet. After saving it panics on the
# way out (exit 102 in 0.36.3): success is judged by the PNG alone. Everything started
# here runs in its own process group and is killed on exit.
set -u

die() { echo "viewer-screenshot: $*" >&2; exit 1; }

[ $# -ge 2 ] && [ $# -le 3 ] || die "usage: $0 FILE.rrd OUT.png [WIDTHxHEIGHT]"
file=$1 out=$2 size=${3:-1600x1000}
[[ $size =~ ^([0-9]+)x([0-9]+)$ ]] || die "size must be WIDTHxHEIGHT, got '$size'"
w=${BASH_REMATCH[1]} h=${BASH_REMATCH[2]}
[ -r "$file" ] || die "cannot read $file"
# (The viewer shows an empty window, and logs nothing, for a file it cannot decode.)
[ "$(head -c 4 "$file")" = RRF2 ] || die "$file is not a Rerun recording (no RRF2 header)"
# The Rerun SDKs read RERUN too, as an on/off switch for logging: such a value is not a path.
rerun=${RERUN:-}
case ${rerun,,} in ''|on|off|true|false|yes|no|0|1) rerun=$(command -v rerun || true) ;; esac
[ -n "$rerun" ] && [ -x "$rerun" ] && [ ! -d "$rerun" ] || die "no rerun viewer: set \$RERUN to its path or put rerun on PATH"
command -v Xvfb >/dev/null || die "no Xvfb (apt-get install xvfb)"
case $out in /*) ;; *) out=$PWD/$out ;; esac
case $file in /*) ;; *) file=$PWD/$file ;; esac
[ -d "$(dirname "$out")" ] || die "no directory $(dirname "$out")"
timeout_s=${VIEWER_TIMEOUT:-120}

tmp=$(mktemp -d /tmp/viewer-screenshot.XXXXXX) || die "mktemp failed"
xvfb_pid='' viewer_pid=''
cleanup() {
    # Each was started with setsid, so its pid is its process group.
    for p in $viewer_pid $xvfb_pid; do
        kill -TERM -- "-$p" 2>/dev/null
    done
    for p in $viewer_pid $xvfb_pid; do
        for _ in 1 2 3 4 5 6 7 8 9 10; do kill -0 -- "-$p" 2>/dev/null || break; sleep 0.2; done
        kill -KILL -- "-$p" 2>/dev/null
        wait "$p" 2>/dev/null
    done
    [ -n "${VIEWER_KEEP_LOG:-}" ] && cp "$tmp/viewer.log" "$VIEWER_KEEP_LOG" 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# The display number Xvfb chose is written to fd 3.
setsid Xvfb -displayfd 3 -screen 0 "$((4 * w + 64))x$((4 * h + 64))x24" -nolisten tcp -noreset \
    3>"$tmp/display" >"$tmp/xvfb.log" 2>&1 &
xvfb_pid=$!
for _ in $(seq 100); do
    [ -s "$tmp/display" ] && break
    kill -0 "$xvfb_pid" 2>/dev/null || die "Xvfb failed: $(tail -n 3 "$tmp/xvfb.log" | tr '\n' ' ')"
    sleep 0.1
done
display=$(tr -dc 0-9 <"$tmp/display")
[ -n "$display" ] || die "Xvfb did not report a display within 10 s"

rm -f "$out"
mkdir -m 700 "$tmp/xdg" "$tmp/home"
(
    cd "$tmp" || exit 1
    export DISPLAY=":$display" HOME="$tmp/home" XDG_RUNTIME_DIR="$tmp/xdg" RUST_LOG=error
    exec setsid "$rerun" --port auto --hide-welcome-screen --renderer vulkan \
        --window-size "${w}x${h}" --screenshot-to "$out" "$file"
) >"$tmp/viewer.log" 2>&1 &
viewer_pid=$!

# The viewer quits by itself after saving; wait for that or the timeout.
# (Up to 5 s more once the PNG exists, so it is not cut off mid-write.)
waited=0 grace=0
while kill -0 "$viewer_pid" 2>/dev/null; do
    if [ -s "$out" ]; then grace=$((grace + 1)); [ "$grace" -ge 25 ] && break; fi
    [ "$waited" -ge "$((timeout_s * 5))" ] && break
    sleep 0.2
    waited=$((waited + 1))
done

if [ -s "$out" ] && [ "$(head -c 8 "$out" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ]; then
    exit 0
fi
reason=$(grep -m1 -iE 'error|panic' "$tmp/viewer.log" | sed 's/\x1b\[[0-9;]*m//g' | cut -c1-200)
if kill -0 "$viewer_pid" 2>/dev/null; then
    die "no screenshot after ${timeout_s} s${reason:+ ($reason)}"
fi
die "viewer exited without a screenshot${reason:+: $reason}"
