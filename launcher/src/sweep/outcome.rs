//! How a sweep's realisations ended, and what that makes of the sweep: a realisation that did
//! not complete (a component failed, hung or was killed; a state diverged) is counted as failed
//! and kept out of the statistics, whose figures would otherwise mix whole runs with cut ones;
//! an interrupted sweep keeps what it finished.

use serde::Serialize;

use crate::error::LaunchError;
use crate::run::Stop;

/// A realisation that did not complete.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Failed {
    /// Its seed.
    pub seed: u64,
    /// "failed" (a component failed, hung or was killed) or "diverged" (a state left its bound).
    pub kind: &'static str,
    /// Why, as the run said.
    pub reason: String,
}

impl Failed {
    /// The failure of realisation `seed` that ended with `stop`, if it did not complete.
    pub fn of(seed: u64, stop: &Stop) -> Option<Failed> {
        let (kind, reason) = match stop {
            Stop::Completed | Stop::Interrupted(_) => return None,
            Stop::Failed(w) => ("failed", w.clone()),
            Stop::Diverged(w) => ("diverged", w.clone()),
        };
        Some(Failed { seed, kind, reason })
    }
}

/// The sweep's exit, from how its realisations ended (README "Commands"): interrupted (130,
/// 129 or 131 as for a run) before any failure, then a failed realisation (3), then a diverged
/// one (4); `None` when every realisation asked for completed.
pub fn verdict(
    name: &str,
    requested: usize,
    finished: usize,
    failed: &[Failed],
    interrupted: Option<&str>,
) -> Option<LaunchError> {
    if let Some(sig) = interrupted {
        return Some(LaunchError::Interrupted(format!(
            "{name}: sweep interrupted by {sig} after {finished} of {requested} realisations; their statistics are written, marked partial"
        )));
    }
    let count = |kind: &str| failed.iter().filter(|f| f.kind == kind).count();
    let first = |kind: &str| {
        failed
            .iter()
            .find(|f| f.kind == kind)
            .map(|f| format!("seed {}: {}", f.seed, f.reason))
            .unwrap_or_default()
    };
    if count("failed") > 0 {
        return Some(LaunchError::Component(format!(
            "{name}: {} of {requested} realisations failed (first, {})",
            count("failed"),
            first("failed")
        )));
    }
    if count("diverged") > 0 {
        return Some(LaunchError::Diverged(format!(
            "{name}: {} of {requested} realisations diverged (first, {})",
            count("diverged"),
            first("diverged")
        )));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::{EXIT_COMPONENT, EXIT_DIVERGED};

    #[test]
    fn failures_outrank_divergence_and_completion_is_silent() {
        let f = |seed, stop: Stop| Failed::of(seed, &stop).unwrap();
        let both = [
            f(3, Stop::Diverged("x".into())),
            f(
                5,
                Stop::Failed("observer 'bad' (pid 1, stopped) published no sample".into()),
            ),
        ];
        let e = verdict("s", 10, 10, &both, None).unwrap();
        assert_eq!(e.exit_code(), EXIT_COMPONENT);
        assert!(
            e.to_string()
                .contains("1 of 10 realisations failed (first, seed 5: observer 'bad'"),
            "{e}"
        );
        assert_eq!(
            verdict("s", 10, 10, &both[..1], None).unwrap().exit_code(),
            EXIT_DIVERGED
        );
        assert!(verdict("s", 10, 10, &[], None).is_none());
        assert!(Failed::of(1, &Stop::Completed).is_none());
        assert!(
            verdict("s", 10, 4, &both, Some("SIGTERM"))
                .unwrap()
                .to_string()
                .contains("after 4 of 10 realisations")
        );
    }
}
