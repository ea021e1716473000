//! `--mode processes`: one process per component, in lockstep over iceoryx2, supervised.
//!
//! The launcher creates the run's space and its own recording subscribers first, starts the
//! components (each in its own process group, so a terminal's Ctrl-C reaches only the launcher),
//! waits until every component reports `ready`, then says `go`. While the run goes it drains
//! the recording subscribers and polls the children: a component that exits early or is killed
//! stops the run within a poll interval, the others are killed, and the recording is closed.

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use lockstep::{cleanup_dead_runs, Bus, Header, Reader, RunSpace, Wait, WireHeader, PROTOCOL_VERSION};
use scenario::Scenario;

use super::configs::Configs;
use super::envelope::{envelopes, Launchable, Program};
use super::session::Session;
use super::{interrupt, Stop};
use crate::error::LaunchError;
use recording::write::StepRow;

/// How long components may take to report ready.
const READY_TIMEOUT: Duration = Duration::from_secs(20);
/// How long the run may make no progress before it is declared stuck: shorter than a
/// component's own inlet timeout (10 s), so the launcher names the stall first.
const STALL_TIMEOUT: Duration = Duration::from_secs(5);
/// Sleep between drains. The launcher shares the cores with the lockstep ring, and every
/// wake-up takes a core from it for a moment: drain rarely, in large batches. At the fastest
/// step rate measured (~250k steps/s) 5 ms is ~1300 samples, well inside the recorder's buffer.
const POLL: Duration = Duration::from_millis(5);
/// How much of a component's stderr is kept for the message that quotes its last line.
const STDERR_KEPT: usize = 4096;

/// A started component.
struct Proc {
    label: String,
    child: Child,
    stderr: Arc<Mutex<String>>,
    status: Option<ExitStatus>,
}

impl Proc {
    fn describe_exit(&self) -> String {
        let status = self.status.expect("exited");
        let how = match (status.code(), status.signal()) {
            (Some(code), _) => format!("exited with status {code}"),
            (None, Some(sig)) => format!("was killed by signal {sig} ({})", signal_name(sig)),
            _ => "ended".into(),
        };
        let err = self.stderr.lock().map(|s| s.trim().lines().last().unwrap_or("").to_string()).unwrap_or_default();
        if err.is_empty() { format!("{} (pid {}) {how}", self.label, self.child.id()) } else { format!("{} (pid {}) {how}: {err}", self.label, self.child.id()) }
    }

    /// "observer 'uio' (pid N, stopped)": the process named with the state the kernel reports.
    fn describe_stall(&self) -> String {
        let pid = self.child.id();
        // /proc/<pid>/stat: "pid (comm) S ..."; the state letter follows the last ')'.
        let state = std::fs::read_to_string(format!("/proc/{pid}/stat"))
            .ok()
            .and_then(|s| s.rsplit_once(')').and_then(|(_, rest)| rest.trim_start().chars().next()));
        let state = match state {
            Some('T') | Some('t') => ", stopped",
            Some('D') => ", in uninterruptible sleep",
            Some('Z') => ", exited",
            _ => "",
        };
        format!("{} (pid {pid}{state})", self.label)
    }
}

fn signal_name(sig: i32) -> &'static str {
    match sig {
        libc::SIGKILL => "SIGKILL",
        libc::SIGTERM => "SIGTERM",
        libc::SIGINT => "SIGINT",
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGABRT => "SIGABRT",
        libc::SIGBUS => "SIGBUS",
        libc::SIGFPE => "SIGFPE",
        libc::SIGPIPE => "SIGPIPE",
        _ => "signal",
    }
}

/// Kills and reaps every child still running; safe to call twice.
fn stop_all(procs: &mut [Proc]) {
    for p in procs.iter_mut() {
        // The whole process group, also of a component that has exited already: an external
        // command may have started children of its own (a shell script, an interpreter's
        // workers) that outlive it. A group that is gone (ESRCH) is fine.
        // SAFETY: kill(2) on the group this launcher created for the child (pgid = its pid).
        unsafe { libc::kill(-(p.child.id() as i32), libc::SIGKILL) };
        if p.status.is_none() {
            let _ = p.child.kill();
        }
    }
    for p in procs.iter_mut() {
        if p.status.is_none() {
            p.status = p.child.wait().ok();
        }
    }
}

/// The command that starts a component: its binary next to the launcher's, or, when only the
/// launcher was built (`cargo run`), the launcher itself in component mode.
fn component_command(kind: &str) -> Command {
    let exe = std::env::current_exe().unwrap_or_else(|_| "launcher".into());
    let sibling = exe.with_file_name(kind);
    if sibling.is_file() {
        Command::new(sibling)
    } else {
        let mut c = Command::new(exe);
        c.args(["component", kind]);
        c
    }
}

/// An external command's program: a bare name (no `/`) of a program built beside the launcher —
/// a kit component of this workspace — is that one; anything else as given (a bare name then
/// goes through `PATH`, a relative path from the scenario's folder).
fn program_path(program: &str, workdir: &Path) -> std::path::PathBuf {
    if !program.contains('/') {
        if let Ok(exe) = std::env::current_exe() {
            let sibling = exe.with_file_name(program);
            if sibling.is_file() {
                return sibling;
            }
        }
        return program.into();
    }
    // Relative to the scenario's folder, spelled out: how a relative program resolves together
    // with a changed working directory is left to the platform.
    workdir.join(program)
}

/// The CPUs this process may run on.
fn allowed_cpus() -> Vec<usize> {
    // SAFETY: sched_getaffinity fills the set we own.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Vec::new();
        }
        (0..libc::CPU_SETSIZE as usize).filter(|&c| libc::CPU_ISSET(c, &set)).collect()
    }
}

/// Restricts the calling process to one CPU (best effort: a refusal leaves it where it is).
/// Called in the child between fork and exec, so the component starts where it will run.
fn pin_self(cpu: usize) {
    // SAFETY: the set is initialised before use; sched_setaffinity is a plain system call
    // (async-signal-safe) and only reads it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}

/// Which CPU each component runs on (None: wherever the scheduler likes).
///
/// Only the ring — plant, the controller's observer, controller (or, open loop, the plant and
/// its observers) — is placed; followers sleep between batches and float. With a CPU per ring
/// process each gets its own. With two, the plant gets one to itself and the rest of the ring
/// shares the other: only one process switch then lies on each step's critical path (a switch
/// between processes costs ~2.5 µs on the 2-vCPU machines this was measured on). In between,
/// the plant keeps the first CPU and the rest of the ring takes the others in turn.
fn placement(cfg: &Configs, pin: bool) -> (Option<usize>, Vec<Option<usize>>, Option<usize>) {
    let cpus = allowed_cpus();
    let nobs = cfg.observers.len();
    if !pin || cpus.len() < 2 {
        return (None, vec![None; nobs], None);
    }
    let ring_observers: Vec<bool> = cfg.plant.followers.iter().map(|f| !f).collect();
    let ring = 1 + ring_observers.iter().filter(|&&r| r).count() + usize::from(cfg.plant.controller);
    let mut next = 1;
    let mut cpu_for = |_: ()| {
        let c = if cpus.len() >= ring { cpus[next] } else { cpus[1 + (next - 1) % (cpus.len() - 1)] };
        next += 1;
        Some(c)
    };
    let observers = ring_observers.iter().map(|&r| if r { cpu_for(()) } else { None }).collect();
    let controller = if cfg.plant.controller { cpu_for(()) } else { None };
    (Some(cpus[0]), observers, controller)
}

/// Starts a component (PROTOCOL.md §1): our binary, or the scenario's command in the scenario
/// file's folder; either way with the protocol's environment, in its own process group.
fn spawn(c: &Launchable, workdir: &Path, space: &RunSpace, cpu: Option<usize>, tx: &mpsc::Sender<(usize, String)>, index: usize) -> Result<Proc, LaunchError> {
    let label = c.label.clone();
    let mut cmd = match &c.program {
        Program::Builtin(kind) => {
            let mut cmd = component_command(kind);
            cmd.args(["--run", space.id(), "--name", &c.config.name, "--wait", &c.config.wait]);
            cmd
        }
        Program::External(p) => {
            let mut cmd = Command::new(program_path(&p.command[0], workdir));
            cmd.args(&p.command[1..]).current_dir(workdir);
            cmd
        }
    };
    cmd.env("UIO_PROTOCOL", PROTOCOL_VERSION.to_string())
        .env("UIO_RUN", space.id())
        .env("UIO_NAME", &c.config.name)
        .env("UIO_ROLE", c.config.role.name())
        .env("UIO_CONFIG", space.config_path(&c.file()))
        .env(lockstep::RUNS_DIR_ENV, space.dir().parent().unwrap_or(space.dir()))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0);
    if let Some(cpu) = cpu {
        // SAFETY: the closure makes one async-signal-safe system call and allocates nothing.
        unsafe {
            cmd.pre_exec(move || {
                pin_self(cpu);
                Ok(())
            });
        }
    }
    let mut child = cmd.spawn().map_err(|e| {
        let what = match &c.program {
            Program::External(p) if !p.command[0].contains('/') && e.kind() == std::io::ErrorKind::NotFound => format!(
                " ({}: neither beside the launcher nor in PATH; a kit component of this workspace is built with `cargo build --release --workspace`)",
                scenario::untrusted::quoted(&p.command[0])
            ),
            Program::External(p) => format!(" ({})", scenario::untrusted::quoted(&p.command[0])),
            Program::Builtin(_) => String::new(),
        };
        LaunchError::Component(format!("cannot start {label}{what}: {e}"))
    })?;
    let out = child.stdout.take().expect("piped");
    let tx = tx.clone();
    std::thread::spawn(move || {
        // Until `ready` the lines go to the handshake; after it a component's stdout is read
        // and dropped, so a chatty component neither blocks on a full pipe nor fills memory.
        let mut lines = BufReader::new(out).lines().map_while(Result::ok);
        for line in lines.by_ref() {
            let ready = line.trim() == "ready";
            if tx.send((index, line)).is_err() || ready {
                break;
            }
        }
        lines.for_each(drop);
    });
    let mut err = child.stderr.take().expect("piped");
    let stderr = Arc::new(Mutex::new(String::new()));
    let sink = stderr.clone();
    std::thread::spawn(move || {
        let mut buf = [0u8; 4096];
        while let Ok(n) = err.read(&mut buf) {
            if n == 0 {
                break;
            }
            if let Ok(mut s) = sink.lock() {
                s.push_str(&String::from_utf8_lossy(&buf[..n]));
                // Only the end is quoted in messages: keep the last few KiB.
                if s.len() > 2 * STDERR_KEPT {
                    let mut cut = s.len() - STDERR_KEPT;
                    while !s.is_char_boundary(cut) {
                        cut += 1;
                    }
                    s.drain(..cut);
                }
            }
        }
    });
    Ok(Proc { label, child, stderr, status: None })
}

/// The samples received from one component, in order. Their value buffers are recycled, so
/// once the queue has been as deep as it gets, receiving allocates nothing.
struct Queue {
    /// How messages name the component.
    label: String,
    /// Names of its values (1-based), for messages.
    names: Vec<String>,
    items: VecDeque<(WireHeader, Vec<f64>)>,
    free: Vec<Vec<f64>>,
    /// The highest step any of its samples carried.
    last: Option<u64>,
}

impl Queue {
    fn new(c: &Launchable) -> Self {
        Queue { label: c.label.clone(), names: c.config.publishes.names.clone(), items: VecDeque::new(), free: Vec::new(), last: None }
    }

    fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Moves every pending sample of `reader` in; returns how many there were.
    fn drain(&mut self, reader: &Reader) -> Result<usize, LaunchError> {
        let (items, free, last) = (&mut self.items, &mut self.free, &mut self.last);
        reader
            .drain(|h, v| {
                let mut buf = free.pop().unwrap_or_default();
                buf.clear();
                buf.extend_from_slice(v);
                *last = Some(last.map_or(h.step, |l| l.max(h.step)));
                items.push_back((*h, buf));
            })
            .map_err(|e| LaunchError::Component(format!("{}: {e}", self.label)))
    }

    /// Takes the sample of step `k` into `out`, checking it against the protocol (PROTOCOL.md
    /// §6): the step, the protocol version, the number of values, and that each is finite.
    fn take(&mut self, k: u64, out: &mut [f64]) -> Result<Header, LaunchError> {
        let (h, values) = self.items.pop_front().expect("non-empty");
        let broken = |why: String| LaunchError::Component(format!("{} broke the protocol at step {k}: {why}", self.label));
        if h.protocol != PROTOCOL_VERSION {
            return Err(broken(format!("its sample says protocol version {}, the run speaks {PROTOCOL_VERSION}", h.protocol)));
        }
        if h.step != k {
            return Err(broken(format!("its sample is of step {}", h.step)));
        }
        if values.len() != out.len() {
            return Err(broken(format!("its sample has {} values, the run's configuration says {}", values.len(), out.len())));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            let name = self.names.get(i).map_or(String::new(), |n| format!(" ({})", scenario::untrusted::quoted(n)));
            return Err(broken(format!("value {}{name} is {}", i + 1, values[i])));
        }
        out.copy_from_slice(&values);
        self.free.push(values);
        Ok(Header::of(&h, 0))
    }

    /// Checks that the sample of step k was made from its input's sample k: it cannot have taken
    /// its input (`taken_ns`) before that input was sent. A component that publishes without
    /// reading would otherwise go unnoticed until its full subscriber buffer blocks the plant.
    fn made_after(&self, k: u64, own: &Header, input: &Header, input_label: &str) -> Result<(), LaunchError> {
        if own.taken_ns < input.sent_ns {
            return Err(LaunchError::Component(format!(
                "{} broke the protocol at step {k}: it published the step before {input_label}'s sample {k} was sent (it does not read its input)",
                self.label
            )));
        }
        Ok(())
    }
}

/// Per-component queues of received samples, assembled into rows in step order.
struct Assembly {
    plant: Queue,
    observers: Vec<Queue>,
    controller: Option<Queue>,
    next: u64,
    /// Steps K of the run: the plant's end sample (step K) is not a row.
    steps: u64,
    /// Sample period: the recording's time is k·dt, whatever a plant's header says.
    dt: f64,
    /// Index of the observer the controller reads.
    controller_observer: Option<usize>,
}

impl Assembly {
    /// The component whose sample for the next step is missing, first in the order samples flow
    /// within a step (plant, observers, controller): the others wait on it. Indices as the
    /// launcher spawns them.
    fn missing(&self) -> Option<usize> {
        if self.plant.is_empty() {
            return Some(0);
        }
        if let Some(i) = self.observers.iter().position(|q| q.is_empty()) {
            return Some(1 + i);
        }
        self.controller.as_ref().filter(|q| q.is_empty()).map(|_| 1 + self.observers.len())
    }

    /// Moves every complete step into the session.
    fn assemble(&mut self, row: &mut StepRow, session: &mut Session) -> Result<usize, LaunchError> {
        let mut done = 0;
        loop {
            if self.next >= self.steps {
                return Ok(done);
            }
            let ready = !self.plant.is_empty() && self.observers.iter().all(|q| !q.is_empty()) && self.controller.as_ref().is_none_or(|q| !q.is_empty());
            if !ready {
                return Ok(done);
            }
            let k = self.next;
            row.plant_hdr = self.plant.take(k, &mut row.plant)?;
            row.k = k;
            row.t = k as f64 * self.dt;
            for (i, q) in self.observers.iter_mut().enumerate() {
                row.xhat_hdr[i] = q.take(k, &mut row.xhat[i])?;
                q.made_after(k, &row.xhat_hdr[i], &row.plant_hdr, "the plant")?;
            }
            if let Some(q) = &mut self.controller {
                row.u_hdr = q.take(k, &mut row.u)?;
                if let Some(c) = self.controller_observer {
                    q.made_after(k, &row.u_hdr, &row.xhat_hdr[c], &self.observers[c].label)?;
                }
            }
            session.record(row)?;
            self.next += 1;
            done += 1;
        }
    }

    /// The plant's end sample (step K), checked like every other, once every step was assembled.
    fn end(&mut self, row: &mut StepRow) -> Result<Option<Header>, LaunchError> {
        if self.plant.is_empty() {
            return Ok(None);
        }
        self.plant.take(self.steps, &mut row.plant).map(Some)
    }

    /// Whether component `i` (spawn order) has published its last sample: step K for the plant
    /// (its end sample), K − 1 for the others.
    fn published_all(&self, i: usize) -> bool {
        let nobs = self.observers.len();
        let (q, last) = match i {
            0 => (&self.plant, self.steps),
            i if i <= nobs => (&self.observers[i - 1], self.steps.saturating_sub(1)),
            _ => (self.controller.as_ref().expect("a controller"), self.steps.saturating_sub(1)),
        };
        q.last.is_some_and(|l| l >= last)
    }

    fn queue(&self, i: usize) -> &Queue {
        let nobs = self.observers.len();
        match i {
            0 => &self.plant,
            i if i <= nobs => &self.observers[i - 1],
            _ => self.controller.as_ref().expect("a controller"),
        }
    }
}

/// The launcher's recording subscribers, one per topic.
struct Readers<'a> {
    plant: &'a Reader,
    observers: &'a [Reader],
    controller: Option<&'a Reader>,
}

impl Readers<'_> {
    /// Moves every pending sample into its queue; returns how many there were.
    fn drain_all(&self, asm: &mut Assembly) -> Result<usize, LaunchError> {
        let mut got = asm.plant.drain(self.plant)?;
        for (r, q) in self.observers.iter().zip(asm.observers.iter_mut()) {
            got += q.drain(r)?;
        }
        if let (Some(r), Some(q)) = (self.controller, asm.controller.as_mut()) {
            got += q.drain(r)?;
        }
        Ok(got)
    }
}

/// Runs the scenario across processes.
pub fn run(s: &Scenario, cfg: &Configs, session: &mut Session, wait: Wait, pin: bool) -> Result<Stop, LaunchError> {
    cleanup_dead_runs();
    let space = RunSpace::create().map_err(|e| LaunchError::Component(e.to_string()))?;
    let result = run_in(s, &space, cfg, session, wait, pin);
    space.remove();
    result
}

fn run_in(s: &Scenario, space: &RunSpace, cfg: &Configs, session: &mut Session, wait: Wait, pin: bool) -> Result<Stop, LaunchError> {
    let ipc = |e: lockstep::LockstepError| LaunchError::Component(e.to_string());
    let components = envelopes(s, cfg, space, wait);
    for c in &components {
        space.write_config(&c.file(), &to_json(&c.config)).map_err(ipc)?;
    }

    // The recorder's subscribers exist before any component can publish: they create every
    // service of the run (PROTOCOL.md §4).
    let bus = Bus::join(space, "launcher", Wait::Yield).map_err(ipc)?;
    space.restrict_shm().map_err(ipc)?;
    let readers: Vec<Reader> = components.iter().map(|c| bus.reader(&c.config.publishes.service)).collect::<Result<_, _>>().map_err(ipc)?;
    let nobs = s.observers.len();

    let (tx, rx) = mpsc::channel();
    let mut procs: Vec<Proc> = Vec::new();
    let (plant_cpu, observer_cpus, controller_cpu) = placement(cfg, pin);
    let cpus: Vec<Option<usize>> = std::iter::once(plant_cpu).chain(observer_cpus).chain(s.controller.as_ref().map(|_| controller_cpu)).collect();
    let workdir = s.path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let workdir = &std::path::absolute(workdir).unwrap_or_else(|_| workdir.to_path_buf());
    let result = (|| {
        for (i, (c, &cpu)) in components.iter().zip(&cpus).enumerate() {
            procs.push(spawn(c, workdir, space, cpu, &tx, i)?);
        }
        handshake(&mut procs, &rx)?;
        let r = Readers { plant: &readers[0], observers: &readers[1..1 + nobs], controller: readers.get(1 + nobs) };
        let mut asm = Assembly {
            plant: Queue::new(&components[0]),
            observers: components[1..1 + nobs].iter().map(Queue::new).collect(),
            controller: components.get(1 + nobs).map(Queue::new),
            next: 0,
            steps: s.steps,
            dt: s.dt,
            controller_observer: s.controller.as_ref().and_then(|c| s.observers.iter().position(|o| o.name == c.observer)),
        };
        supervise(cfg, session, &mut procs, &r, &mut asm)
    })();
    stop_all(&mut procs);
    drop((readers, bus));
    result
}

/// Waits for every component's `ready`, then tells them all `go`.
fn handshake(procs: &mut [Proc], rx: &mpsc::Receiver<(usize, String)>) -> Result<(), LaunchError> {
    let deadline = Instant::now() + READY_TIMEOUT;
    let mut ready = vec![false; procs.len()];
    while !ready.iter().all(|&r| r) {
        if let Some(sig) = interrupt::received() {
            return Err(LaunchError::Interrupted(format!("{sig} received while the components started")));
        }
        for p in procs.iter_mut() {
            if p.status.is_none()
                && let Ok(Some(st)) = p.child.try_wait()
            {
                p.status = Some(st);
                // Give its stderr reader a moment to collect the message.
                std::thread::sleep(Duration::from_millis(20));
                return Err(LaunchError::Component(format!("{} before the run began", p.describe_exit())));
            }
        }
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok((i, line)) if line.trim() == "ready" => ready[i] = true,
            Ok(_) | Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {}
        }
        if Instant::now() > deadline {
            let slow: Vec<&str> = procs.iter().zip(&ready).filter(|(_, r)| !**r).map(|(p, _)| p.label.as_str()).collect();
            return Err(LaunchError::Component(format!("{} did not report ready within {} s", slow.join(", "), READY_TIMEOUT.as_secs())));
        }
    }
    for p in procs.iter_mut() {
        let mut stdin = p.child.stdin.take().expect("piped");
        stdin.write_all(b"go\n").and_then(|_| stdin.flush()).map_err(|e| LaunchError::Component(format!("{}: {e}", p.label)))?;
    }
    Ok(())
}

fn supervise(cfg: &Configs, session: &mut Session, procs: &mut [Proc], readers: &Readers, asm: &mut Assembly) -> Result<Stop, LaunchError> {
    let steps = cfg.plant.plant.steps;
    let mut row = StepRow::new(cfg.layout, readers.observers.len(), readers.controller.is_some());
    let mut last_progress = Instant::now();
    loop {
        let got = readers.drain_all(asm)?;
        if asm.assemble(&mut row, session)? > 0 {
            last_progress = Instant::now();
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
            let Ok(Some(st)) = procs[i].child.try_wait() else { continue };
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
            let mut what = procs[i].describe_exit();
            if st.success() {
                let last = asm.queue(i).last.map_or("none".to_string(), |l| format!("of step {l}"));
                what += &format!(" before the end of the run (its last sample: {last})");
            }
            let last = if asm.next == 0 { "no step completed".to_string() } else { format!("last completed step {}", asm.next - 1) };
            if i == 0 && st.code() == Some(plant::shell::EXIT_DIVERGED) {
                return Ok(Stop::Diverged(format!("{what} ({last})")));
            }
            return Ok(Stop::Failed(format!("{what}; {last}")));
        }
        if procs.iter().all(|p| p.status.is_some()) && got == 0 {
            return Ok(Stop::Failed(format!("every component finished but only {} of {steps} steps arrived", asm.next)));
        }
        if last_progress.elapsed() > STALL_TIMEOUT {
            let missing = asm.missing();
            let who = missing.map_or_else(|| "a component".to_string(), |i| procs[i].describe_stall());
            let hint = if missing == Some(0) { " (a plant blocked publishing to a component that stopped reading its samples shows as this too)" } else { "" };
            stop_all(procs);
            let last = if asm.next == 0 { "no step completed".to_string() } else { format!("last completed step {}", asm.next - 1) };
            return Ok(Stop::Failed(format!("{who} published no sample for step {} within {} s; {last}{hint}", asm.next, STALL_TIMEOUT.as_secs())));
        }
        std::thread::sleep(POLL);
    }
}

fn to_json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("configurations serialise")
}
