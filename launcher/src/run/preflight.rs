//! Before a run whose plant is one of our data- or FMU-reading components: the component that
//! will read the file (`fmu_plant --check`, `replay_plant --check`) reads it against the
//! scenario's map, so that a bad file is refused with exit 2 and one line before any process,
//! shared memory or output exists.
//!
//! - `[plant.fmu]`: the archive and model description (not the FMU's library: what that does
//!   when called is the run's to see) — not a zip, no `modelDescription.xml`, model exchange
//!   only, no binary for this platform, a variable that is not there or of the wrong kind.
//! - `[plant.replay]`: the whole data file with the scenario's column map and grid — a missing
//!   column, a non-finite cell, time stamps that go back or off the grid, too few rows, an
//!   `.rrd` of another plant. What it says of the data (rows, held rows, whether x is in it)
//!   goes to the summary.

use std::io::Write;
use std::process::{Command, Stdio};

use scenario::{Scenario, FMU_PLANT_PROGRAM, REPLAY_PLANT_PROGRAM};

use crate::error::LaunchError;

/// Exit 2 with `fmu_plant`'s one line when the FMU cannot be this scenario's plant.
pub fn fmu(s: &Scenario) -> Result<(), LaunchError> {
    let (Some(_), Some(spec)) = (&s.plant_fmu, &s.plant_process) else { return Ok(()) };
    // Its lines name the field (plant.fmu.inputs[2] …) themselves.
    check(s, ["plant.fmu: ", ""], FMU_PLANT_PROGRAM, "fmu-plant", &spec.params).map(drop)
}

/// The facts `replay_plant --check` reports, or exit 2 with its one line when the data cannot
/// be this scenario's plant.
pub fn replay(s: &Scenario) -> Result<Option<serde_json::Value>, LaunchError> {
    let (Some(_), Some(spec)) = (&s.plant_replay, &s.plant_process) else { return Ok(None) };
    let out = check(s, ["plant.replay: "; 2], REPLAY_PLANT_PROGRAM, "replay", &spec.params)?;
    let facts = serde_json::from_slice(&out).map_err(|e| LaunchError::BadInput(format!("{}: plant.replay: {REPLAY_PLANT_PROGRAM} --check: its report: {e}", s.path.display())))?;
    Ok(Some(facts))
}

/// `program --check` (a kit component built beside the launcher, of cargo package `package`)
/// with `params` on stdin: its stdout, or its last line on stderr as bad input. `field` heads
/// this function's own messages and the component's line.
fn check(s: &Scenario, field: [&str; 2], program: &str, package: &str, params: &serde_json::Value) -> Result<Vec<u8>, LaunchError> {
    sibling(&s.path, field, program, "--check", package, params)
}

/// `program flag` (a kit component built beside the launcher, of cargo package `package`) with
/// `input` as JSON on stdin: its stdout, or its last line on stderr as bad input of `file`.
/// `field` heads this function's own messages and the component's line. `--check` here, and
/// `fmu_plant --linearize` for `launcher linearize`.
pub fn sibling(file: &std::path::Path, field: [&str; 2], program: &str, flag: &str, package: &str, input: &serde_json::Value) -> Result<Vec<u8>, LaunchError> {
    let exe = std::env::current_exe().unwrap_or_else(|_| "launcher".into()).with_file_name(program);
    let path = if exe.is_file() { exe } else { program.into() };
    let bad = |why: String| LaunchError::BadInput(format!("{}: {}{why}", file.display(), field[0]));
    let mut child = Command::new(&path)
        .arg(flag)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| bad(format!("cannot start {program} ({e}); it is built with `cargo build --release -p {package}`")))?;
    let text = serde_json::to_string(input).expect("serialises");
    child.stdin.take().expect("piped").write_all(text.as_bytes()).map_err(|e| bad(format!("{program} {flag}: {e}")))?;
    let out = child.wait_with_output().map_err(|e| bad(format!("{program} {flag}: {e}")))?;
    if out.status.success() {
        return Ok(out.stdout);
    }
    let said = String::from_utf8_lossy(&out.stderr);
    let line = said.lines().rfind(|l| !l.trim().is_empty()).unwrap_or("").trim().to_string();
    if line.is_empty() {
        return Err(bad(format!("{program} {flag} failed ({})", out.status)));
    }
    Err(LaunchError::BadInput(format!("{}: {}{line}", file.display(), field[1])))
}
