#!/usr/bin/env bash
# The project's test command: system packages, every binary, every test — one cargo profile
# (release) for building and testing, so nothing compiles twice.
set -euo pipefail
cd "$(dirname "$0")/.."

# The Hui–Żak LMI path (feature observer/lmi) links the system OpenBLAS, which needs gfortran's
# runtime to link against. Debian package names; installed once per machine.
# The FMU plant (fmu/plant) imports FMUs through the `fmi` crate, whose FFI bindings bindgen
# makes at build time from libclang.
need=()
ldconfig -p | grep -q 'libopenblas\.so ' || need+=(libopenblas-dev)
ldconfig -p | grep -q 'libgfortran\.so ' || need+=(libgfortran-12-dev)
ldconfig -p | grep -Eq 'libclang(-[0-9.]+)?\.so ' || need+=(libclang-dev)
if [ ${#need[@]} -gt 0 ]; then
  echo "installing ${need[*]} (for the LMI design path and the FMU import's bindings)"
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get install -y --no-install-recommends "${need[@]}" >/dev/null \
    || { $sudo apt-get update >/dev/null && $sudo apt-get install -y --no-install-recommends "${need[@]}" >/dev/null; }
fi

# The Python kit (python/) and the Python components (components/) run in a virtual
# environment the script makes itself (pip from PyPI): made once, and again when the kit
# changes. Its bin/ goes first on PATH, so the launcher's `python3` is the environment's.
venv="${UIO_VENV:-$PWD/.venv}"
stamp="$venv/.uio-installed"
"$venv/bin/python3" -c 'import fmpy' 2>/dev/null || rm -f "$stamp"  # test FMUs: fmpy
"$venv/bin/python3" -c 'import mcap' 2>/dev/null || rm -f "$stamp"  # export --mcap read back
"$venv/bin/python3" -c 'import control, maturin' 2>/dev/null || rm -f "$stamp"  # the Python package
"$venv/bin/python3" -c 'import rerun' 2>/dev/null || rm -f "$stamp"  # `rerun rrd verify` on our recordings
"$venv/bin/python3" -c 'import pythonfmu' 2>/dev/null || rm -f "$stamp"  # a third-party exporter's FMUs
"$venv/bin/python3" -c 'import dask, distributed' 2>/dev/null || rm -f "$stamp"  # sweeps on Dask workers
if [ ! -x "$venv/bin/python3" ] || [ ! -e "$stamp" ] \
   || [ -n "$(find python/pyproject.toml python/uio_component -newer "$stamp" -print -quit)" ]; then
  if ! python3 -c 'import ensurepip, venv' 2>/dev/null; then
    echo "installing python3-venv (for the Python kit's environment)"
    sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get install -y --no-install-recommends python3-venv >/dev/null \
      || { $sudo apt-get update >/dev/null && $sudo apt-get install -y --no-install-recommends python3-venv >/dev/null; }
  fi
  echo "preparing the Python environment $venv"
  [ -x "$venv/bin/python3" ] || python3 -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check ./python pytest scipy fmpy mcap maturin control rerun-sdk==0.36.3 pythonfmu dask distributed  # dask, distributed: the Python package's sweeps on Dask workers; pythonfmu: FMUs from a third-party exporter; fmpy: test FMUs; mcap: export, maturin and control: the Python package; rerun-sdk: Rerun's own CLI checks our recordings
  touch "$stamp"
fi
export PATH="$venv/bin:$PATH"

# One formatting (rustfmt.toml), checked before anything is built: `cargo fmt --all` fixes it.
cargo fmt --all --check >/dev/null || { echo "cargo fmt --all --check: the sources are not formatted (run cargo fmt --all)"; exit 1; }
# No import circle between the files of a crate (each file's uses resolved to the file that
# defines the item).
python3 scripts/check-imports.py
# No function over 120 lines outside tests, unless a `// one job:` comment says why it is one.
python3 scripts/check-functions.py

# The multi-process tests start the component binaries: build them all first.
cargo build --release --workspace --bins
# The observer FMUs' library (a cdylib, which --bins does not build), for `uio-launcher export-fmu`.
cargo build --release -p fmu-observer
# Lints on every target of the workspace (and the LMI design path), warnings as errors.
cargo clippy --release --workspace --all-targets -- -D warnings
cargo clippy --release -p observer --all-targets --features lmi -- -D warnings
# The Python package on the design library (pyuio/, PyO3): maturin builds it with cargo, in
# this target directory, and installs it in the environment; unchanged sources rebuild nothing.
"$venv/bin/pip" install -q --disable-pip-version-check --no-build-isolation ./pyuio

log=$(mktemp)
trap 'rm -f "$log"' EXIT
cargo test --release --workspace 2>&1 | tee "$log"
# The same design tests with the LMI solver compiled in.
cargo test --release -p observer --features lmi 2>&1 | tee -a "$log"

# test FMUs: FMI 2.0/3.0 co-simulation FMUs from fmu/testfmus, for test_fmu_testfmus.py,
# and one made by a third-party exporter from PyPI, pythonfmu
export UIO_TEST_FMUS="${CARGO_TARGET_DIR:-$PWD/target}/testfmus"; fmu/testfmus/build.sh "$UIO_TEST_FMUS"

# The Python kit and components.
python -m pytest -q python/tests 2>&1 | tee -a "$log"

# One closing line for the whole suite: cargo's `test result:` lines and pytest's summary. A
# cargo test that cannot run here says `skipped: <test>: <reason>` (tests::skip) and returns,
# which libtest counts as passed: those are taken out of the passed and counted apart, as
# pytest's own skips are.
awk '/^test result:/ { p += $4; f += $6 }
     /^skipped: / { s += 1; p -= 1 }
     /^[0-9]+ (passed|failed|skipped)/ || /^=+ .*[0-9]+ (passed|failed|skipped).* in [0-9.]+s/ {
       for (i = 2; i <= NF; i++) {
         if ($i ~ /^passed/) p += $(i - 1)
         if ($i ~ /^skipped/) s += $(i - 1)
         if ($i ~ /^(failed|errors?)/) f += $(i - 1)
       }
     }
     END { printf "tests: %d passed, %d skipped, %d failed\n", p, s, f }' "$log"
