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
        return refuse("--mode", "--vary runs its points in-process");
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
    let jobs = jobs.clamp(1, outcomes.len());
    print!(
        "{}",
        report::table(&s.name, &opts.varies, s.seed, jobs, &outcomes)
    );
    let csv = a.out.join(format!("{}.vary.csv", s.name));
    outputs::write_bytes(&csv, report::csv(&opts.varies, &outcomes).as_bytes())
        .map_err(LaunchError::Component)?;
    let json = a.out.join(format!("{}.vary.json", s.name));
    let text =
        serde_json::to_string_pretty(&report::json(&s.name, &opts.varies, s.seed, &outcomes))
            .expect("serialises");
    outputs::write_bytes(&json, (text + "\n").as_bytes()).map_err(LaunchError::Component)?;
    let (pngs, skipped) =
        report::plots(&a.out, &s.name, &opts.varies, &outcomes).map_err(LaunchError::Component)?;
    for line in skipped {
        println!("  {line}");
    }
    println!(
        "vary: {} and {} ({} plot(s) in {})",
        csv.display(),
        json.display(),
        pngs.len(),
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
