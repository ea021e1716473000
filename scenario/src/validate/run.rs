//! The run's own settings: dt, duration (a whole number of steps, at most the step cap), the
//! stall timeout and the share of a fault's time that counts as isolated.

use crate::check::{Bad, bad, finite};
use crate::limits::MAX_STEPS;
use crate::raw::RawScenario;

/// dt, duration and the number of steps.
pub(super) fn timing(raw: &RawScenario) -> Result<(f64, f64, u64), Bad> {
    let dt = finite("dt", raw.dt)?;
    let duration = finite("duration", raw.duration)?;
    if dt <= 0.0 {
        return Err(bad("dt", format!("{dt} must be > 0")));
    }
    if duration <= 0.0 {
        return Err(bad("duration", format!("{duration} must be > 0")));
    }
    if duration < dt {
        return Err(bad(
            "duration",
            format!("{duration} is shorter than one step (dt = {dt})"),
        ));
    }
    let steps_f = (duration / dt).round();
    if (steps_f * dt - duration).abs() > 1e-9 * duration {
        return Err(bad(
            "duration",
            format!("{duration} is not a whole number of steps of dt = {dt}"),
        ));
    }
    if steps_f > MAX_STEPS as f64 {
        return Err(bad(
            "duration",
            format!("{steps_f} steps is more than {MAX_STEPS} (duration / dt)"),
        ));
    }
    let steps = steps_f as u64;
    Ok((dt, duration, steps))
}

/// `tail`: a stretch of the run, at least one step of dt and at most the whole run.
pub(super) fn tail(raw: &RawScenario, dt: f64, duration: f64) -> Result<Option<f64>, Bad> {
    match raw.tail {
        None => Ok(None),
        Some(t) if t.is_finite() && t <= duration && (t / dt).round() >= 1.0 => Ok(Some(t)),
        Some(t) => Err(bad(
            "tail",
            format!(
                "{t} s must be at least one step (dt = {dt} s) and at most the run's duration ({duration} s)"
            ),
        )),
    }
}

/// `isolated_fraction` (default 0.9) and `stall_timeout`.
pub(super) fn settings(raw: &RawScenario) -> Result<(f64, f64), Bad> {
    let isolated_fraction = match raw.isolated_fraction {
        None => 0.9,
        Some(x) if x.is_finite() && x > 0.0 && x <= 1.0 => x,
        Some(x) => {
            return Err(bad(
                "isolated_fraction",
                format!("{x} must be a share of the fault's time, 0 < x ≤ 1"),
            ));
        }
    };
    let stall_timeout = match raw.stall_timeout {
        None => crate::limits::STALL_TIMEOUT,
        Some(v) => crate::limits::stall_timeout(v).map_err(|r| bad("stall_timeout", r))?,
    };
    Ok((isolated_fraction, stall_timeout))
}
