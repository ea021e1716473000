//! The worker: on the component's host, one per remote component. Started by the agent with the
//! start request on stdin, it makes a run space of this host's own (its id is fresh, so even two
//! "hosts" on one machine never share shared memory), writes the component's configuration
//! there, starts the component, relays `ready` and `go`, carries its samples to the launcher's
//! host and its inputs back, and reports how it exited. It dies with the agent, the launcher's
//! proxy or the link, and removes the component and the run space whichever happens.

use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use lockstep::component::{ComponentConfig, Iceoryx2Place};
use lockstep::{Bus, RunSpace, Wait};
use zenoh::Wait as _;
use zenoh::sample::SampleKind;

use crate::beat::Beat;
use crate::credentials::{self, Side};
use crate::keys;
use crate::proxy::StartRequest;
use crate::pump::{Exports, Idle, Imports};
use crate::seal::Secret;
use crate::sealed::{SealedPublisher, SealedSubscriber};
use crate::session::{Role, open};

static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_term(_: libc::c_int) {
    STOP.store(true, Ordering::Relaxed);
}

/// Runs the worker for the request on stdin, connecting with the agent's credentials in
/// `credentials` (none: a plain TCP agent); returns the exit code.
pub fn run(connect: &str, credentials: Option<&std::path::Path>) -> i32 {
    // The agent's death (SIGTERM, set by the agent at spawn) or a stop: tear down, then exit.
    // SAFETY: the handler only stores to an atomic.
    unsafe {
        libc::signal(libc::SIGTERM, on_term as *const () as libc::sighandler_t);
        libc::signal(libc::SIGINT, on_term as *const () as libc::sighandler_t);
    }
    let mut text = String::new();
    if let Err(e) = std::io::stdin().read_to_string(&mut text) {
        say!("worker: stdin: {e}");
        return 3;
    }
    let req: StartRequest = match serde_json::from_str(&text) {
        Ok(r) => r,
        Err(e) => {
            say!("worker: bad request: {e}");
            return 3;
        }
    };
    let space = match RunSpace::create() {
        Ok(s) => s,
        Err(e) => {
            say!("worker: {e}");
            return 3;
        }
    };
    let code = match serve(connect, credentials, &req, &space) {
        Ok(()) => 0,
        Err(e) => {
            say!("worker for {}: {e}", req.run);
            3
        }
    };
    space.remove();
    code
}

// one job: one component request served on the agent's host (spawn, relay, wait, clean up): every
// exit path shares the same locals and cleanup.
fn serve(
    connect: &str,
    credentials: Option<&std::path::Path>,
    req: &StartRequest,
    space: &RunSpace,
) -> Result<(), String> {
    let mut cfg: ComponentConfig =
        serde_json::from_str(&req.config).map_err(|e| format!("configuration: {e}"))?;
    keys::check_run(&req.run)?;
    keys::check_component(&cfg.name)?;
    let secret = Secret::from_hex(&req.secret)?;
    let tls = credentials
        .map(|d| credentials::load(d, Side::Agent))
        .transpose()?;
    let (run, name) = (req.run.clone(), cfg.name.clone());
    let wait: Wait = cfg.wait.parse().map_err(|e| format!("wait: {e}"))?;
    // The component's world is this host's run space.
    cfg.run = space.id().to_string();
    cfg.iceoryx2 = Iceoryx2Place::of(space);
    space
        .write_config(
            &cfg.file(),
            &serde_json::to_string_pretty(&cfg).expect("serialises"),
        )
        .map_err(|e| e.to_string())?;
    let bus = Bus::join(space, "bridge", wait).map_err(|e| e.to_string())?;

    let z = open(Role::Client { connect }, tls.as_ref())?;
    let _token = z
        .liveliness()
        .declare_token(keys::alive(&run, &name, "worker"))
        .wait()
        .map_err(|e| e.to_string())?;
    let proxy = z
        .liveliness()
        .declare_subscriber(keys::alive(&run, &name, "proxy"))
        .history(true)
        .wait()
        .map_err(|e| e.to_string())?;
    let status = std::cell::RefCell::new(SealedPublisher::new(
        &z,
        &secret,
        keys::status(&run, &name),
    )?);
    let mut go = SealedSubscriber::new(&z, &secret, keys::go(&run, &name))?;
    let mut pings = SealedSubscriber::new(&z, &secret, keys::ping(&run, &name))?;
    let mut pong = SealedPublisher::new(&z, &secret, keys::pong(&run, &name))?;
    let reads: Vec<(String, usize, String)> = cfg
        .reads
        .iter()
        .map(|r| {
            (
                r.service.clone(),
                r.len,
                keys::to_component(&run, &name, &r.service),
            )
        })
        .collect();
    let mut imports = Imports::new(&bus, &z, &secret, &reads)?;
    let mut exports = Exports::new(
        &bus,
        &z,
        &secret,
        &[(
            cfg.publishes.service.clone(),
            keys::from_component(&run, &name),
        )],
    )?;
    let report = |line: String| status.borrow_mut().put(line.as_bytes());
    let mut beat = Beat::new(&z, &secret, &run, &name, "worker", "proxy")?;

    let mut child = spawn(&req.builtin, space, &cfg, wait).inspect_err(|e| {
        let _ = report(format!("exit 3 0 {e}"));
    })?;
    let last_err = collect_stderr(&mut child);
    let (tx, rx) = mpsc::channel();
    let out = child.stdout.take().expect("piped");
    std::thread::spawn(move || {
        for line in BufReader::new(out).lines().map_while(Result::ok) {
            if line.trim() == "ready" {
                let _ = tx.send(());
                break;
            }
        }
    });
    // Kept open for the run: a closed stdin before `go` means "stopped" to a component.
    let mut stdin = child.stdin.take();
    let mut proxy_seen = false;
    let mut phase = Phase::Starting;
    let started = Instant::now();
    let mut idle = Idle::new();
    loop {
        if STOP.load(Ordering::Relaxed) {
            kill(&mut child);
            return Err("stopped (the agent went away)".into());
        }
        while let Ok(Some(s)) = proxy.try_recv() {
            match s.kind() {
                SampleKind::Put => proxy_seen = true,
                SampleKind::Delete => {
                    kill(&mut child);
                    return Err(format!(
                        "the launcher's side of {name} went away (run stopped, or the link was cut)"
                    ));
                }
            }
        }
        if !beat.alive() {
            kill(&mut child);
            return Err(format!(
                "the launcher's side of {name} went silent (run stopped, or the link was cut)"
            ));
        }
        if !proxy_seen && started.elapsed() > Duration::from_secs(5) {
            kill(&mut child);
            return Err(format!("no launcher-side proxy for {name}"));
        }
        // The proxy's clock probes: answer at once with this host's time.
        while let Some(p) = pings.try_recv() {
            let mut answer = p.to_vec();
            answer.extend(lockstep::now_ns().to_le_bytes());
            pong.put(&answer)?;
        }
        match phase {
            Phase::Starting if rx.try_recv().is_ok() => {
                report("ready".into())?;
                phase = Phase::Ready;
            }
            Phase::Ready if let Some(text) = go.try_recv_text() => {
                // `go <θ> <round trip>`: the launcher's host's times onto this one's.
                let mut words = text.split(' ');
                let (Some("go"), Some(Ok(theta)), Some(Ok(rtt))) = (
                    words.next(),
                    words.next().map(str::parse::<i64>),
                    words.next().map(str::parse::<u64>),
                ) else {
                    return Err(format!(
                        "{name}: a malformed go from the proxy: '{}'",
                        text.escape_debug()
                    ));
                };
                imports.shift_ns = theta;
                beat.arm();
                say!(
                    "worker for {name}: this host's clock reads {theta} ns ahead of the launcher's host's (± {} ns, half the shortest of 16 round trips)",
                    rtt / 2
                );
                if let Some(s) = stdin.as_mut() {
                    s.write_all(b"go\n")
                        .and_then(|_| s.flush())
                        .map_err(|e| format!("{name}: {e}"))?;
                }
                phase = Phase::Running;
            }
            _ => {}
        }
        let worked = if phase == Phase::Running {
            exports.pump()? + imports.pump()? > 0
        } else {
            false
        };
        if let Ok(Some(st)) = child.try_wait() {
            // Everything it published before it exited goes first.
            while exports.pump()? > 0 {}
            let code = st.code().unwrap_or(3);
            let why = match (st.code(), st.signal()) {
                (_, Some(sig)) => format!("killed by signal {sig}"),
                (Some(0), _) => "exited".to_string(),
                (Some(c), _) => format!(
                    "exited with status {c}: {}",
                    last_err.lock().map(|s| s.clone()).unwrap_or_default()
                ),
                _ => "exited".to_string(),
            };
            report(format!("exit {code} {} {why}", exports.sent))?;
            // Let the report leave before the session closes.
            std::thread::sleep(Duration::from_millis(100));
            drop(stdin);
            return Ok(());
        }
        idle.after(worked);
    }
}

#[derive(PartialEq, Clone, Copy)]
enum Phase {
    Starting,
    Ready,
    Running,
}

/// Starts our built-in component of this kind, beside this executable, in its own process
/// group, as the launcher would (PROTOCOL.md §1).
fn spawn(
    builtin: &str,
    space: &RunSpace,
    cfg: &ComponentConfig,
    wait: Wait,
) -> Result<Child, String> {
    if !matches!(builtin, "plant" | "observer" | "controller") {
        return Err(format!(
            "'{}' is not a built-in component",
            builtin.escape_debug()
        ));
    }
    let exe = std::env::current_exe()
        .map_err(|e| e.to_string())?
        .with_file_name(lockstep::programs::builtin(builtin));
    Command::new(&exe)
        .args([
            "--run",
            space.id(),
            "--name",
            &cfg.name,
            "--wait",
            &wait.to_string(),
        ])
        .envs(cfg.launch_env(space))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0)
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", exe.display()))
}

/// The last line the component wrote on stderr.
fn collect_stderr(child: &mut Child) -> Arc<Mutex<String>> {
    let last = Arc::new(Mutex::new(String::new()));
    let sink = last.clone();
    let err = child.stderr.take().expect("piped");
    std::thread::spawn(move || {
        for line in BufReader::new(err).lines().map_while(Result::ok) {
            if let Ok(mut l) = sink.lock() {
                *l = line;
            }
        }
    });
    last
}

/// Kills the component's process group and waits for it.
fn kill(child: &mut Child) {
    // SAFETY: signals the process group this worker created for the child.
    unsafe {
        libc::kill(-(child.id() as i32), libc::SIGKILL);
    }
    let _ = child.wait();
}
