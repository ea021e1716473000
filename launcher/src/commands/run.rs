//! `uio-launcher run`: a scenario, recorded to DIR/<name>.rrd and DIR/<name>.summary.json.

use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::limits;
use launcher::run::{self, Mode, Options};
use launcher::{eprintln, print, println};
use lockstep::Wait;

use crate::cli::{ModeArg, Pin, RunArgs};

/// What `launcher` with no command runs: the shipped seed-002 scenario, across processes.
pub fn default_args() -> RunArgs {
    RunArgs {
        scenario: launcher::shipped::dir().join("seed002-sine.toml"),
        out: "runs".into(),
        mode: ModeArg::Processes,
        wait: None,
        force: true,
        allow_unstable: false,
        pin: Pin::Auto,
        record_every: 1,
        record: Vec::new(),
        compress: false,
        seed: None,
        realtime: false,
        speed: None,
        stall_timeout: None,
    }
}

pub fn command(a: RunArgs) -> Result<ExitCode, LaunchError> {
    let speed = a.speed.unwrap_or(1.0);
    limits::speed(speed)?;
    let realtime = a.realtime.then_some(speed);
    // A paced run sleeps while it waits, unless told otherwise.
    let wait = a.wait.or(realtime.map(|_| Wait::Block));
    let select = recording::write::Selection::new(a.record_every, &a.record)
        .map_err(LaunchError::BadInput)?
        .compressed(a.compress);
    let (mut s, p) = super::prepared(&a.scenario, a.seed)?;
    if let Some(t) = a.stall_timeout {
        s.stall_timeout = scenario::limits::stall_timeout(t)
            .map_err(|e| LaunchError::BadInput(format!("--stall-timeout: {e}")))?;
    }
    if let Some(x) = realtime {
        limits::schedule(x, s.dt, s.steps)?;
    }
    for w in &p.warnings {
        eprintln!("warning: {w}");
    }
    let mode = Mode::from(a.mode);
    if mode == Mode::InProcess && !s.remote.is_empty() {
        eprintln!(
            "note: --mode in-process runs every component here; the scenario's [hosts] placements apply across processes"
        );
    }
    let opts = Options {
        out: a.out,
        mode,
        wait: wait.unwrap_or_else(Wait::default_for_machine),
        force: a.force,
        allow_unstable: a.allow_unstable,
        record: true,
        pin: a.pin == Pin::Auto,
        select,
        progress: true,
        realtime,
    };
    let o = run::run(&s, &p, &opts)?;
    print!("{}", o.summary.table());
    if let Some(rrd) = &o.rrd {
        println!(
            "recording: {}   (view it with: rerun {})",
            rrd.display(),
            rrd.display()
        );
    }
    super::ended("run", &s, &o)
}
