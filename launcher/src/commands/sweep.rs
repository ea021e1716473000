//! `uio-launcher sweep`: N noise realisations (seeds S, S+1, …), DIR/<name>.sweep.json; with
//! `--shard K/N` one shard of them (DIR/<name>.shard-K-of-N.json), and `sweep merge` the shards
//! into the sweep they make.

use std::path::Path;
use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::run::{Mode, interrupt};
use launcher::sweep::{SweepSummary, shard};
use launcher::{limits, print, println};
use lockstep::Wait;

use crate::cli::{MergeArgs, SweepArgs, SweepCommand};

pub fn command(a: SweepArgs) -> Result<ExitCode, LaunchError> {
    if let Some(SweepCommand::Merge(m)) = a.merge {
        return merge(m);
    }
    let scenario = a
        .scenario
        .clone()
        .expect("clap requires a scenario without a subcommand");
    if !a.vary.is_empty() {
        return super::vary::command(a, &scenario);
    }
    let runs = a.runs.unwrap_or(100);
    let jobs = a.jobs.unwrap_or_else(limits::default_jobs);
    match a.shard {
        None => limits::sweep_runs(runs),
        Some(sh) => limits::sharded_runs(runs, sh.range(runs).len()),
    }
    .and_then(|_| limits::jobs(jobs))?;
    // One calibration for every realisation, from the first seed (every shard's the same).
    let (s, p) = super::prepared(&scenario, a.seed)?;
    let opts = launcher::sweep::SweepOptions {
        runs,
        jobs,
        seed: s.seed,
        mode: Mode::from(a.mode),
        out: a.out.clone(),
        keep_worst: a.keep_worst,
        wait: Wait::default_for_machine(),
        shard: a.shard,
    };
    interrupt::install();
    if let Some(sh) = a.shard {
        let (file, path) = shard::run_shard(&s, &p, &opts, sh)?;
        print!("{}", file.text());
        println!("shard file: {}", path.display());
        return match file.verdict() {
            None => Ok(ExitCode::SUCCESS),
            Some(e) => Err(e),
        };
    }
    let sw = launcher::sweep::sweep(&s, &p, &opts)?;
    finish(&sw, &a.out)
}

/// The table, the summary file and the exit of a whole sweep.
fn finish(sw: &SweepSummary, out: &Path) -> Result<ExitCode, LaunchError> {
    let path = sw.write(out).map_err(LaunchError::Component)?;
    ended(sw, &path)
}

/// The table and the exit of a sweep whose summary is at `path`.
fn ended(sw: &SweepSummary, path: &Path) -> Result<ExitCode, LaunchError> {
    print!("{}", sw.table());
    println!("sweep summary: {}", path.display());
    match sw.verdict() {
        None => Ok(ExitCode::SUCCESS),
        Some(e) => Err(e),
    }
}

fn merge(m: MergeArgs) -> Result<ExitCode, LaunchError> {
    let (sw, path) = shard::merge_into(&m.shards, &m.out)?;
    ended(&sw, &path)
}
