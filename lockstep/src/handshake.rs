//! How a component process is started and synchronised by the launcher.
//!
//! The launcher starts each component with `UIO_RUN`, `UIO_NAME` and the rest of PROTOCOL.md §1
//! in its environment (our built-in components also get `--run <id> --name <name> --wait
//! <strategy>`), its stdin and stdout piped. The component reads its configuration from the run directory, creates
//! all its ports, writes `ready` on stdout, and starts stepping only when it reads `go` on stdin:
//! by then every subscriber of the run exists, so no first sample is lost. If the launcher dies,
//! the kernel kills the component (PR_SET_PDEATHSIG).

use std::io::{BufRead, IsTerminal, Write};

use crate::error::LockstepError;
use crate::run::RunSpace;
use crate::wait::Wait;

/// What a component was told on its command line.
#[derive(Debug, Clone)]
pub struct Launch {
    /// The run it belongs to.
    pub run: RunSpace,
    /// Its name (the observer's name; "plant", "controller").
    pub name: String,
    /// The wait strategy.
    pub wait: Wait,
}

/// Exit code for a component started the wrong way.
pub const EXIT_USAGE: i32 = 2;

/// Parses `--run <id> --name <name> [--wait <w>]`; the error explains how to start a run.
pub fn parse_launch(
    component: &str,
    args: impl IntoIterator<Item = String>,
) -> Result<Launch, String> {
    let how = format!(
        "{component}: this program is one process of a co-simulation and is started by the launcher, \
         e.g. `uio-launcher run scenarios/seed002-sine.toml`"
    );
    let mut run = None;
    let mut name = None;
    let mut wait = Wait::default_for_machine();
    let mut it = args.into_iter();
    while let Some(a) = it.next() {
        let mut value = || {
            it.next()
                .ok_or_else(|| format!("{how} ({a} needs a value)"))
        };
        match a.as_str() {
            "--run" => run = Some(value()?),
            "--name" => name = Some(value()?),
            "--wait" => wait = value()?.parse().map_err(|e| format!("{component}: {e}"))?,
            "-h" | "--help" => return Err(how),
            other => return Err(format!("{how} (unknown argument '{other}')")),
        }
    }
    // A component started by a launcher of PROTOCOL.md gets the same in its environment.
    let run = run
        .or_else(|| std::env::var("UIO_RUN").ok())
        .ok_or_else(|| how.clone())?;
    let name = name.or_else(|| std::env::var("UIO_NAME").ok());
    let run = RunSpace::open(&run).map_err(|e| format!("{how} ({e})"))?;
    // SAFETY: getppid has no preconditions.
    let parent = unsafe { libc::getppid() };
    if run.owner() != Some(parent) {
        return Err(format!(
            "{how} (its parent, pid {parent}, is not the launcher of run '{}')",
            run.id()
        ));
    }
    if std::io::stdin().is_terminal() {
        return Err(format!(
            "{how} (stdin is a terminal, not the launcher's pipe)"
        ));
    }
    Ok(Launch {
        run,
        name: name.unwrap_or_else(|| component.to_string()),
        wait,
    })
}

/// Asks the kernel to kill this process when its parent (the launcher) dies.
pub fn die_with_parent() {
    // SAFETY: prctl(PR_SET_PDEATHSIG) only sets a flag on the calling process.
    unsafe {
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
    }
    // (A parent that died before the flag was set is caught by `parse_launch`: the new parent
    // is then not the run's launcher.)
}

/// Writes `ready`, then blocks until the launcher writes `go` (or closes the pipe).
pub fn ready_then_wait_for_go() -> Result<(), LockstepError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "ready")
        .and_then(|_| out.flush())
        .map_err(|e| LockstepError::Io(format!("stdout: {e}")))?;
    let mut line = String::new();
    std::io::stdin()
        .lock()
        .read_line(&mut line)
        .map_err(|e| LockstepError::Io(format!("stdin: {e}")))?;
    if line.trim() == "go" {
        Ok(())
    } else {
        Err(LockstepError::Io(
            "the launcher stopped the run before it began".into(),
        ))
    }
}
