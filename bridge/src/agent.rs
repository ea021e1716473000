//! The agent: runs on a host that takes part in runs, as `launcher agent --host NAME --listen
//! tcp/ADDRESS:PORT`. It is a Zenoh router listening on that one endpoint (nothing else), holds
//! the liveliness token that tells launchers it is there, and starts one worker per component a
//! launcher asks for. Workers are its children and die with it (SIGTERM: they stop their
//! component and remove its run space first).

use std::io::Write;
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use zenoh::Wait;

use crate::keys;
use crate::proxy::StartRequest;
use crate::session::{open, Role};

static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_term(_: libc::c_int) {
    STOP.store(true, Ordering::Relaxed);
}

/// Runs the agent until SIGTERM or SIGINT; returns the exit code.
pub fn run(host: &str, listen: &str) -> i32 {
    if let Err(e) = keys::check_host(host) {
        eprintln!("agent: --host: {e}");
        return 2;
    }
    // SAFETY: the handler only stores to an atomic.
    unsafe {
        libc::signal(libc::SIGTERM, on_term as *const () as libc::sighandler_t);
        libc::signal(libc::SIGINT, on_term as *const () as libc::sighandler_t);
    }
    match serve(host, listen) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("agent {host}: {e}");
            3
        }
    }
}

fn serve(host: &str, listen: &str) -> Result<(), String> {
    let z = open(Role::Router { listen }).map_err(|e| format!("cannot listen on {e}"))?;
    let _token = z.liveliness().declare_token(keys::agent(host)).wait().map_err(|e| e.to_string())?;
    let starts = z.declare_queryable(keys::start(host)).wait().map_err(|e| e.to_string())?;
    eprintln!("agent {host}: listening on {listen}");
    let mut workers: Vec<Child> = Vec::new();
    while !STOP.load(Ordering::Relaxed) {
        workers.retain_mut(|w| matches!(w.try_wait(), Ok(None)));
        let Ok(Some(query)) = starts.recv_timeout(Duration::from_millis(100)) else { continue };
        let text = query.payload().and_then(|p| p.try_to_string().ok()).map(|s| s.to_string()).unwrap_or_default();
        let answer = match serde_json::from_str::<StartRequest>(&text) {
            Ok(_) => worker(listen, &text).map(|w| workers.push(w)),
            Err(e) => Err(format!("bad start request: {e}")),
        };
        let _ = match answer {
            Ok(()) => query.reply(keys::start(host), "started").wait(),
            Err(e) => query.reply_err(e).wait(),
        };
    }
    for w in &mut workers {
        // SAFETY: signals our own child.
        unsafe {
            libc::kill(w.id() as i32, libc::SIGTERM);
        }
    }
    for w in &mut workers {
        let _ = w.wait();
    }
    Ok(())
}

/// Starts a worker with the request on its stdin; it dies (SIGTERM) with the agent.
fn worker(listen: &str, request: &str) -> Result<Child, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut cmd = Command::new(exe);
    cmd.args(["worker", "--connect", listen]).stdin(Stdio::piped());
    // SAFETY: one async-signal-safe system call between fork and exec.
    unsafe {
        cmd.pre_exec(|| {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
            Ok(())
        });
    }
    let mut child = cmd.spawn().map_err(|e| format!("cannot start a worker: {e}"))?;
    let mut stdin = child.stdin.take().expect("piped");
    stdin.write_all(request.as_bytes()).map_err(|e| format!("worker: {e}"))?;
    Ok(child)
}
