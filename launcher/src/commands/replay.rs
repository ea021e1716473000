//! `uio-launcher replay`: observers on a run's recorded plant samples, the plant replayed from the
//! recording, the controller removed (open loop).

use std::path::Path;
use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::run::{self, Mode, Options};
use launcher::{print, println};
use lockstep::Wait;

use crate::cli::ReplayArgs;

pub fn command(a: ReplayArgs) -> Result<ExitCode, LaunchError> {
    let recording = a.recording;
    let out = a
        .out
        .unwrap_or_else(|| recording.parent().unwrap_or(Path::new(".")).join("replay"));
    let s = launcher::replay::scenario(&recording, a.scenario.as_deref())?;
    launcher::replay::refuse_overwrite(&recording, &out, &s.name)?;
    let p = launcher::calibrate::planned(&s)?;
    let opts = Options {
        force: a.force,
        progress: true,
        pin: true,
        ..Options::quiet(&out, Mode::Processes, Wait::default_for_machine(), true)
    };
    let o = run::run(&s, &p, &opts)?;
    print!("{}", o.summary.table());
    if let Some(rrd) = &o.rrd {
        println!("recording: {}", rrd.display());
    }
    super::ended("replay", &s, &o)
}
