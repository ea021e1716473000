//! A started component: how it is started (PROTOCOL.md §1), described when it fails, and
//! stopped with its whole process group.

use std::io::{BufRead, BufReader, Read};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};

use lockstep::RunSpace;

use super::super::envelope::{Launchable, Program};
use super::placement::pin_self;
use crate::error::LaunchError;

/// How much of a component's stderr is kept for the message that quotes its last line.
const STDERR_KEPT: usize = 4096;

/// A started component.
pub(super) struct Proc {
    pub(super) label: String,
    pub(super) child: Child,
    stderr: Arc<Mutex<String>>,
    pub(super) status: Option<ExitStatus>,
}

impl Proc {
    pub(super) fn describe_exit(&self) -> String {
        let status = self.status.expect("exited");
        let how = match (status.code(), status.signal()) {
            (Some(code), _) => format!("exited with status {code}"),
            (None, Some(sig)) => format!("was killed by signal {sig} ({})", signal_name(sig)),
            _ => "ended".into(),
        };
        let err = self
            .stderr
            .lock()
            .map(|s| s.trim().lines().last().unwrap_or("").to_string())
            .unwrap_or_default();
        if err.is_empty() {
            format!("{} (pid {}) {how}", self.label, self.child.id())
        } else {
            format!("{} (pid {}) {how}: {err}", self.label, self.child.id())
        }
    }

    /// "observer 'uio' (pid N, stopped)": the process named with the state the kernel reports.
    pub(super) fn describe_stall(&self) -> String {
        let pid = self.child.id();
        // /proc/<pid>/stat: "pid (comm) S ..."; the state letter follows the last ')'.
        let state = std::fs::read_to_string(format!("/proc/{pid}/stat"))
            .ok()
            .and_then(|s| {
                s.rsplit_once(')')
                    .and_then(|(_, rest)| rest.trim_start().chars().next())
            });
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
pub(super) fn stop_all(procs: &mut [Proc]) {
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
    let exe = std::env::current_exe().unwrap_or_else(|_| lockstep::programs::LAUNCHER.into());
    let sibling = exe.with_file_name(lockstep::programs::builtin(kind));
    if sibling.is_file() {
        Command::new(sibling)
    } else {
        let mut c = Command::new(exe);
        c.args(["component", kind]);
        c
    }
}

/// An external command's program: a bare name (no `/`) of a program built beside the launcher —
/// a kit component of this workspace, also by its name before the `uio-` names
/// ([`lockstep::programs::renamed`]) — is that one; anything else as given (a bare name then
/// goes through `PATH`, a relative path from the scenario's folder).
fn program_path(program: &str, workdir: &Path) -> std::path::PathBuf {
    if !program.contains('/') {
        if let Ok(exe) = std::env::current_exe() {
            // The renamed program first: a build directory may still hold the old binary.
            let names = lockstep::programs::renamed(program)
                .into_iter()
                .chain(std::iter::once(program.to_string()));
            for name in names {
                let sibling = exe.with_file_name(name);
                if sibling.is_file() {
                    return sibling;
                }
            }
        }
        return program.into();
    }
    // Relative to the scenario's folder, spelled out: how a relative program resolves together
    // with a changed working directory is left to the platform.
    workdir.join(program)
}

/// Starts a component (PROTOCOL.md §1): our binary, or the scenario's command in the scenario
/// file's folder; either way with the protocol's environment, in its own process group.
pub(super) fn spawn(
    c: &Launchable,
    workdir: &Path,
    space: &RunSpace,
    cpu: Option<usize>,
    tx: &mpsc::Sender<(usize, Option<String>)>,
    index: usize,
) -> Result<Proc, LaunchError> {
    let label = c.label.clone();
    let mut cmd = match &c.program {
        Program::Builtin(kind) => {
            let mut cmd = component_command(kind);
            cmd.args([
                "--run",
                space.id(),
                "--name",
                &c.config.name,
                "--wait",
                &c.config.wait,
            ]);
            cmd
        }
        Program::External(p) => {
            let mut cmd = Command::new(program_path(&p.command[0], workdir));
            cmd.args(&p.command[1..]).current_dir(workdir);
            cmd
        }
        Program::Remote(kind, r) => {
            let mut cmd = Command::new(crate::run::bridge_path());
            cmd.args([
                "remote",
                "--host",
                &r.host,
                "--connect",
                &r.endpoint,
                "--builtin",
                kind,
            ]);
            cmd
        }
    };
    cmd.envs(c.config.launch_env(space))
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
            Program::Remote(..) => format!(" ({}: build it with `cargo build --release --workspace`)", crate::run::bridge_path().display()),
            Program::Builtin(_) => String::new(),
        };
        LaunchError::Component(format!("cannot start {label}{what}: {e}"))
    })?;
    let out = child.stdout.take().expect("piped");
    let tx = tx.clone();
    std::thread::spawn(move || {
        // Until `ready` the lines go to the handshake, and the end of stdout before it (`None`)
        // says at once that the component cannot start; after it a component's stdout is read
        // and dropped, so a chatty component neither blocks on a full pipe nor fills memory.
        let mut lines = BufReader::new(out).lines().map_while(Result::ok);
        for line in lines.by_ref() {
            let ready = line.trim() == "ready";
            if tx.send((index, Some(line))).is_err() || ready {
                lines.for_each(drop);
                return;
            }
        }
        let _ = tx.send((index, None));
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
    Ok(Proc {
        label,
        child,
        stderr,
        status: None,
    })
}
