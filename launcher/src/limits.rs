//! The bounds of the counts the command line asks for, checked before anything starts: a
//! number typed wrong is bad input (exit 2, the flag named), never a panic, an abort or a run
//! that cannot mean what it says. The scenario's own counts are bounded in `scenario::limits`.

use crate::error::LaunchError;

/// Most realisations of a sweep: the summary of each is kept until the statistics are
/// gathered (a few KiB each).
pub const MAX_SWEEP_RUNS: usize = 100_000;
/// Most realisations of a sharded sweep (`--shard K/N`), each shard at most [`MAX_SWEEP_RUNS`].
pub const MAX_SHARDED_RUNS: usize = 100_000_000;
/// Most worker threads of a sweep: each holds one realisation in memory.
pub const MAX_JOBS: usize = 1024;
/// `--speed` of a paced run: from a thousandth to a million times real time. Slower would
/// stretch a second of simulation over more than a quarter of an hour of sleeping; faster gives
/// a step of dt = 1 ms less than a nanosecond, no schedule at all (a million times real time
/// still shows how far a run falls behind a pace it cannot keep).
pub const SPEED: (f64, f64) = (1e-3, 1e6);
/// Most steps of a benchmark run, as of a scenario.
pub const MAX_BENCH_STEPS: u64 = scenario::limits::MAX_STEPS;
/// Most repetitions of the benchmark.
pub const MAX_REPEAT: usize = 1000;
/// Largest model of `bench --states`: its random plant is designed in O(n³) and written as a
/// scenario of n² numbers per matrix.
pub const MAX_STATES: usize = 500;

fn bad(flag: &str, value: impl std::fmt::Debug, reason: impl std::fmt::Display) -> LaunchError {
    // Debug: a float as it is typed (1e-300), not spelled out in 300 digits.
    LaunchError::BadInput(format!("{flag} {value:?}: {reason}"))
}

/// `--runs` of a sweep.
pub fn sweep_runs(runs: usize) -> Result<(), LaunchError> {
    if runs == 0 {
        return Err(bad("--runs", runs, "must be at least 1"));
    }
    if runs > MAX_SWEEP_RUNS {
        return Err(bad(
            "--runs",
            runs,
            format!(
                "at most {MAX_SWEEP_RUNS} realisations (each one's summary is kept until the statistics are gathered)"
            ),
        ));
    }
    Ok(())
}

/// `--runs` of a sharded sweep: the whole up to [`MAX_SHARDED_RUNS`], this process's share of it
/// (`count`) up to [`MAX_SWEEP_RUNS`].
pub fn sharded_runs(runs: usize, count: usize) -> Result<(), LaunchError> {
    if runs == 0 {
        return Err(bad("--runs", runs, "must be at least 1"));
    }
    if runs > MAX_SHARDED_RUNS {
        return Err(bad(
            "--runs",
            runs,
            format!("at most {MAX_SHARDED_RUNS} realisations in a sharded sweep"),
        ));
    }
    if count > MAX_SWEEP_RUNS {
        return Err(bad(
            "--shard",
            count,
            format!(
                "a shard runs at most {MAX_SWEEP_RUNS} realisations (each one's row is kept until its file is written): use more shards"
            ),
        ));
    }
    Ok(())
}

/// `--jobs` when not given: every core, at most [`MAX_JOBS`].
pub fn default_jobs() -> usize {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(MAX_JOBS)
}

/// `--jobs` of a sweep.
pub fn jobs(jobs: usize) -> Result<(), LaunchError> {
    if !(1..=MAX_JOBS).contains(&jobs) {
        return Err(bad(
            "--jobs",
            jobs,
            format!("must be from 1 to {MAX_JOBS} worker threads"),
        ));
    }
    Ok(())
}

/// `--speed` of `run --realtime`.
pub fn speed(speed: f64) -> Result<(), LaunchError> {
    let (lo, hi) = SPEED;
    if !(speed.is_finite() && (lo..=hi).contains(&speed)) {
        return Err(bad(
            "--speed",
            speed,
            format!("must be from {lo} to {hi} (times real time)"),
        ));
    }
    Ok(())
}

/// The schedule `--speed` makes of a scenario's steps: a step of at least 1 ns of wall time,
/// and a run whose schedule fits CLOCK_MONOTONIC's nanoseconds.
pub fn schedule(speed: f64, dt: f64, steps: u64) -> Result<(), LaunchError> {
    let period_ns = dt / speed * 1e9;
    if period_ns < 1.0 {
        return Err(bad(
            "--speed",
            speed,
            format!(
                "a step of dt = {dt} s would get {period_ns:.3} ns of wall time: too little to pace"
            ),
        ));
    }
    let total_ns = period_ns * steps as f64;
    if total_ns > (1u64 << 62) as f64 {
        return Err(bad(
            "--speed",
            speed,
            format!("the paced run would last {:.3e} s", total_ns * 1e-9),
        ));
    }
    Ok(())
}

/// `--steps` and `--repeat` of `bench`.
pub fn bench(steps: u64, repeat: usize) -> Result<(), LaunchError> {
    if !(1..=MAX_BENCH_STEPS).contains(&steps) {
        return Err(bad(
            "--steps",
            steps,
            format!("must be from 1 to {MAX_BENCH_STEPS}"),
        ));
    }
    if !(1..=MAX_REPEAT).contains(&repeat) {
        return Err(bad(
            "--repeat",
            repeat,
            format!("must be from 1 to {MAX_REPEAT}"),
        ));
    }
    Ok(())
}

/// `--states` of `bench`.
pub fn states(states: &[usize]) -> Result<(), LaunchError> {
    match states.iter().find(|&&n| !(1..=MAX_STATES).contains(&n)) {
        Some(n) => Err(bad(
            "--states",
            n,
            format!("a benchmark plant has from 1 to {MAX_STATES} states"),
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_inclusive_and_name_the_flag() {
        assert!(sweep_runs(MAX_SWEEP_RUNS).is_ok() && sweep_runs(1).is_ok());
        assert!(
            sweep_runs(MAX_SWEEP_RUNS + 1)
                .unwrap_err()
                .to_string()
                .starts_with("--runs ")
        );
        assert!(jobs(0).unwrap_err().to_string().starts_with("--jobs 0:"));
        assert!(speed(1e-3).is_ok() && speed(1e6).is_ok() && schedule(1e6, 0.001, 1000).is_ok());
        assert!(
            speed(1e-300).is_err()
                && speed(f64::NAN).is_err()
                && speed(0.0).is_err()
                && speed(2e6).is_err()
        );
        assert!(schedule(1e6, 1e-7, 1).is_err(), "a step of less than 1 ns");
        assert!(
            schedule(1e-3, 1e9, 1e9 as u64).is_err(),
            "longer than the clock"
        );
        assert!(
            bench(0, 1).is_err() && bench(MAX_BENCH_STEPS + 1, 1).is_err() && bench(10, 0).is_err()
        );
        assert!(states(&[3, 0]).is_err() && states(&[MAX_STATES]).is_ok());
    }
}
