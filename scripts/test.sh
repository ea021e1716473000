#!/usr/bin/env bash
# The project's test command: system packages, every binary, every test — one cargo profile
# (release) for building and testing, so nothing compiles twice.
set -euo pipefail
cd "$(dirname "$0")/.."

# The Hui–Żak LMI path (feature observer/lmi) links the system OpenBLAS, which needs gfortran's
# runtime to link against. Debian package names; installed once per machine.
need=()
ldconfig -p | grep -q 'libopenblas\.so ' || need+=(libopenblas-dev)
ldconfig -p | grep -q 'libgfortran\.so ' || need+=(libgfortran-12-dev)
if [ ${#need[@]} -gt 0 ]; then
  echo "installing ${need[*]} (for the LMI design path)"
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get install -y --no-install-recommends "${need[@]}" >/dev/null \
    || { $sudo apt-get update >/dev/null && $sudo apt-get install -y --no-install-recommends "${need[@]}" >/dev/null; }
fi

# The multi-process tests start the component binaries: build them all first.
cargo build --release --workspace --bins

log=$(mktemp)
trap 'rm -f "$log"' EXIT
cargo test --release --workspace 2>&1 | tee "$log"
# The same design tests with the LMI solver compiled in.
cargo test --release -p observer --features lmi 2>&1 | tee -a "$log"

# One closing line for the whole suite.
awk '/^test result:/ { p += $4; f += $6 } END { printf "tests: %d passed, %d failed\n", p, f }' "$log"
