//! `launcher sweep`: N noise realisations (seeds S, S+1, …), DIR/<name>.sweep.json.

use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::run::{Mode, interrupt};
use launcher::{limits, print, println};
use lockstep::Wait;

use crate::cli::SweepArgs;

pub fn command(a: SweepArgs) -> Result<ExitCode, LaunchError> {
    let jobs = a.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .min(limits::MAX_JOBS)
    });
    limits::sweep_runs(a.runs).and_then(|_| limits::jobs(jobs))?;
    // One calibration for every realisation, from the first seed.
    let (s, p) = super::prepared(&a.scenario, a.seed)?;
    let opts = launcher::sweep::SweepOptions {
        runs: a.runs,
        jobs,
        seed: s.seed,
        mode: Mode::from(a.mode),
        out: a.out.clone(),
        keep_worst: a.keep_worst,
        wait: Wait::default_for_machine(),
    };
    interrupt::install();
    let sw = launcher::sweep::sweep(&s, &p, &opts)?;
    print!("{}", sw.table());
    let path = sw.write(&a.out).map_err(LaunchError::Component)?;
    println!("sweep summary: {}", path.display());
    match sw.verdict() {
        None => Ok(ExitCode::SUCCESS),
        Some(e) => Err(e),
    }
}
