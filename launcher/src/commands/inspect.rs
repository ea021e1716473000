//! `uio-launcher inspect`: what a recording holds, its figures recomputed from the recorded data.

use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::{eprintln, print, println};

use crate::cli::InspectArgs;

pub fn command(a: InspectArgs) -> Result<ExitCode, LaunchError> {
    let r = super::read_recording(&a.recording)?;
    let i = recording::inspect::inspect(&a.recording.display().to_string(), &r);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&i).expect("serialises"));
    } else {
        print!("{}", i.text());
    }
    for w in &i.warnings {
        eprintln!("warning: {w}");
    }
    Ok(ExitCode::SUCCESS)
}
