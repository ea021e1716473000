//! Before a run with `[plant.replay]`: the component that will replay the data
//! (`replay_plant --check`) reads the whole file with the scenario's column map and grid, so
//! that bad data (a missing column, a non-finite cell, time stamps that go back or off the
//! grid, too few rows, an `.rrd` of another plant) is refused with exit 2 and one line before
//! any process, shared memory or output exists. What it says of the data goes to the summary.

use std::io::Write;
use std::process::{Command, Stdio};

use scenario::{Scenario, REPLAY_PLANT_PROGRAM};

use crate::error::LaunchError;

/// The facts `replay_plant --check` reports (rows, held rows, whether x is in the data), or
/// exit 2 with its one line when the data cannot be this scenario's plant.
pub fn check(s: &Scenario) -> Result<Option<serde_json::Value>, LaunchError> {
    let (Some(_), Some(spec)) = (&s.plant_replay, &s.plant_process) else { return Ok(None) };
    let exe = std::env::current_exe().unwrap_or_else(|_| "launcher".into()).with_file_name(REPLAY_PLANT_PROGRAM);
    let program = if exe.is_file() { exe } else { REPLAY_PLANT_PROGRAM.into() };
    let bad = |why: String| LaunchError::BadInput(format!("{}: plant.replay: {why}", s.path.display()));
    let mut child = Command::new(&program)
        .arg("--check")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| bad(format!("cannot start {REPLAY_PLANT_PROGRAM} ({e}); it is built with `cargo build --release -p replay`")))?;
    let text = serde_json::to_string(&spec.params).expect("serialises");
    child.stdin.take().expect("piped").write_all(text.as_bytes()).map_err(|e| bad(format!("{REPLAY_PLANT_PROGRAM} --check: {e}")))?;
    let out = child.wait_with_output().map_err(|e| bad(format!("{REPLAY_PLANT_PROGRAM} --check: {e}")))?;
    if out.status.success() {
        let facts = serde_json::from_slice(&out.stdout).map_err(|e| bad(format!("{REPLAY_PLANT_PROGRAM} --check: its report: {e}")))?;
        return Ok(Some(facts));
    }
    let said = String::from_utf8_lossy(&out.stderr);
    let line = said.lines().rfind(|l| !l.trim().is_empty()).unwrap_or("").trim().to_string();
    Err(bad(if line.is_empty() { format!("{REPLAY_PLANT_PROGRAM} --check failed ({})", out.status) } else { line }))
}
