//! One function per command, each in its own file: it takes the command's typed arguments
//! ([`crate::cli`]) and gives the process's exit code, or the [`LaunchError`] that `main` prints
//! as one line and maps to its exit code (`launcher::error`, the one place codes are chosen).

pub mod agent;
pub mod bench;
pub mod compare;
pub mod component;
pub mod design;
pub mod export;
pub mod export_fmu;
pub mod floor_node;
pub mod inspect;
pub mod linearize;
pub mod list;
pub mod plot;
pub mod replay;
pub mod run;
pub mod sweep;
pub mod vary;

use std::path::Path;
use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::run::{Outcome, Stop};
use launcher::{plan, shipped};
use scenario::Scenario;

/// Loads the scenario a command-line argument names (a path, or a shipped scenario's name).
/// A scenario loaded, with `seed` in place of its own, designed, and its calibrated thresholds set.
pub fn prepared(arg: &Path, seed: Option<u64>) -> Result<(Scenario, plan::Plan), LaunchError> {
    let mut s = shipped::load(arg)?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    let p = launcher::calibrate::planned(&s)?;
    Ok((s, p))
}

/// How a run (`what` = "run") or a replay ended, as the process's outcome: success when it
/// completed and met its `[expect]` table; else the error of its kind (exit 5, 4, 130, 3).
pub fn ended(what: &str, s: &Scenario, o: &Outcome) -> Result<ExitCode, LaunchError> {
    match &o.stop {
        Stop::Completed if o.summary.expectations_met() => Ok(ExitCode::SUCCESS),
        Stop::Completed => Err(LaunchError::Expect(format!(
            "{}: the {what} missed its [expect] table",
            s.path.display()
        ))),
        Stop::Diverged(w) => Err(LaunchError::Diverged(format!(
            "{}: {what} stopped: {w}",
            s.name
        ))),
        Stop::Interrupted(sig) => Err(LaunchError::Interrupted(format!(
            "{}: {what} interrupted by {sig}; recording closed",
            s.name
        ))),
        Stop::Failed(w) => Err(LaunchError::Component(format!("{}: {w}", s.name))),
    }
}

/// Reads a recording, or says why not: bad input (exit 2) when it cannot be read at all,
/// damaged (exit 6) when it does not match the digest written with it (nothing is then written
/// from it).
pub fn read_recording(path: &Path) -> Result<recording::Recording, LaunchError> {
    let r = recording::read(path).map_err(|e| LaunchError::BadInput(e.to_string()))?;
    if let recording::Integrity::Damaged(what) = &r.integrity {
        let why = if what.starts_with('/') || what == recording::digest::SCENARIO_KEY {
            format!(
                "{}: its data does not match the digest written with the recording",
                scenario::quoted(what)
            )
        } else {
            what.clone()
        };
        return Err(LaunchError::Damaged(format!(
            "{}: damaged: {why}",
            path.display()
        )));
    }
    Ok(r)
}

/// `r` in deviations from its operating point when asked (`--deviations`), else as recorded.
pub fn shifted(
    path: &Path,
    r: recording::Recording,
    deviations: bool,
) -> Result<recording::Recording, LaunchError> {
    if !deviations {
        return Ok(r);
    }
    recording::deviations::in_deviations(&r)
        .map_err(|e| LaunchError::BadInput(format!("{}: --deviations: {e}", path.display())))
}
