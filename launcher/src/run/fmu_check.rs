//! Before a run with `[plant.fmu]`: the component that will load the FMU (`fmu_plant --check`)
//! reads its archive and model description and the scenario's variable map, so that a bad FMU
//! is refused with exit 2 before any process, shared memory or output exists. The check does
//! not load the FMU's library: what it does when called is the run's to see.

use std::io::Write;
use std::process::{Command, Stdio};

use scenario::{Scenario, FMU_PLANT_PROGRAM};

use crate::error::LaunchError;

/// Exit 2 with the component's one line when the FMU cannot be this scenario's plant.
pub fn check(s: &Scenario) -> Result<(), LaunchError> {
    let (Some(_), Some(spec)) = (&s.plant_fmu, &s.plant_process) else { return Ok(()) };
    let exe = std::env::current_exe().unwrap_or_else(|_| "launcher".into()).with_file_name(FMU_PLANT_PROGRAM);
    let program = if exe.is_file() { exe } else { FMU_PLANT_PROGRAM.into() };
    let bad = |why: String| LaunchError::BadInput(format!("{}: plant.fmu: {why}", s.path.display()));
    let mut child = Command::new(&program)
        .arg("--check")
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| bad(format!("cannot start {FMU_PLANT_PROGRAM} ({e}); it is built with `cargo build --release -p fmu-plant`")))?;
    let text = serde_json::to_string(&spec.params).expect("serialises");
    child.stdin.take().expect("piped").write_all(text.as_bytes()).map_err(|e| bad(format!("{FMU_PLANT_PROGRAM} --check: {e}")))?;
    let out = child.wait_with_output().map_err(|e| bad(format!("{FMU_PLANT_PROGRAM} --check: {e}")))?;
    if out.status.success() {
        return Ok(());
    }
    let said = String::from_utf8_lossy(&out.stderr);
    let line = said.lines().rfind(|l| !l.trim().is_empty()).unwrap_or("").trim().to_string();
    Err(LaunchError::BadInput(format!("{}: {}", s.path.display(), if line.is_empty() { format!("{FMU_PLANT_PROGRAM} --check failed ({})", out.status) } else { line })))
}
