//! `--mode processes`: one process per component, in lockstep over iceoryx2, supervised.
//!
//! The launcher creates the run's space and its own recording subscribers first, starts the
//! components (each in its own process group, so a terminal's Ctrl-C reaches only the launcher),
//! waits until every component reports `ready`, then says `go`. While the run goes it drains
//! the recording subscribers and polls the children: a component that exits early or is killed
//! stops the run within a poll interval, the others are killed, and the recording is closed.

mod assembly;
mod liveness;
pub(crate) mod placement;
mod proc;

use std::io::Write;
use std::path::Path;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use lockstep::{Bus, Reader, RunSpace, Wait, cleanup_dead_runs};
use scenario::Scenario;

use self::assembly::{Assembly, Readers};
use self::placement::placement;
use self::proc::{Proc, spawn, stop_all};
use super::configs::Configs;
use super::envelope::envelopes;
use super::session::Session;
use super::stall::STALL_BLOCKED;
use super::{Stop, interrupt};
use crate::error::LaunchError;
use recording::write::StepRow;

/// How long components may take to report ready.
const READY_TIMEOUT: Duration = Duration::from_secs(20);
/// Sleep between drains. The launcher shares the cores with the lockstep ring, and every
/// wake-up takes a core from it for a moment: drain rarely, in large batches. At the fastest
/// step rate measured (~250k steps/s) 5 ms is ~1300 samples, well inside the recorder's buffer.
const POLL: Duration = Duration::from_millis(5);
/// Samples per service taken between yields of the core.
const CHUNK: usize = 16;

/// Runs the scenario across processes.
pub fn run(
    s: &Scenario,
    cfg: &Configs,
    session: &mut Session,
    wait: Wait,
    pin: bool,
) -> Result<Stop, LaunchError> {
    cleanup_dead_runs();
    let space = RunSpace::create().map_err(|e| LaunchError::Component(e.to_string()))?;
    let result = run_in(s, &space, cfg, session, wait, pin);
    space.remove();
    result
}

fn run_in(
    s: &Scenario,
    space: &RunSpace,
    cfg: &Configs,
    session: &mut Session,
    wait: Wait,
    pin: bool,
) -> Result<Stop, LaunchError> {
    let ipc = |e: lockstep::LockstepError| LaunchError::Component(e.to_string());
    let components = envelopes(s, cfg, space, wait);
    for c in &components {
        space
            .write_config(&c.file(), &to_json(&c.config))
            .map_err(ipc)?;
    }

    // The recorder's subscribers exist before any component can publish: they create every
    // service of the run (PROTOCOL.md §4).
    let bus = Bus::join(space, "launcher", Wait::Yield).map_err(ipc)?;
    space.restrict_shm().map_err(ipc)?;
    let readers: Vec<Reader> = components
        .iter()
        .map(|c| bus.reader(&c.config.publishes.service))
        .collect::<Result<_, _>>()
        .map_err(ipc)?;
    // Observer processes: one per observer, one per bank (its members together).
    let nobs = cfg.processes.len();

    let (tx, rx) = mpsc::channel();
    let mut procs: Vec<Proc> = Vec::new();
    let (plant_cpu, observer_cpus, controller_cpu) = placement(cfg, pin);
    let cpus: Vec<Option<usize>> = std::iter::once(plant_cpu)
        .chain(observer_cpus)
        .chain(s.controller.as_ref().map(|_| controller_cpu))
        .collect();
    let workdir = s
        .path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let workdir = &std::path::absolute(workdir).unwrap_or_else(|_| workdir.to_path_buf());
    let result = (|| {
        for (i, (c, &cpu)) in components.iter().zip(&cpus).enumerate() {
            procs.push(spawn(c, workdir, space, cpu, &tx, i)?);
        }
        let stall = Duration::from_secs_f64(s.stall_timeout);
        handshake(&mut procs, &rx, stall)?;
        let r = Readers {
            plant: &readers[0],
            observers: &readers[1..1 + nobs],
            controller: readers.get(1 + nobs),
        };
        let mut asm = Assembly::new(
            &components,
            cfg,
            s.steps,
            s.dt,
            s.controller
                .as_ref()
                .and_then(|c| s.observers.iter().position(|o| o.name == c.observer)),
        );
        supervise(cfg, session, &mut procs, &r, &mut asm, stall)
    })();
    stop_all(&mut procs);
    drop((readers, bus));
    result
}

/// How long a component whose stdout ended before `ready` is given to exit, so that its exit
/// status and last words can be quoted.
const EXIT_GRACE: Duration = Duration::from_millis(100);

/// Waits for every component's `ready`, then tells them all `go`. A component whose stdout ends
/// before `ready` cannot report it: it failed to start, and is named at once. One still starting
/// after [`READY_TIMEOUT`] is waited for up to the stall limit while it runs or waits for a core
/// (an interpreter importing its libraries on a loaded machine), and named once blocked; one the
/// kernel has stopped (SIGSTOP, a debugger) is named after [`STALL_BLOCKED`].
fn handshake(
    procs: &mut [Proc],
    rx: &mpsc::Receiver<(usize, Option<String>)>,
    stall: Duration,
) -> Result<(), LaunchError> {
    let start = Instant::now();
    let pgids: Vec<u32> = procs.iter().map(|p| p.child.id()).collect();
    let mut watch: Option<liveness::Watch> = None;
    let mut looks = 0usize;
    let mut ready = vec![false; procs.len()];
    while !ready.iter().all(|&r| r) {
        if let Some(sig) = interrupt::received() {
            return Err(LaunchError::Interrupted(format!(
                "{sig} received while the components started"
            )));
        }
        for p in procs.iter_mut() {
            if p.status.is_none()
                && let Ok(Some(st)) = p.child.try_wait()
            {
                p.status = Some(st);
                // Give its stderr reader a moment to collect the message.
                std::thread::sleep(Duration::from_millis(20));
                return Err(LaunchError::Component(format!(
                    "{} before the run began",
                    p.describe_exit()
                )));
            }
        }
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok((i, Some(line))) if line.trim() == "ready" => ready[i] = true,
            Ok((i, None)) if !ready[i] => return Err(closed_before_ready(&mut procs[i])),
            Ok(_) | Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {}
        }
        let slow: Vec<usize> = (0..procs.len()).filter(|&i| !ready[i]).collect();
        // (All may have become ready in this pass: the loop then ends.)
        // A stopped component cannot become ready until someone continues it: it is named after
        // the run's own blocked limit, not the start-up allowance.
        if start.elapsed() > STALL_BLOCKED && !slow.is_empty() {
            let w = watch.get_or_insert_with(|| liveness::Watch::new(&pgids));
            // One slow component judged per look, in turn.
            let mut named = None;
            let i = slow[looks % slow.len()];
            if let Some(v) = w.judge(&pgids, i) {
                looks += 1;
                let waited = start.elapsed();
                named = match v {
                    liveness::Verdict::Stopped => Some(format!(
                        "{} did not report ready within {} s and is stopped",
                        procs[i].describe_stall(),
                        waited.as_secs()
                    )),
                    liveness::Verdict::Blocked if waited > READY_TIMEOUT => Some(format!(
                        "{} did not report ready within {} s and is asleep, using no CPU",
                        procs[i].describe_stall(),
                        READY_TIMEOUT.as_secs()
                    )),
                    _ => None,
                };
            }
            if named.is_none() && start.elapsed() > stall.max(READY_TIMEOUT) {
                let labels: Vec<&str> = slow.iter().map(|&i| procs[i].label.as_str()).collect();
                named = Some(format!(
                    "{} did not report ready within {} s (the stall limit: stall_timeout in the scenario, --stall-timeout)",
                    labels.join(", "),
                    lti::eig::sig(stall.max(READY_TIMEOUT).as_secs_f64())
                ));
            }
            if let Some(why) = named {
                return Err(LaunchError::Component(why));
            }
        }
    }
    for p in procs.iter_mut() {
        let mut stdin = p.child.stdin.take().expect("piped");
        stdin
            .write_all(b"go\n")
            .and_then(|_| stdin.flush())
            .map_err(|e| LaunchError::Component(format!("{}: {e}", p.label)))?;
    }
    Ok(())
}

/// The failure of a component whose stdout ended before it reported ready: its exit, when it
/// exits within [`EXIT_GRACE`] (it usually closed stdout by exiting), else the closed pipe.
fn closed_before_ready(p: &mut Proc) -> LaunchError {
    let until = Instant::now() + EXIT_GRACE;
    while Instant::now() < until {
        if let Ok(Some(st)) = p.child.try_wait() {
            p.status = Some(st);
            // Give its stderr reader a moment to collect the message.
            std::thread::sleep(Duration::from_millis(20));
            return LaunchError::Component(format!("{} before the run began", p.describe_exit()));
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    LaunchError::Component(format!(
        "{} (pid {}) closed its stdout before it reported ready: it failed to start",
        p.label,
        p.child.id()
    ))
}

// one job: the launcher's lockstep loop across processes: samples in, figures and recording out,
// each component's end or failure judged where it is seen, over state every arm shares.
fn supervise(
    cfg: &Configs,
    session: &mut Session,
    procs: &mut [Proc],
    readers: &Readers,
    asm: &mut Assembly,
    stall: Duration,
) -> Result<Stop, LaunchError> {
    let steps = cfg.plant.steps;
    let mut row = StepRow::new(
        cfg.layout,
        cfg.observers.len(),
        readers.controller.is_some(),
    );
    let mut last_progress = Instant::now();
    let pgids: Vec<u32> = procs.iter().map(|p| p.child.id()).collect();
    let mut watch: Option<liveness::Watch> = None;
    loop {
        // In chunks, yielding the core between them: the ring's processes, spinning on it, get
        // it back within a chunk's work (tens of µs) instead of after the whole batch.
        let mut got = 0;
        loop {
            let chunk = readers.drain_up_to(asm, CHUNK)?;
            got += chunk;
            let made = asm.assemble(&mut row, session)?;
            if made > 0 {
                last_progress = Instant::now();
            }
            if let Some(w) = session.diverged.take() {
                stop_all(procs);
                return Ok(Stop::Diverged(w));
            }
            if chunk == 0 && made == 0 {
                break;
            }
            std::thread::yield_now();
        }
        if asm.next == steps {
            // The plant's end sample (step K) closes the last step's timing; a plant that has
            // exited without one ends the run all the same.
            if let Some(h) = asm.end(&mut row)? {
                session.close_last(&h)?;
                return Ok(Stop::Completed);
            }
            if procs[0].status.is_some() {
                return Ok(Stop::Completed);
            }
        }
        if let Some(sig) = interrupt::received() {
            return Ok(Stop::Interrupted(sig));
        }
        // A component that ended before the last step ends the run.
        for i in 0..procs.len() {
            if procs[i].status.is_some() {
                continue;
            }
            let Ok(Some(st)) = procs[i].child.try_wait() else {
                continue;
            };
            procs[i].status = Some(st);
            // Status 0 is the end of its part only when it published all of it; collect what it
            // published before it went (its last samples may still be on their way).
            readers.drain_all(asm)?;
            asm.assemble(&mut row, session)?;
            if st.success() && asm.published_all(i) {
                continue;
            }
            std::thread::sleep(Duration::from_millis(20));
            readers.drain_all(asm)?;
            asm.assemble(&mut row, session)?;
            if st.success() && asm.published_all(i) {
                continue;
            }
            stop_all(procs);
            // A component that stopped on another's broken sample (the plant reads every
            // observer) is not the one to name.
            if let Some(e) = asm.queued_violation(&row) {
                return Err(e);
            }
            let mut what = procs[i].describe_exit();
            if st.success() {
                let last = asm
                    .queue(i)
                    .last
                    .map_or("none".to_string(), |l| format!("of step {l}"));
                what += &format!(" before the end of the run (its last sample: {last})");
            }
            let last = if asm.next == 0 {
                "no step completed".to_string()
            } else {
                format!("last completed step {}", asm.next - 1)
            };
            if i == 0 && st.code() == Some(plant::shell::EXIT_DIVERGED) {
                return Ok(Stop::Diverged(format!("{what} ({last})")));
            }
            return Ok(Stop::Failed(format!("{what}; {last}")));
        }
        if procs.iter().all(|p| p.status.is_some()) && got == 0 {
            return Ok(Stop::Failed(format!(
                "every component finished but only {} of {steps} steps arrived",
                asm.next
            )));
        }
        let quiet = last_progress.elapsed();
        if quiet <= STALL_BLOCKED {
            watch = None;
        } else {
            let missing = asm.missing();
            let last = if asm.next == 0 {
                "no step completed".to_string()
            } else {
                format!("last completed step {}", asm.next - 1)
            };
            let verdict = match missing {
                Some(i) => watch
                    .get_or_insert_with(|| liveness::Watch::new(&pgids))
                    .judge(&pgids, i),
                None => Some(liveness::Verdict::Blocked),
            };
            let why = match verdict {
                None => None,
                Some(liveness::Verdict::Busy) if quiet <= stall => None,
                Some(liveness::Verdict::Busy) => Some(format!(
                    "published no sample for step {} within {} s although it ran or waited for a core (the stall limit: stall_timeout in the scenario, --stall-timeout); {last}",
                    asm.next,
                    lti::eig::sig(stall.as_secs_f64())
                )),
                Some(v) => {
                    let state = if v == liveness::Verdict::Stopped {
                        "it is stopped"
                    } else {
                        "it is asleep and used no CPU for the last second"
                    };
                    let hint = if missing == Some(0) {
                        " (a plant blocked publishing to a component that stopped reading its samples shows as this too)"
                    } else {
                        ""
                    };
                    Some(format!(
                        "published no sample for step {} within {} s and {state}; {last}{hint}",
                        asm.next,
                        STALL_BLOCKED.as_secs()
                    ))
                }
            };
            if let Some(why) = why {
                let who = missing
                    .map_or_else(|| "a component".to_string(), |i| procs[i].describe_stall());
                stop_all(procs);
                return Ok(Stop::Failed(format!("{who} {why}")));
            }
        }
        std::thread::sleep(POLL);
    }
}

fn to_json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("configurations serialise")
}
