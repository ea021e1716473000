//! `launcher bench`: the seed-002 closed loop (plant, two observers, controller) for N steps,
//! in one process and across processes, with and without recording.

use std::path::Path;

use lockstep::Wait;
use serde::Serialize;

use crate::error::LaunchError;
use crate::plan::plan;
use recording::write::Percentiles;
use crate::run::{run, Mode, Options, Stop};
use scenario::Scenario;

/// One benchmark run.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRun {
    /// "processes" or "in-process".
    pub mode: String,
    /// Whether the .rrd was written.
    pub recording: bool,
    /// Steps run.
    pub steps: u64,
    /// Steps per second of wall time.
    pub steps_per_s: f64,
    /// Full-step latency, ns.
    pub step_ns: Percentiles,
}

/// Runs the benchmark on `scenario` (seed002-sine) for `steps` steps.
pub fn bench(scenario: &Path, steps: u64, wait: Wait, pin: bool, modes: &[Mode], recording: &[bool]) -> Result<Vec<BenchRun>, LaunchError> {
    let mut s = Scenario::load(scenario)?;
    s.steps = steps;
    s.duration = steps as f64 * s.dt;
    s.expect = Default::default();
    let p = plan(&s).map_err(|e| LaunchError::Scenario(e.error))?;
    let tmp = std::env::temp_dir().join(format!("uio-bench-{}", std::process::id()));
    let mut out = Vec::new();
    for &mode in modes {
        for &record in recording {
            let opts = Options { out: tmp.clone(), mode, wait, force: true, allow_unstable: false, record, pin, select: Default::default(), progress: false };
            let o = run(&s, &p, &opts)?;
            if o.stop != Stop::Completed {
                return Err(LaunchError::Component(format!("benchmark run stopped: {:?}", o.stop)));
            }
            out.push(BenchRun {
                mode: mode.name().into(),
                recording: record,
                steps: o.summary.steps,
                steps_per_s: o.summary.steps_per_s,
                step_ns: o.summary.latency_ns.step,
            });
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    Ok(out)
}

/// The printed table.
pub fn table(runs: &[BenchRun], wait: Wait) -> String {
    let mut t = format!("seed002 closed loop (plant, 2 observers, controller), wait = {wait}\n");
    t += &format!("{:<12} {:<10} {:>10} {:>14} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "mode", "recording", "steps", "steps/s", "p50 µs", "p90 µs", "p99 µs", "p99.9 µs", "max µs");
    for r in runs {
        let us = |ns: u64| format!("{:.2}", ns as f64 / 1000.0);
        t += &format!(
            "{:<12} {:<10} {:>10} {:>14.0} {:>9} {:>9} {:>9} {:>9} {:>9}\n",
            r.mode,
            r.recording,
            r.steps,
            r.steps_per_s,
            us(r.step_ns.p50),
            us(r.step_ns.p90),
            us(r.step_ns.p99),
            us(r.step_ns.p999),
            us(r.step_ns.max)
        );
    }
    let rate = |m: &str, rec: bool| runs.iter().find(|r| r.mode == m && r.recording == rec).map(|r| r.steps_per_s);
    if let (Some(p), Some(i)) = (rate("processes", false), rate("in-process", false)) {
        t += &format!("processes / in-process steps/s (no recording): {:.3}\n", p / i);
    }
    for m in ["in-process", "processes"] {
        if let (Some(a), Some(b)) = (rate(m, true), rate(m, false)) {
            t += &format!("{m}: recording costs {:.1} % of steps/s\n", 100.0 * (1.0 - a / b));
        }
    }
    t
}
