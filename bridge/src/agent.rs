//! The agent: runs on a host that takes part in runs, as `uio-launcher agent --host NAME --listen
//! quic/ADDRESS:PORT`. It is a Zenoh router listening on that one endpoint (nothing else), admits
//! only peers with the user's credentials ([`crate::credentials`]) under its access rules
//! ([`crate::access`]), holds the liveliness token that tells launchers it is there, and starts
//! one worker per component a launcher asks for — at most `--max-workers` at once, one per run
//! and component, for run ids and names that are plain key chunks. Workers are its children and die with it (SIGTERM: they stop their
//! component and remove its run space first).

use std::io::Write;
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use zenoh::Wait;

use lockstep::component::ComponentConfig;

use crate::access;
use crate::credentials::{self, Credentials, Side};
use crate::keys;
use crate::proxy::StartRequest;
use crate::seal::Secret;
use crate::session::{self, Role, open, secured};

static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_term(_: libc::c_int) {
    STOP.store(true, Ordering::Relaxed);
}

/// How the agent is started (`uio-launcher agent …`).
pub struct Options {
    /// This host's name, as scenarios' `[hosts]` tables call it.
    pub host: String,
    /// The one endpoint to listen on.
    pub listen: String,
    /// The credentials directory (for a `quic/…` endpoint).
    pub credentials: std::path::PathBuf,
    /// Accept a plain `tcp/…` endpoint.
    pub insecure: bool,
    /// Components (workers) this agent runs at once, over every run.
    pub max_workers: usize,
    /// Accept a wildcard listen address.
    pub all_interfaces: bool,
}

/// True for an endpoint whose address is a wildcard (`quic/0.0.0.0:7447`, `tcp/[::]:7447`):
/// it listens on every interface of the host.
pub fn wildcard(endpoint: &str) -> bool {
    let address = endpoint.split_once('/').map_or(endpoint, |(_, a)| a);
    let host = address.rsplit_once(':').map_or(address, |(h, _)| h);
    let host = host.trim_start_matches('[').trim_end_matches(']');
    host.parse::<std::net::IpAddr>()
        .is_ok_and(|ip| ip.is_unspecified())
}

/// Runs the agent until SIGTERM or SIGINT; returns the exit code.
pub fn run(o: &Options) -> i32 {
    if let Err(e) = keys::check_host(&o.host) {
        say!("agent: --host: {e}");
        return 2;
    }
    if wildcard(&o.listen) && !o.all_interfaces {
        say!(
            "agent {}: --listen {}: a wildcard address listens on every interface of this host; give the one address the launcher reaches (e.g. quic/10.0.0.2:7447), or add --all-interfaces",
            o.host,
            o.listen
        );
        return 2;
    }
    let tls = if o.listen.starts_with("tls/") {
        say!(
            "agent {}: --listen {}: {}",
            o.host,
            o.listen,
            session::TLS_OVER_TCP
        );
        return 2;
    } else if secured(&o.listen) {
        match credentials::load(&o.credentials, Side::Agent) {
            Ok(c) => Some(c),
            Err(e) => {
                say!("agent {}: credentials: {e}", o.host);
                return 2;
            }
        }
    } else if o.listen.starts_with("tcp/") && o.insecure {
        say!(
            "agent {}: --insecure: plain TCP, anyone who reaches {} can start components here and read their samples",
            o.host,
            o.listen
        );
        None
    } else if o.listen.starts_with("tcp/") {
        say!(
            "agent {}: --listen {}: plain TCP admits anyone who reaches it; listen on quic/… with credentials (`uio-launcher agent init`), or add --insecure on a network you trust",
            o.host,
            o.listen
        );
        return 2;
    } else {
        say!(
            "agent {}: --listen {}: an endpoint is quic/<address>:<port> (or tcp/… with --insecure)",
            o.host,
            o.listen
        );
        return 2;
    };
    if o.max_workers == 0 {
        say!("agent {}: --max-workers must be at least 1", o.host);
        return 2;
    }
    // SAFETY: the handler only stores to an atomic.
    unsafe {
        libc::signal(libc::SIGTERM, on_term as *const () as libc::sighandler_t);
        libc::signal(libc::SIGINT, on_term as *const () as libc::sighandler_t);
    }
    match serve(o, tls.as_ref()) {
        Ok(()) => 0,
        Err(e) => {
            say!("agent {}: {e}", o.host);
            3
        }
    }
}

fn serve(o: &Options, tls: Option<&Credentials>) -> Result<(), String> {
    let host = o.host.as_str();
    let z = open(
        Role::Router {
            listen: &o.listen,
            access: access::config(tls.is_some()),
        },
        tls,
    )
    .map_err(|e| format!("cannot listen on {e}"))?;
    let _token = z
        .liveliness()
        .declare_token(keys::agent(host))
        .wait()
        .map_err(|e| e.to_string())?;
    let starts = z
        .declare_queryable(keys::start(host))
        .wait()
        .map_err(|e| e.to_string())?;
    say!("agent {host}: listening on {}", o.listen);
    // Each worker with the (run, component) it serves: one worker per pair.
    let mut workers: Vec<(Child, String, String)> = Vec::new();
    while !STOP.load(Ordering::Relaxed) {
        workers.retain_mut(|(w, _, _)| matches!(w.try_wait(), Ok(None)));
        let Ok(Some(query)) = starts.recv_timeout(Duration::from_millis(100)) else {
            continue;
        };
        let text = query
            .payload()
            .and_then(|p| p.try_to_string().ok())
            .map(|s| s.to_string())
            .unwrap_or_default();
        let answer = admit(&text, &workers, o.max_workers).and_then(|(run, name)| {
            let w = worker(o, tls.is_some(), &text)?;
            workers.push((w, run, name));
            Ok(())
        });
        let _ = match answer {
            Ok(()) => query.reply(keys::start(host), "started").wait(),
            Err(e) => {
                say!("agent {host}: refused a start request: {e}");
                query.reply_err(e).wait()
            }
        };
    }
    for (w, _, _) in &mut workers {
        // SAFETY: signals our own child.
        unsafe {
            libc::kill(w.id() as i32, libc::SIGTERM);
        }
    }
    for (w, _, _) in &mut workers {
        let _ = w.wait();
    }
    Ok(())
}

/// Checks a start request before anything is started for it: its run id and component name
/// are plain key chunks (no wildcards), its secret well formed, the (run, component) pair not
/// already served, and the agent below its worker limit. Returns the pair.
fn admit(
    text: &str,
    workers: &[(Child, String, String)],
    max: usize,
) -> Result<(String, String), String> {
    let req: StartRequest =
        serde_json::from_str(text).map_err(|e| format!("bad start request: {e}"))?;
    keys::check_run(&req.run)?;
    Secret::from_hex(&req.secret)?;
    let cfg: ComponentConfig = serde_json::from_str(&req.config)
        .map_err(|e| format!("bad component configuration: {e}"))?;
    keys::check_component(&cfg.name)?;
    // What the worker will make here from the request: services (Zenoh keys and shared memory)
    // of plain names and of samples no larger than a proxy or a worker accepts.
    let max_len = (session::MAX_CLIENT_MESSAGE - 64) / 8;
    for (service, len) in std::iter::once((&cfg.publishes.service, cfg.publishes.len))
        .chain(cfg.reads.iter().map(|r| (&r.service, r.len)))
    {
        keys::check_service(service)?;
        if len == 0 || len > max_len {
            return Err(format!(
                "service '{}' has samples of {len} values; at most {max_len} cross hosts",
                service.escape_debug()
            ));
        }
    }
    if cfg.reads.len() > 64 {
        return Err(format!(
            "{} reads {} services; at most 64",
            cfg.name,
            cfg.reads.len()
        ));
    }
    if workers
        .iter()
        .any(|(_, r, n)| *r == req.run && *n == cfg.name)
    {
        return Err(format!(
            "run {} already has its {} here",
            req.run,
            cfg.name.escape_debug()
        ));
    }
    if workers.len() >= max {
        return Err(format!(
            "this agent runs {max} components already (its --max-workers)"
        ));
    }
    Ok((req.run, cfg.name))
}

/// Starts a worker with the request on its stdin; it dies (SIGTERM) with the agent.
fn worker(o: &Options, tls: bool, request: &str) -> Result<Child, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut cmd = Command::new(exe);
    cmd.args(["worker", "--connect", &o.listen])
        .stdin(Stdio::piped());
    if tls {
        cmd.arg("--credentials").arg(&o.credentials);
    }
    // SAFETY: one async-signal-safe system call between fork and exec.
    unsafe {
        cmd.pre_exec(|| {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
            Ok(())
        });
    }
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("cannot start a worker: {e}"))?;
    let mut stdin = child.stdin.take().expect("piped");
    if let Err(e) = stdin.write_all(request.as_bytes()) {
        let _ = child.kill();
        let _ = child.wait();
        return Err(format!("worker: {e}"));
    }
    Ok(child)
}

#[cfg(test)]
mod tests {
    use super::wildcard;

    #[test]
    fn wildcard_addresses_are_told_from_one_interfaces_address() {
        for w in [
            "quic/0.0.0.0:7447",
            "tcp/0.0.0.0:1",
            "quic/[::]:7447",
            "tcp/[0:0:0:0:0:0:0:0]:7447",
        ] {
            assert!(wildcard(w), "{w}");
        }
        for one in [
            "quic/10.0.0.2:7447",
            "quic/127.0.0.1:7447",
            "quic/[::1]:7447",
            "tcp/[fe80::1]:9",
            "quic/agent.example:7447",
        ] {
            assert!(!wildcard(one), "{one}");
        }
    }
}
