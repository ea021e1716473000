//! `uio-launcher bench --states N[,N…]`: how the cost of a step grows with the model. For each n, a
//! random stable plant (seeded, so every call measures the same plants) with a Chen–Patton UIO
//! and a Luenberger observer in closed loop runs for the benchmark's steps in each mode; the
//! table gives steps/s, the step's p50 and, with recording, the bytes written per step.
//!
//! The plant: A = −2I + R/√n (R standard normal: eigenvalues near −2, within about ±1), B with 2
//! columns, C n×n (every state measured, as on a sensor-dense FE or thermal model), E one column
//! — generic, so rank CE = rank E and (A, E, C) has no invariant zeros. Observer poles
//! −3 − 0.05·i; the feedback is a small random gain G = 0.1·R/√n (placing n poles with two inputs
//! is ill-conditioned for large n, and the step costs the same whatever G is).
//!
//! Why p = n: with p = n the observer placements are direct (K = Cᵀ⁻¹-like, O(n³)), so the
//! designs reach n = 1000. With p < n, robust eigenstructure assignment (Tits–Yang) is O(n⁵) per
//! sweep here and stops near n = 50–100 (BENCHMARKS.md).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::Serialize;

use lockstep::Wait;
use scenario::Scenario;

use crate::error::LaunchError;
use crate::plan::plan;
use crate::run::Mode;

/// One (n, mode, recording) measurement.
#[derive(Debug, Clone, Serialize)]
pub struct StatesRun {
    /// States.
    pub n: usize,
    /// Mode.
    pub mode: String,
    /// Recorded.
    pub recording: bool,
    /// Steps per second.
    pub steps_per_s: f64,
    /// Step p50, ns.
    pub step_p50_ns: u64,
    /// Bytes of `.rrd` per step (recorded runs).
    pub bytes_per_step: Option<f64>,
    /// Wall time of the designs (UIO, Luenberger, feedback), s.
    pub design_s: f64,
}

fn rows(m: &[Vec<f64>]) -> String {
    let r: Vec<String> = m
        .iter()
        .map(|row| {
            format!(
                "[{}]",
                row.iter()
                    .map(|v| format!("{v:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
        .collect();
    format!("[{}]", r.join(", "))
}

fn poles(n: usize, base: f64) -> String {
    (0..n)
        .map(|i| format!("{:?}", base - 0.05 * i as f64))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The scenario text for n states, `steps` steps of 1 ms.
pub fn scenario_text(n: usize, steps: u64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
    let mut normal = |r: usize, c: usize| -> Vec<Vec<f64>> {
        (0..r)
            .map(|_| {
                (0..c)
                    .map(|_| rng.sample::<f64, _>(StandardNormal))
                    .collect()
            })
            .collect()
    };
    let scale = 1.0 / (n as f64).sqrt();
    let mut a = normal(n, n);
    for (i, row) in a.iter_mut().enumerate() {
        for v in row.iter_mut() {
            *v *= scale;
        }
        row[i] -= 2.0;
    }
    let (b, c, e) = (normal(n, 2), normal(n, n), normal(n, 1));
    let g: Vec<Vec<f64>> = normal(2, n)
        .into_iter()
        .map(|r| r.into_iter().map(|v| 0.1 * v * scale).collect())
        .collect();
    format!(
        r#"name = "states-{n}"
dt = 0.001
duration = {duration:?}
[plant]
A = {a}
B = {b}
C = {c}
E = {e}
x0 = [{x0}]
[[disturbance]]
kind = "sine"
amplitude = 1.0
frequency_hz = 0.5
[[input]]
kind = "constant"
value = 0.0
[[input]]
kind = "step"
time = 0.01
before = 0.0
after = 0.1
[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [{po}]
[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [{po}]
[controller]
kind = "state-feedback"
observer = "uio"
gain = {g}
"#,
        duration = steps as f64 * 0.001,
        a = rows(&a),
        b = rows(&b),
        c = rows(&c),
        e = rows(&e),
        x0 = vec!["0.1"; n].join(", "),
        po = poles(n, -3.0),
        g = rows(&g),
    )
}

/// Measures each n in `states` for `steps` steps in `modes` × `recording`.
pub fn states(
    states: &[usize],
    steps: u64,
    wait: Wait,
    pin: bool,
    modes: &[Mode],
    recording: &[bool],
) -> Result<Vec<StatesRun>, LaunchError> {
    let tmp = std::env::temp_dir().join(format!("uio-bench-states-{}", std::process::id()));
    let mut out = Vec::new();
    for &n in states {
        if n == 0 {
            return Err(LaunchError::BadInput(
                "--states: a plant has at least one state".into(),
            ));
        }
        let text = scenario_text(n, steps);
        let s = Scenario::parse(std::path::Path::new(&format!("states-{n}.toml")), &text)?;
        let t = std::time::Instant::now();
        let p = plan(&s).map_err(|e| LaunchError::Scenario(e.error))?;
        let design_s = t.elapsed().as_secs_f64();
        for &mode in modes {
            for &record in recording {
                let o = super::measure::measure(&s, &p, &tmp, mode, wait, record, pin)?;
                let bytes = o
                    .rrd
                    .as_ref()
                    .and_then(|f| std::fs::metadata(f).ok())
                    .map(|m| m.len() as f64 / o.summary.steps.max(1) as f64);
                out.push(StatesRun {
                    n,
                    mode: mode.name().into(),
                    recording: record,
                    steps_per_s: o.summary.steps_per_s,
                    step_p50_ns: o.summary.latency_ns.step.p50,
                    bytes_per_step: bytes,
                    design_s,
                });
            }
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    Ok(out)
}

/// The printed table.
pub fn table(runs: &[StatesRun]) -> String {
    let mut t = format!(
        "{:>6} {:<12} {:<10} {:>12} {:>10} {:>12} {:>9}\n",
        "n", "mode", "recording", "steps/s", "p50 µs", "bytes/step", "design s"
    );
    for r in runs {
        t += &format!(
            "{:>6} {:<12} {:<10} {:>12.0} {:>10.2} {:>12} {:>9.2}\n",
            r.n,
            r.mode,
            r.recording,
            r.steps_per_s,
            r.step_p50_ns as f64 / 1000.0,
            r.bytes_per_step
                .map_or_else(|| "—".into(), |b| format!("{b:.0}")),
            r.design_s
        );
    }
    t
}
