//! `uio-launcher sweep --vary`: the scenario at points where the simulated plant differs from the
//! design model (`launcher::vary`), its table, CSV, JSON and plots.

use std::path::Path;
use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::run::interrupt;
use launcher::vary::{VaryOptions, report};
use launcher::{limits, print, println};
use lockstep::Wait;

use crate::cli::{ModeArg, SweepArgs};

pub fn command(a: SweepArgs, scenario: &Path) -> Result<ExitCode, LaunchError> {
    let refuse = |flag: &str, why: &str| Err(LaunchError::BadInput(format!("{flag}: {why}")));
    if a.runs.is_some() {
        return refuse(
            "--runs",
            "with --vary each point runs once, at the seed (--points sets the draws of a distribution)",
        );
    }
    if a.shard.is_some() {
        return refuse("--shard", "shards a noise sweep, not --vary");
    }
    if a.keep_worst > 0 {
        return refuse(
            "--keep-worst",
            "keeps a noise sweep's worst realisations, not --vary's",
        );
    }
    if a.mode != ModeArg::InProcess {
        return refuse(
            "--mode",
            "--vary runs a built-in plant's points in-process and an FMU's as processes",
        );
    }
    if !(1..=launcher::vary::MAX_POINTS).contains(&a.points) {
        return refuse("--points", &format!("1 … {}", launcher::vary::MAX_POINTS));
    }
    let jobs = a.jobs.unwrap_or_else(limits::default_jobs);
    // Designed (and calibrated) once, on the nominal model.
    let (s, p) = super::prepared(scenario, a.seed)?;
    let opts = VaryOptions {
        varies: a.vary.clone(),
        draws: a.points,
        seed: s.seed,
        jobs,
        out: a.out.clone(),
        wait: Wait::default_for_machine(),
    };
    interrupt::install();
    let outcomes = launcher::vary::vary(&s, &p, &opts)?;
    let jobs = launcher::vary::mode_of(&s, jobs).1.clamp(1, outcomes.len());
    print!(
        "{}",
        report::table(&s.name, &opts.varies, s.seed, jobs, &outcomes)
    );
    let written = launcher::vary::report::write(&a.out, &s, &opts.varies, &outcomes)?;
    for line in &written.skipped {
        println!("  {line}");
    }
    println!(
        "vary: {} and {} ({} plot(s) in {})",
        written.csv.display(),
        written.json.display(),
        written.pngs,
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
