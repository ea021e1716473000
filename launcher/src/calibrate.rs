//! Thresholds calibrated on fault-free runs (`calibrate = { runs = N, margin = m }`): before the
//! run, the scenario runs N times in-process without its faults and without a recording, with
//! seeds 2³² + S + r (S the run's seed), so that the calibration never sees the noise of the
//! run it calibrates; each residual's threshold is then m × the largest evaluation J it reached
//! on their decided steps. The same seed gives the same thresholds, in either mode.

use diagnosis::Threshold;

use crate::error::LaunchError;
use crate::plan::Plan;
use crate::run::{self, Mode, Options, Stop};
use scenario::Scenario;

/// Where calibration seeds start, above any seed a scenario is likely to name.
pub const SEED_OFFSET: u64 = 1 << 32;

/// The plan a run of `s` uses: its designs ([`crate::plan::plan`]) with the calibrated
/// thresholds set.
pub fn planned(s: &Scenario) -> Result<Plan, LaunchError> {
    let mut p = crate::plan::plan(s).map_err(|e| LaunchError::Scenario(e.error))?;
    calibrate(s, &mut p)?;
    Ok(p)
}

/// Sets every calibrated bank's thresholds in `plan`.
pub fn calibrate(s: &Scenario, plan: &mut Plan) -> Result<(), LaunchError> {
    let wanted: Vec<(usize, usize, f64)> = plan
        .banks
        .iter()
        .enumerate()
        .filter_map(|(i, b)| {
            if let Threshold::Calibrated { runs, margin } = b.spec.threshold {
                Some((i, runs, margin))
            } else {
                None
            }
        })
        .collect();
    let Some(most) = wanted.iter().map(|w| w.1).max() else {
        return Ok(());
    };
    let mut clean = s.clone();
    clean.faults.clear();
    clean.expect = Default::default();
    let opts = Options {
        allow_unstable: true,
        ..Options::quiet(
            &std::env::temp_dir(),
            Mode::InProcess,
            lockstep::Wait::default_for_machine(),
            false,
        )
    };
    let mut top: Vec<Vec<f64>> = plan
        .banks
        .iter()
        .map(|b| vec![f64::NEG_INFINITY; b.members.len()])
        .collect();
    for r in 0..most {
        clean.seed = SEED_OFFSET.wrapping_add(s.seed).wrapping_add(r as u64);
        let o = run::run(&clean, plan, &opts)?;
        if o.stop != Stop::Completed {
            let why = o.summary.stopped.unwrap_or_default();
            return Err(LaunchError::Component(format!(
                "{}: calibration realisation {} (seed {}) did not complete: {why}",
                s.name,
                r + 1,
                clean.seed
            )));
        }
        let figures = o.summary.diagnosis.map(|d| d.residuals).unwrap_or_default();
        for &(b, _, _) in wanted.iter().filter(|w| r < w.1) {
            for (t, m) in top[b].iter_mut().zip(&plan.banks[b].members) {
                // A residual's figures carry its member's name.
                if let Some(v) = figures
                    .iter()
                    .find(|f| f.residual == m.name)
                    .and_then(|f| f.max_fault_free_evaluation)
                {
                    *t = t.max(v);
                }
            }
        }
    }
    for &(b, _, margin) in &wanted {
        for (j, m) in plan.banks[b].members.iter_mut().enumerate() {
            if !top[b][j].is_finite() {
                return Err(LaunchError::BadInput(format!(
                    "{}: diagnoser '{}': calibration saw no decided fault-free step (ignore_before is past the end of the run)",
                    s.path.display(),
                    plan.banks[b].spec.name
                )));
            }
            m.threshold = margin * top[b][j];
        }
    }
    Ok(())
}
