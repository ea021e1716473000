//! `uio-launcher agent …`: becomes `uio-bridge agent …` (exec), which serves the components a
//! launcher on another host places here.

use std::os::unix::process::CommandExt;
use std::process::ExitCode;

use launcher::error::LaunchError;

use crate::cli::AgentArgs;

pub fn command(a: AgentArgs) -> Result<ExitCode, LaunchError> {
    let bridge = launcher::run::bridge_path();
    // exec returns only when it failed.
    let e = std::process::Command::new(&bridge)
        .arg("agent")
        .args(&a.args)
        .exec();
    Err(LaunchError::Component(format!(
        "cannot run {}: {e} (build it with `cargo build --release --workspace`)",
        bridge.display()
    )))
}
