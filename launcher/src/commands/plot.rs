//! `uio-launcher plot`: a recording's views as PNG files.

use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::{eprintln, println};

use crate::cli::PlotArgs;

pub fn command(a: PlotArgs) -> Result<ExitCode, LaunchError> {
    let selection = recording::plot::PlotSelection {
        signals: a.signals,
        from: a.from,
        to: a.to,
    };
    selection.validate().map_err(LaunchError::BadInput)?;
    let r = super::read_recording(&a.recording)
        .and_then(|r| super::shifted(&a.recording, r, a.deviations))?;
    if !r.complete {
        eprintln!(
            "warning: {}: incomplete recording (its writer did not finish); plotting what it holds",
            a.recording.display()
        );
    }
    let files = recording::plot::plot(&r, &a.out, &selection)
        .map_err(|e| LaunchError::BadInput(format!("{}: {e}", a.recording.display())))?;
    for f in &files {
        println!("{}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}
