//! `uio-launcher sweep`: Monte Carlo over the noise. Realisation i runs the scenario with seed
//! S + i (S = `--seed`, or the scenario's `seed`), without a recording; the figures of every
//! realisation are gathered into distributions: detection delay, isolation accuracy,
//! false-alarm rate per hour of fault-free simulated time, each residual's measured exceedance
//! rate beside the false-alarm probability its χ² threshold was asked for, and each observer's
//! tail error. Realisations are independent and gathered in seed order, so the result is the
//! same whatever the number of jobs. The worst realisations can be run again with a recording
//! (the same seed gives the same run, bit for bit). A realisation that does not complete is
//! counted as failed and left out of the statistics; an interrupted sweep writes the statistics
//! of the realisations it finished, marked partial ([`outcome`]).

mod outcome;
pub mod pool;
mod row;
pub mod shard;
mod stats;

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

pub use outcome::Failed;
pub use row::Row;
pub use shard::Shard;
pub use stats::{Spread, spread};

use crate::error::LaunchError;
use crate::plan::Plan;
use crate::run::{self, Mode, Options, Stop};
use crate::summary::Summary;
use scenario::Scenario;

/// How to sweep.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Realisations.
    pub runs: usize,
    /// Worker threads (in-process mode).
    pub jobs: usize,
    /// The first seed.
    pub seed: u64,
    /// In-process (default) or processes (one realisation at a time).
    pub mode: Mode,
    /// Where the sweep summary (and kept recordings) go.
    pub out: PathBuf,
    /// Run the worst realisations again with a recording.
    pub keep_worst: usize,
    /// Wait strategy (processes mode).
    pub wait: lockstep::Wait,
    /// Only this shard's realisations (`--shard K/N`).
    pub shard: Option<Shard>,
}

/// What a sweep's statistics are gathered against: the scenario's names, and the sweep asked
/// for. A shard file carries it, and `uio-launcher sweep merge` gathers with it alone.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Frame {
    /// Scenario name.
    pub scenario: String,
    /// Its faults' names, in the scenario's order.
    pub faults: Vec<String>,
    /// Its observers' names, in the scenario's order.
    pub observers: Vec<String>,
    /// The share of a fault's active time it must be isolated correctly for to count.
    pub isolated_fraction: f64,
    /// Realisations asked for (`--runs`, of the whole sweep).
    pub requested: usize,
    /// The first seed.
    pub seed: u64,
    /// "in-process" or "processes".
    pub mode: String,
}

impl Frame {
    /// The frame of sweeping `s` with `opts`.
    pub fn of(s: &Scenario, opts: &SweepOptions) -> Frame {
        Frame {
            scenario: s.name.clone(),
            faults: s.faults.iter().map(|f| f.name.clone()).collect(),
            observers: s.observers.iter().map(|o| o.name.clone()).collect(),
            isolated_fraction: s.isolated_fraction,
            requested: opts.runs,
            seed: opts.seed,
            mode: opts.mode.name().into(),
        }
    }
}

/// One fault over the sweep.
#[derive(Debug, Clone, Serialize)]
pub struct FaultSweep {
    /// Its name.
    pub name: String,
    /// Realisations that detected it.
    pub detected: usize,
    /// Delays of those, s.
    pub detection_delay: Option<Spread>,
    /// Realisations that isolated it correctly: for at least the scenario's `isolated_fraction`
    /// of its active time.
    pub isolated_correctly: usize,
    /// isolated_correctly / runs (none without a completed realisation).
    pub isolation_accuracy: Option<f64>,
    /// Realisations whose first isolation named its channel.
    pub first_isolation_correct: usize,
    /// The share of its active time isolated correctly, over the realisations.
    pub isolated_fraction: Option<Spread>,
}

/// One residual over the sweep.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualSweep {
    /// `<diagnoser>-<i>`.
    pub residual: String,
    /// Its threshold.
    pub threshold: f64,
    /// The false-alarm probability per sample asked for (χ²).
    pub asked_false_alarm: Option<f64>,
    /// Fault-free samples decided, over all realisations.
    pub fault_free_steps: u64,
    /// How many exceeded the threshold.
    pub exceedances: u64,
    /// exceedances / fault_free_steps: the measured false-alarm probability per sample.
    pub measured_false_alarm: Option<f64>,
}

/// The sweep's summary (`<name>.sweep.json`).
#[derive(Debug, Clone, Serialize)]
pub struct SweepSummary {
    /// Scenario name.
    pub scenario: String,
    /// Realisations in the statistics: those that completed.
    pub runs: usize,
    /// Realisations asked for (`--runs`).
    pub requested: usize,
    /// Realisations that ended, completed or failed (fewer than asked when interrupted).
    pub finished: usize,
    /// Whether the sweep was interrupted: the statistics are of the realisations it finished.
    pub partial: bool,
    /// The share of a fault's active time it must be isolated correctly for to count.
    pub isolated_fraction: f64,
    /// The signal that interrupted it.
    pub interrupted_by: Option<&'static str>,
    /// Seeds asked for: first and last.
    pub seeds: [u64; 2],
    /// Mode.
    pub mode: String,
    /// Jobs.
    pub jobs: usize,
    /// Wall-clock time, s.
    pub wall_s: f64,
    /// Realisations that did not complete (a component failed, hung or was killed; a state
    /// diverged), by seed: not in the statistics.
    pub failed: Vec<Failed>,
    /// Per fault.
    pub faults: Vec<FaultSweep>,
    /// Alarm episodes while no fault acted, over all realisations.
    pub false_alarms: u64,
    /// Realisations with at least one false alarm.
    pub runs_with_false_alarms: usize,
    /// Fault-free simulated time decided, over all realisations, s.
    pub fault_free_time_s: f64,
    /// false_alarms per hour of fault-free simulated time.
    pub false_alarm_rate_per_hour: Option<f64>,
    /// Per residual.
    pub residuals: Vec<ResidualSweep>,
    /// Per observer: its tail max |x − x̂| over the realisations.
    pub tail_max_abs_error: Vec<(String, Option<Spread>)>,
    /// The seeds of the realisations kept with a recording (worst first).
    pub kept: Vec<u64>,
}

/// A realisation run: its summary and how it ended, or why it could not run.
type Ran = Result<(Summary, Stop), LaunchError>;

/// Runs realisation `seed`: its summary and how it ended (an interruption is an error).
fn one(s: &Scenario, plan: &Plan, seed: u64, opts: &SweepOptions, record: bool) -> Ran {
    let mut s = s.clone();
    s.seed = seed;
    if record {
        s.name = format!("{}-seed{seed}", s.name);
    }
    let outcome = run::run(
        &s,
        plan,
        &Options::quiet(&opts.out, opts.mode, opts.wait, record),
    )?;
    if let Stop::Interrupted(sig) = outcome.stop {
        return Err(LaunchError::Interrupted(format!(
            "{}: sweep interrupted by {sig}",
            s.name
        )));
    }
    Ok((outcome.summary, outcome.stop))
}

/// The realisations of a sweep (or of its shard) that ended, in seed order.
pub struct Realised {
    /// The completed ones.
    pub rows: Vec<Row>,
    /// The ones that did not complete.
    pub failed: Vec<Failed>,
    /// How many ended, completed or failed.
    pub finished: usize,
    /// The signal that interrupted the sweep.
    pub interrupted: Option<&'static str>,
    /// Wall-clock time, s.
    pub wall_s: f64,
    /// Worker threads used.
    pub jobs: usize,
}

/// Runs the realisations of `opts.shard` (all of them without one): realisation i has seed
/// S + i. Realisations are independent and gathered in seed order, whatever the jobs.
pub fn realise(s: &Scenario, plan: &Plan, opts: &SweepOptions) -> Result<Realised, LaunchError> {
    let range = opts.shard.map_or(0..opts.runs, |sh| sh.range(opts.runs));
    let count = range.len();
    match opts.shard {
        None => crate::limits::sweep_runs(opts.runs)?,
        Some(_) => crate::limits::sharded_runs(opts.runs, count)?,
    }
    crate::limits::jobs(opts.jobs)?;
    let jobs = if opts.mode == Mode::Processes {
        1
    } else {
        opts.jobs.clamp(1, count.max(1))
    };
    run::budget::check_memory(s, plan, jobs as u64)?;
    run::create_output_dir(&opts.out)?;
    let start = Instant::now();
    let bar = progress_bar(count);
    let seed_of = |j: usize| opts.seed.wrapping_add((range.start + j) as u64);
    // A realisation that could not run at all (or was interrupted) ends the sweep; one that ran
    // and failed is counted, and the others go on.
    let results = pool::in_order(
        count,
        jobs,
        |j| one(s, plan, seed_of(j), opts, false),
        || {
            if let Some(b) = &bar {
                b.inc(1);
            }
        },
    );
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let interrupted = run::interrupt::received();
    let (mut rows, mut failed, mut finished) = (Vec::new(), Vec::new(), 0);
    for (j, r) in results.into_iter().enumerate() {
        let seed = seed_of(j);
        match r {
            None => {}
            // Cut short by the interruption: not finished.
            Some(Err(_)) if interrupted.is_some() => {}
            Some(Err(e)) => return Err(e),
            Some(Ok((summary, stop))) => {
                finished += 1;
                match Failed::of(seed, &stop) {
                    Some(f) => failed.push(f),
                    None => rows.push(Row::of(seed, &summary)),
                }
            }
        }
    }
    Ok(Realised {
        rows,
        failed,
        finished,
        interrupted,
        wall_s: start.elapsed().as_secs_f64(),
        jobs,
    })
}

/// Runs the `k` worst of `rows` again with a recording (the same seed gives the same run, bit
/// for bit): their seeds, worst first.
pub fn keep_worst(
    s: &Scenario,
    plan: &Plan,
    opts: &SweepOptions,
    rows: &[Row],
    k: usize,
) -> Result<Vec<u64>, LaunchError> {
    let seeds = row::worst(rows, k);
    for &seed in &seeds {
        one(s, plan, seed, opts, true)?;
    }
    Ok(seeds)
}

/// Runs the sweep.
pub fn sweep(s: &Scenario, plan: &Plan, opts: &SweepOptions) -> Result<SweepSummary, LaunchError> {
    let r = realise(s, plan, opts)?;
    let mut out = gather(&Frame::of(s, opts), r.jobs, &r.rows);
    out.finished = r.finished;
    out.failed = r.failed;
    out.partial = r.interrupted.is_some();
    out.interrupted_by = r.interrupted;
    out.wall_s = r.wall_s;
    if r.interrupted.is_some() {
        return Ok(out);
    }
    // The worst realisations, again, with their recordings.
    out.kept = keep_worst(s, plan, opts, &r.rows, opts.keep_worst)?;
    Ok(out)
}

fn progress_bar(total: usize) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(total as u64);
        if let Ok(style) =
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} realisations, {eta} left")
        {
            b.set_style(style);
        }
        b
    })
}

/// The distributions over the completed realisations' rows, in seed order; `finished`,
/// `failed` and `partial` are the caller's.
pub fn gather(frame: &Frame, jobs: usize, rows: &[Row]) -> SweepSummary {
    let runs = rows;
    let diag: Vec<&diagnosis::Diagnosis> =
        runs.iter().filter_map(|r| r.diagnosis.as_ref()).collect();
    let faults = frame
        .faults
        .iter()
        .map(|name| {
            let figs: Vec<&diagnosis::FaultFigure> = diag
                .iter()
                .filter_map(|d| d.faults.iter().find(|x| &x.name == name))
                .collect();
            let delays: Vec<f64> = figs.iter().filter_map(|x| x.delay).collect();
            let correct = figs.iter().filter(|x| x.correct).count();
            let fractions: Vec<f64> = figs.iter().filter_map(|x| x.isolated_fraction).collect();
            FaultSweep {
                name: name.clone(),
                detected: delays.len(),
                detection_delay: spread(&delays),
                isolated_correctly: correct,
                isolation_accuracy: (!runs.is_empty()).then(|| correct as f64 / runs.len() as f64),
                first_isolation_correct: figs.iter().filter(|x| x.first_isolation_correct).count(),
                isolated_fraction: spread(&fractions),
            }
        })
        .collect();
    let false_alarms: u64 = diag.iter().map(|d| d.false_alarms).sum();
    let fault_free: f64 = diag.iter().map(|d| d.fault_free_time).sum();
    let mut residuals: Vec<ResidualSweep> = Vec::new();
    for d in &diag {
        for r in &d.residuals {
            match residuals.iter_mut().find(|x| x.residual == r.residual) {
                Some(x) => {
                    x.fault_free_steps += r.fault_free_steps;
                    x.exceedances += r.exceedances;
                }
                None => residuals.push(ResidualSweep {
                    residual: r.residual.clone(),
                    threshold: r.threshold,
                    asked_false_alarm: r.asked_false_alarm,
                    fault_free_steps: r.fault_free_steps,
                    exceedances: r.exceedances,
                    measured_false_alarm: None,
                }),
            }
        }
    }
    for x in &mut residuals {
        x.measured_false_alarm =
            (x.fault_free_steps > 0).then(|| x.exceedances as f64 / x.fault_free_steps as f64);
    }
    let tail = frame
        .observers
        .iter()
        .map(|name| {
            let v: Vec<f64> = runs
                .iter()
                .filter_map(|r| {
                    r.observers
                        .iter()
                        .find(|(x, _)| x == name)
                        .and_then(|(_, e)| *e)
                })
                .collect();
            (name.clone(), spread(&v))
        })
        .collect();
    SweepSummary {
        scenario: frame.scenario.clone(),
        runs: runs.len(),
        requested: frame.requested,
        finished: runs.len(),
        partial: false,
        isolated_fraction: frame.isolated_fraction,
        interrupted_by: None,
        seeds: [
            frame.seed,
            frame
                .seed
                .wrapping_add(frame.requested.saturating_sub(1) as u64),
        ],
        mode: frame.mode.clone(),
        jobs,
        wall_s: 0.0,
        failed: Vec::new(),
        faults,
        false_alarms,
        runs_with_false_alarms: diag.iter().filter(|d| d.false_alarms > 0).count(),
        fault_free_time_s: fault_free,
        false_alarm_rate_per_hour: (fault_free > 0.0)
            .then(|| false_alarms as f64 / fault_free * 3600.0),
        residuals,
        tail_max_abs_error: tail,
        kept: Vec::new(),
    }
}

impl SweepSummary {
    /// The sweep's failure, if it is one: interrupted, a realisation failed or diverged.
    pub fn verdict(&self) -> Option<LaunchError> {
        outcome::verdict(
            &self.scenario,
            self.requested,
            self.finished,
            &self.failed,
            self.interrupted_by,
        )
    }

    /// Writes `<out>/<name>.sweep.json` (atomically).
    pub fn write(&self, out: &Path) -> Result<PathBuf, String> {
        let path = out.join(format!("{}.sweep.json", self.scenario));
        let text = serde_json::to_string_pretty(self).expect("serialises");
        outputs::write_bytes(&path, (text + "\n").as_bytes())?;
        Ok(path)
    }

    /// The table printed after a sweep.
    pub fn table(&self) -> String {
        let f = |s: &Option<Spread>| {
            s.as_ref().map_or_else(
                || "—".to_string(),
                |s| {
                    format!(
                        "{:.4} / {:.4} / {:.4} / {:.4}",
                        s.min, s.median, s.p95, s.max
                    )
                },
            )
        };
        let mut t = format!(
            "{} sweep: {} realisations (seeds {}–{}), {}, {} job(s), {:.1} s wall\n",
            self.scenario,
            self.requested,
            self.seeds[0],
            self.seeds[1],
            self.mode,
            self.jobs,
            self.wall_s
        );
        if self.partial {
            t += &format!(
                "  PARTIAL: interrupted after {} of {} realisations\n",
                self.finished, self.requested
            );
        }
        if self.runs != self.requested {
            t += &format!(
                "  statistics of {} completed realisation(s); {} failed\n",
                self.runs,
                self.failed.len()
            );
        }
        for x in &self.faults {
            t += &format!(
                "  fault {:<18} detected {}/{}  delay min/median/p95/max {} s  isolated correctly (≥ {} % of its time) in {}; first isolation right in {}/{}; share of its time isolated min/median/p95/max {}\n",
                x.name,
                x.detected,
                self.runs,
                f(&x.detection_delay),
                lti::eig::sig(100.0 * self.isolated_fraction),
                x.isolation_accuracy.map_or_else(
                    || "—".to_string(),
                    |a| format!("{:.1} % of the realisations", 100.0 * a)
                ),
                x.first_isolation_correct,
                self.runs,
                f(&x.isolated_fraction)
            );
        }
        t += &format!(
            "  false alarms: {} over {:.1} s fault-free ({} per hour; {} realisation(s) with one)\n",
            self.false_alarms,
            self.fault_free_time_s,
            self.false_alarm_rate_per_hour
                .map_or_else(|| "—".to_string(), |r| format!("{r:.3}")),
            self.runs_with_false_alarms
        );
        for r in &self.residuals {
            let asked = r
                .asked_false_alarm
                .map_or_else(|| "—".to_string(), |a| format!("{a:.1e}"));
            let measured = r
                .measured_false_alarm
                .map_or_else(|| "—".to_string(), |m| format!("{m:.3e}"));
            t += &format!(
                "  residual {:<12} P(J > threshold) asked {asked}, measured {measured} ({} of {} fault-free samples)\n",
                r.residual, r.exceedances, r.fault_free_steps
            );
        }
        for (name, s) in &self.tail_max_abs_error {
            t += &format!(
                "  observer {:<12} tail max|e| min/median/p95/max {}\n",
                name,
                f(s)
            );
        }
        for x in &self.failed {
            t += &format!("  seed {} {}: {}\n", x.seed, x.kind, x.reason);
        }
        t
    }
}
