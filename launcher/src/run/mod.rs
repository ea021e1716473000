//! Running a scenario: output checks, the chosen mode, the recording, the summary.

pub mod budget;
mod channels;
mod configs;
mod envelope;
mod in_process;
pub mod interrupt;
mod options;
pub mod preflight;
mod processes;
mod progress;
mod salvage;
mod session;
mod stall;

use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use channels::hop_entity;
pub use configs::{Configs, configs};
pub use envelope::{Launchable, Program, bridge_path, envelopes};
pub use options::{Mode, Options, Stop};
pub(crate) use processes::placement::{pin_self, ring_cpus};
pub use session::{Finished, RealtimeFigures, Session, hop_names};

use crate::error::LaunchError;
use crate::plan::Plan;
use crate::summary::Summary;
use scenario::Scenario;

/// What a finished run produced.
#[derive(Debug)]
pub struct Outcome {
    /// The summary (also written as JSON).
    pub summary: Summary,
    /// The recording, if one was written.
    pub rrd: Option<PathBuf>,
    /// The summary file.
    pub summary_path: Option<PathBuf>,
    /// How it ended.
    pub stop: Stop,
}

/// The recording and summary paths of a scenario in `out`.
pub fn output_paths(out: &Path, name: &str) -> (PathBuf, PathBuf) {
    (
        out.join(format!("{name}.rrd")),
        out.join(format!("{name}.summary.json")),
    )
}

/// Makes the output directory `out` (and its parents) if absent; bad input when it cannot be.
pub fn create_output_dir(out: &Path) -> Result<(), LaunchError> {
    fs::create_dir_all(out).map_err(|e| {
        LaunchError::BadInput(format!(
            "{}: cannot create the output directory: {e}",
            out.display()
        ))
    })
}

/// Makes sure the outputs can be written, before anything runs.
fn prepare_output(out: &Path, name: &str, force: bool) -> Result<(PathBuf, PathBuf), LaunchError> {
    create_output_dir(out)?;
    outputs::probe(out).map_err(|e| {
        LaunchError::BadInput(format!(
            "{}: output directory is not writable: {e}",
            out.display()
        ))
    })?;
    let (rrd, summary) = output_paths(out, name);
    for p in [&rrd, &summary] {
        if p.exists() {
            if !force {
                return Err(LaunchError::BadInput(format!(
                    "{}: already exists (pass --force to overwrite)",
                    p.display()
                )));
            }
            // Overwritten now, not when the new run ends: a run that fails must not leave the
            // previous run's outputs looking like its own.
            fs::remove_file(p).map_err(|e| {
                LaunchError::BadInput(format!("{}: cannot overwrite: {e}", p.display()))
            })?;
        }
    }
    // What a killed launcher left, or anything planted at that name (a link is removed, never
    // followed): the recording is then made there as a new file (`outputs::create_new`).
    let partial = rrd.with_extension("rrd.partial");
    if fs::symlink_metadata(&partial).is_ok() {
        fs::remove_file(&partial).map_err(|e| {
            LaunchError::BadInput(format!("{}: cannot replace: {e}", partial.display()))
        })?;
    }
    Ok((rrd, summary))
}

/// The first component the scenario runs as an external process, if any.
fn external_component(s: &Scenario) -> Option<String> {
    if s.plant_process.is_some() {
        return Some("the plant".into());
    }
    if let Some(o) = s.observers.iter().find(|o| o.process.is_some()) {
        return Some(format!("observer '{}'", o.name));
    }
    s.controller
        .as_ref()
        .filter(|c| c.process.is_some())
        .map(|_| "the controller".into())
}

/// Runs a designed scenario.
// one job: a run's life in order (pre-flight, outputs, session, the mode's loop) and the one path
// that ends every run consistently; the stages share the outputs they must clean up.
pub fn run(s: &Scenario, plan: &Plan, opts: &Options) -> Result<Outcome, LaunchError> {
    if let Some(fb) = &plan.feedback
        && let Some(why) = fb.instability()
        && !opts.allow_unstable
    {
        return Err(LaunchError::BadInput(format!(
            "{}: controller: {why}; pass --allow-unstable to run it anyway",
            s.path.display()
        )));
    }
    if opts.mode == Mode::InProcess && s.plant_fmu.is_some() {
        return Err(LaunchError::BadInput(format!(
            "{}: the plant is an FMU: it runs in its own process ({}), so that a crash in the FMU's library cannot take the recording with it; --mode in-process runs only built-in components",
            s.path.display(),
            scenario::FMU_PLANT_PROGRAM
        )));
    }
    if opts.mode == Mode::InProcess
        && let Some(what) = external_component(s)
    {
        return Err(LaunchError::BadInput(format!(
            "{}: {what} is an external process: --mode in-process runs only built-in components",
            s.path.display()
        )));
    }
    // An FMU or recorded data that cannot be the plant is refused before anything runs, by the
    // component that would read it.
    preflight::fmu(s)?;
    let replay = preflight::replay(s)?;
    // A runs directory that is not private (a planted symlink, another user's) is refused
    // before any output exists: bad input, like a scenario's.
    if opts.mode == Mode::Processes {
        lockstep::prepare_runs_dir().map_err(|e| LaunchError::BadInput(e.to_string()))?;
    }
    let mut cfg = configs(s, plan);
    // What the run will take of disk, memory and shared memory, before any output exists.
    budget::check(s, plan, opts, cfg.layout.len(), 1)?;
    let (rrd, summary_path) = if opts.record {
        prepare_output(&opts.out, &s.name, opts.force).map(|(a, b)| (Some(a), Some(b)))?
    } else {
        (None, None)
    };
    // The recording is written under a temporary name and renamed when the run ends, however it
    // ends: a finished `<name>.rrd` is never half-written, and what a killed launcher leaves
    // (`<name>.rrd.partial`, without footer) does not stand in the next run's way.
    let partial = rrd.as_ref().map(|p| p.with_extension("rrd.partial"));
    interrupt::install();
    cfg.pace_s = opts.realtime.map(|x| s.dt / x);
    let mut session = Session::new(
        s,
        cfg.layout,
        plan,
        partial.as_deref(),
        &opts.select,
        cfg.pace_s,
        opts.mode == Mode::Processes,
    )
    .inspect_err(|_| {
        // A recording that could not even be started is of no use to anyone.
        if let Some(p) = &partial {
            let _ = fs::remove_file(p);
        }
    })?;
    if opts.progress {
        session.progress = progress::Progress::new(s.steps);
    }
    let start = Instant::now();
    let stop = match opts.mode {
        Mode::InProcess => in_process::run(&cfg, &mut session),
        Mode::Processes => processes::run(s, &cfg, &mut session, opts.wait, opts.pin),
    };
    let wall = start.elapsed().as_secs_f64();
    // An error once the recording has started ends the run like a failed component: the
    // recording is closed and a summary says why, so the outputs stay consistent.
    let stop = match stop {
        Ok(stop) => stop,
        Err(LaunchError::Interrupted(_)) => {
            Stop::Interrupted(interrupt::received().unwrap_or("SIGINT"))
        }
        Err(e) => Stop::Failed(e.to_string()),
    };
    let steps_done = session.steps;
    let Finished {
        mut metrics,
        latency,
        digest,
        diagnosis,
        realtime,
    } = session.finish().map_err(|e| {
        // Say why the run had stopped too, when the recording's failure is not the whole story.
        let why = match &stop {
            Stop::Completed => String::new(),
            Stop::Diverged(w) | Stop::Failed(w) => format!(" (the run had stopped: {w})"),
            Stop::Interrupted(sig) => format!(" (the run had been interrupted by {sig})"),
        };
        salvage::recording_failed(
            &s.name,
            partial.as_deref(),
            &format!("{e}{why}"),
            steps_done,
        )
    })?;
    metrics.finish();
    // A run that failed before any step completed has nothing to show: it leaves no recording
    // and no summary (a retry then needs no --force); the message says why.
    if steps_done == 0 && !matches!(stop, Stop::Completed) {
        if let Some(p) = &partial {
            let _ = fs::remove_file(p);
        }
        let mut summary = Summary::new(
            s, plan, opts, &metrics, &latency, wall, &stop, None, diagnosis,
        );
        summary.realtime = realtime;
        return Ok(Outcome {
            summary,
            rrd: None,
            summary_path: None,
            stop,
        });
    }
    // Failures after the run are of the run's outputs (a full disk, say): exit code 3, the file named.
    if let (Some(from), Some(to)) = (&partial, &rrd) {
        fs::rename(from, to).map_err(|e| {
            LaunchError::Component(format!(
                "{}: cannot rename the recording into place: {e}",
                to.display()
            ))
        })?;
    }
    let mut summary = Summary::new(
        s,
        plan,
        opts,
        &metrics,
        &latency,
        wall,
        &stop,
        rrd.as_deref(),
        diagnosis,
    );
    summary.realtime = realtime;
    summary.recording_digest = digest;
    if let Some(facts) = replay {
        summary.with_replay(s, facts, matches!(stop, Stop::Completed));
    }
    if let Some(path) = &summary_path {
        summary.write(path).map_err(LaunchError::Component)?;
    }
    Ok(Outcome {
        summary,
        rrd,
        summary_path,
        stop,
    })
}
