#!/usr/bin/env bash
# Test FMUs: builds OUTDIR/{lti_plant,dc_motor,faulty}_{fmi2,fmi3}.fmu — FMI 2.0 and 3.0
# co-simulation FMUs for linux x86_64 — from the C sources next to this script, against the
# FMI headers that FMPy ships, and validates each with FMPy; and OUTDIR/three_tank.fmu, made
# by pythonfmu (a third-party exporter, PyPI) from python/three_tank.py. Idempotent (each FMU is rebuilt
# and replaced atomically); takes a second or two.
#
#   fmu/testfmus/build.sh OUTDIR        (PYTHON: a python with fmpy and pythonfmu; default python3)
set -euo pipefail

[ $# -eq 1 ] || { echo "usage: $0 OUTDIR" >&2; exit 2; }
src="$(cd "$(dirname "$0")" && pwd)"
mkdir -p "$1"
out="$(cd "$1" && pwd)"
py="${PYTHON:-python3}"
cc="${CC:-cc}"

headers="$("$py" -c 'import fmpy, os; print(os.path.join(os.path.dirname(fmpy.__file__), "c-code"))')"
[ -f "$headers/fmi2Functions.h" ] && [ -f "$headers/fmi3Functions.h" ] \
  || { echo "build.sh: no FMI headers in $headers" >&2; exit 1; }

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# -ffp-contract=off: no fused multiply-add, so lti_plant's sums round exactly as documented.
cflags=(-O2 -fPIC -ffp-contract=off -fvisibility=hidden -Wall -Wextra -Werror -I"$src" -I"$headers")

for model in lti_plant dc_motor faulty; do
  "$cc" "${cflags[@]}" -o "$tmp/describe_$model" "$src/describe.c" "$src/$model.c" -lm
  for fmi in 2 3; do
    if [ "$fmi" = 2 ]; then platform=linux64; else platform=x86_64-linux; fi
    dir="$tmp/${model}_fmi$fmi"
    mkdir -p "$dir/binaries/$platform"
    "$cc" -shared "${cflags[@]}" -o "$dir/binaries/$platform/$model.so" \
      "$src/$model.c" "$src/instance.c" "$src/fmi$fmi.c" -lm
    "$tmp/describe_$model" "$fmi" > "$dir/modelDescription.xml"
    (cd "$dir" && "$py" -m zipfile -c "$tmp/${model}_fmi$fmi.fmu" modelDescription.xml binaries)
  done
done

# Validate (schema, variables, model structure) and check each FMU's library has every FMI
# function FMPy loads, then put the FMUs in place.
"$py" - "$tmp"/*.fmu <<'EOF'
import sys
import fmpy
from fmpy.validation import validate_fmu

for path in sys.argv[1:]:
    problems = validate_fmu(path)
    if problems:
        sys.exit(f"{path}: " + "; ".join(problems))
    md = fmpy.read_model_description(path, validate=True)
    assert md.coSimulation is not None, path
    unzipdir = fmpy.extract(path, unzipdir=path[:-len(".fmu")] + "_extracted")
    fmu = fmpy.instantiate_fmu(unzipdir, md, fmi_type="CoSimulation")
    fmu.freeInstance()
EOF
# A third-party exporter's FMU: pythonfmu (PyPI) builds python/three_tank.py into an
# FMI 2.0 co-simulation FMU whose library embeds Python.
mkdir -p "$tmp/py"
"$py" -m pythonfmu build -f "$src/python/three_tank.py" -d "$tmp/py" >/dev/null
"$py" -c 'import fmpy, sys; fmpy.read_model_description(sys.argv[1], validate=True)' "$tmp/py/three_tank.fmu"
mv -f "$tmp"/py/three_tank.fmu "$tmp"/
mv -f "$tmp"/*.fmu "$out"/
echo "build.sh: $(cd "$out" && ls {lti_plant,dc_motor,faulty}_fmi{2,3}.fmu three_tank.fmu | tr '\n' ' ')in $out"
