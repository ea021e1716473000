//! The largest counts a scenario may ask for. Each bounds something that grows with it — a
//! process, memory, a file, or time — so that a number typed wrong is refused as bad input
//! (exit 2, the field named) instead of aborting or filling a disk once the run has started.

/// Most steps (duration / dt) a run may have: 11.6 days at 1 kHz.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Most observer processes a run may hold ([`crate::observer_processes`]: a bank's members
/// share one). Each subscribes to the plant's service, which also feeds the launcher's
/// recorder, and a service of this protocol allows [`lockstep::settings::MAX_SUBSCRIBERS`]
/// subscribers (PROTOCOL.md §4): one for the recorder, the rest for observers.
pub const MAX_OBSERVERS: usize = lockstep::settings::MAX_SUBSCRIBERS - 1;

/// Most `[[fault]]` entries: each adds two values to every plant sample and two recorded
/// signals per step.
pub const MAX_FAULTS: usize = 64;

/// Longest `rms` window, in samples: each bank member keeps the last `window` residual norms
/// (8 bytes each), in every realisation a sweep runs at once.
pub const MAX_WINDOW: i64 = 1_000_000;

/// Longest GLR window, in samples: each step a member extends the correlation of every onset in
/// its window with every channel it tests (N·J·d multiply-adds; 10⁴ × 2 × 2 ≈ 40 µs a step).
pub const MAX_GLR_WINDOW: f64 = 10_000.0;

/// Most calibration realisations (`calibrate.runs`): each is a whole run of the scenario, made
/// before the run itself starts.
pub const MAX_CALIBRATION_RUNS: i64 = 10_000;

/// The default stall limit for a component that runs, or waits for a core, but publishes
/// nothing, s (a stopped or blocked one is named after 5 s).
pub const STALL_TIMEOUT: f64 = 60.0;

/// The largest stall limit accepted, s (a day).
pub const MAX_STALL_TIMEOUT: f64 = 86_400.0;

/// A stall limit: at least the 5 s after which a blocked component is named, at most a day; the
/// reason otherwise (the caller names the field or option).
pub fn stall_timeout(v: f64) -> Result<f64, String> {
    if v.is_finite() && (5.0..=MAX_STALL_TIMEOUT).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{v} s must be between 5 s (when a stopped or blocked component is named) and {MAX_STALL_TIMEOUT} s"
        ))
    }
}
