//! `launcher floor-node` (hidden): one node of the benchmark's floor ring.

use std::process::ExitCode;

use launcher::error::LaunchError;

use crate::cli::FloorNodeArgs;

pub fn command(a: FloorNodeArgs) -> Result<ExitCode, LaunchError> {
    launcher::bench::floor::node(
        &a.run,
        a.index.min(2),
        a.steps,
        [a.len_plant, a.len_observer, a.len_controller],
        a.wait,
    )
    .map_err(|e| LaunchError::Component(format!("floor node {}: {e}", a.index)))?;
    Ok(ExitCode::SUCCESS)
}
