#!/usr/bin/env python3
"""Step latency with an FMU plant beside the built-in plant's, in the same session (BENCHMARKS.md):
seed 002 as the discrete plant of its exact ZOH (scipy), once simulated by the built-in
plant and once by the lti_plant test FMU (FMI 2.0 and 3.0) given the same Φ, Γ_B, Γ_E, across
processes without recording, interleaved, REPS times each; prints each run's step latency
percentiles and steps/s and the medians with the FMU/built-in ratios.

    scripts/fmu-latency.py FMU_DIR [STEPS] [REPS]
      FMU_DIR: where fmu/testfmus/build.sh put the test FMUs; STEPS default 100000, REPS 3.
    (the launcher: $CARGO_TARGET_DIR/release/uio-launcher, else target/release/uio-launcher)
"""

import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python" / "tests"))
from test_fmu_plant import discrete_seed002, lti_table  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
LAUNCHER = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target") / "release" / "uio-launcher"


def run(scenario, out):
    done = subprocess.run([str(LAUNCHER), "run", str(scenario), "--out", str(out), "--force"], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(done.stderr)
    s = json.loads(next(Path(out).glob("*.summary.json")).read_text())
    return s["latency_ns"]["step"], s["steps_per_s"]


def main():
    fmu_dir = Path(sys.argv[1])
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else 100_000
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    tmp = Path(tempfile.mkdtemp(prefix="fmulat"))
    plants = {"built-in": ""}
    plants.update({f"FMU FMI {v}": lti_table(fmu_dir / f"lti_plant_fmi{v}.fmu") for v in (2, 3)})
    files = {}
    for name, table in plants.items():
        text = discrete_seed002(table).replace("duration = 20.0", f"duration = {steps * 0.001}")
        f = tmp / (name.replace(" ", "_") + ".toml")
        f.write_text(text)
        files[name] = f
    got = {name: [] for name in plants}
    for r in range(reps):
        for name, f in files.items():
            lat, rate = run(f, tmp / "out")
            got[name].append((lat, rate))
            print(f"rep {r + 1} {name:>10}: p50 {lat['p50']} ns, p99 {lat['p99']} ns, p99.9 {lat['p999']} ns, {rate:,.0f} steps/s")
    med = {name: {k: statistics.median(x[0][k] for x in v) for k in ("p50", "p99", "p999")} | {"rate": statistics.median(x[1] for x in v)} for name, v in got.items()}
    base = med["built-in"]
    for name, m in med.items():
        print(f"median {name:>10}: p50 {m['p50']:.0f} ns ({m['p50'] / base['p50']:.2f}×), p99 {m['p99']:.0f} ns ({m['p99'] / base['p99']:.2f}×), "
              f"p99.9 {m['p999']:.0f} ns ({m['p999'] / base['p999']:.2f}×), {m['rate']:,.0f} steps/s ({m['rate'] / base['rate']:.2f}×)")


if __name__ == "__main__":
    main()
