//! The proxy: on the launcher's host, it stands in for a component that runs on another host.
//! The launcher starts it as it would start the component (same environment, same configuration
//! file); it asks that host's agent to start the component, relays `ready` and `go`, carries the
//! component's inputs there and its samples back, and exits as the component did — or with
//! status 3 naming the host when the agent or the link is lost.

use std::time::{Duration, Instant};

use lockstep::component::ComponentConfig;
use lockstep::{Bus, RunSpace, Wait};
use zenoh::Wait as _;
use zenoh::sample::SampleKind;

use crate::beat::{Beat, Pulse};
use crate::clock::{Offset, estimate};
use crate::credentials::{self, Side};
use crate::keys;
use crate::pump::{Exports, Idle, Imports};
use crate::seal::Secret;
use crate::sealed::{SealedPublisher, SealedSubscriber};
use crate::session::{MAX_MESSAGE, Role, open, secured};

/// What the agent is asked to start.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct StartRequest {
    /// The launcher's run id (names the keys of the run).
    pub run: String,
    /// Our built-in component: `plant`, `observer` or `controller`.
    pub builtin: String,
    /// The component's configuration, as the launcher wrote it.
    pub config: String,
    /// The secret that seals this component's messages ([`crate::seal`]), hex.
    pub secret: String,
}

/// Exit code for everything that is not the component's own exit.
const FAILED: i32 = 3;

/// Runs the proxy; returns the process's exit code.
pub fn run(host: &str, connect: &str, builtin: &str) -> i32 {
    lockstep::die_with_parent();
    match proxy(host, connect, builtin) {
        Ok(code) => code,
        Err(e) => {
            say!("host {host}: {e}");
            FAILED
        }
    }
}

// one job: one remote component's life seen from this host (link, config hand-over, relay, exit
// code): its stages share the link and one cleanup path.
fn proxy(host: &str, connect: &str, builtin: &str) -> Result<i32, String> {
    let path = std::env::var("UIO_CONFIG")
        .map_err(|_| "UIO_CONFIG is not set: the proxy is started by the launcher".to_string())?;
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{path}: {e}"))?;
    let cfg: ComponentConfig = serde_json::from_str(&text).map_err(|e| format!("{path}: {e}"))?;
    let wait: Wait = cfg.wait.parse().map_err(|e| format!("{path}: wait: {e}"))?;
    let space = RunSpace::open(&cfg.run).map_err(|e| e.to_string())?;
    let bus =
        Bus::join(&space, &format!("bridge-{}", cfg.name), wait).map_err(|e| e.to_string())?;

    let tls = if secured(connect) {
        Some(credentials::load(
            &credentials::default_dir(),
            Side::Launcher,
        )?)
    } else {
        None
    };
    let z = connect_to(connect, tls.as_ref())?;
    wait_for_agent(&z, host, connect)?;
    let (run, name) = (cfg.run.as_str(), cfg.name.as_str());
    let secret = Secret::draw()?;
    let _token = z
        .liveliness()
        .declare_token(keys::alive(run, name, "proxy"))
        .wait()
        .map_err(|e| e.to_string())?;
    let worker = z
        .liveliness()
        .declare_subscriber(keys::alive(run, name, "worker"))
        .wait()
        .map_err(|e| e.to_string())?;
    let mut status = SealedSubscriber::new(&z, &secret, keys::status(run, name))?;
    let mut go = SealedPublisher::new(&z, &secret, keys::go(run, name))?;
    let mut imports = Imports::new(
        &bus,
        &z,
        &secret,
        &[(
            cfg.publishes.service.clone(),
            cfg.publishes.len,
            keys::from_component(run, name),
        )],
    )?;
    let reads: Vec<(String, String)> = cfg
        .reads
        .iter()
        .map(|r| (r.service.clone(), keys::to_component(run, name, &r.service)))
        .collect();
    let mut exports = Exports::new(&bus, &z, &secret, &reads)?;
    let mut beat = Beat::new(&z, &secret, run, name, "proxy", "worker")?;

    let request = serde_json::to_string(&StartRequest {
        run: run.to_string(),
        builtin: builtin.to_string(),
        config: text.clone(),
        secret: secret.to_hex(),
    })
    .expect("serialises");
    if request.len() > MAX_MESSAGE {
        return Err(format!(
            "{name}'s configuration is {} bytes; a start request carries at most {MAX_MESSAGE}",
            request.len()
        ));
    }
    let replies = z
        .get(keys::start(host))
        .payload(request)
        .timeout(Duration::from_secs(10))
        .wait()
        .map_err(|e| e.to_string())?;
    match replies.recv() {
        Ok(reply) => {
            if let Err(e) = reply.result() {
                return Err(format!(
                    "its agent cannot start {name}: {}",
                    e.payload().try_to_string().unwrap_or_default()
                ));
            }
        }
        Err(_) => {
            return Err(format!(
                "its agent at {connect} did not answer the start of {name}"
            ));
        }
    }
    // The component is up on the other host when its worker says `ready`.
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        if let Ok(Some(s)) = worker.try_recv()
            && s.kind() == SampleKind::Delete
        {
            return Err(format!(
                "its worker for {name} stopped before the component was ready"
            ));
        }
        if let Some(line) = status.try_recv_text() {
            if line == "ready" {
                break;
            }
            return Err(exit_message(name, &line));
        }
        if Instant::now() > deadline {
            return Err(format!("{name} did not become ready there within 20 s"));
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    // The hosts' clocks, before the run: the worker's samples then carry this host's times.
    let offset = probe_clock(&z, &secret, run, name)?;
    imports.shift_ns = -offset.theta_ns;
    lockstep::ready_then_wait_for_go().map_err(|e| e.to_string())?;
    go.put(format!("go {} {}", offset.theta_ns, offset.rtt_ns).as_bytes())?;
    beat.arm();
    watchdog(&z, beat.pulse(), host, name);

    let mut idle = Idle::new();
    loop {
        let worked = exports.pump()? + imports.pump()? > 0;
        // The worker's token goes when its session does (the watchdog covers what it misses).
        if matches!(worker.try_recv(), Ok(Some(s)) if s.kind() == SampleKind::Delete) {
            return Err(lost(name));
        }
        if let Some(line) = status.try_recv_text() {
            return finish(name, host, &line, &mut imports);
        }
        idle.after(worked);
    }
}

/// The component has exited on the other host: publish every sample it sent first, then exit
/// as it did.
fn finish(name: &str, host: &str, line: &str, imports: &mut Imports) -> Result<i32, String> {
    let mut parts = line.splitn(4, ' ');
    let (Some("exit"), Some(code), Some(count)) = (
        parts.next(),
        parts.next().and_then(|c| c.parse::<i32>().ok()),
        parts.next().and_then(|c| c.parse::<u64>().ok()),
    ) else {
        return Err(format!("{name}: its worker said '{}'", line.escape_debug()));
    };
    let message = parts.next().unwrap_or("");
    let deadline = Instant::now() + Duration::from_secs(2);
    while imports.received < count && Instant::now() < deadline {
        if imports.pump()? == 0 {
            std::thread::sleep(Duration::from_micros(100));
        }
    }
    if imports.received < count {
        return Err(format!(
            "{name} sent {count} samples, {} arrived",
            imports.received
        ));
    }
    if code != 0 {
        say!("{name} on host {host}: {message}");
    }
    Ok(code)
}

/// The agent's liveliness token says it is there; a fresh session may still be settling, so
/// it is asked for up to 2 s.
fn wait_for_agent(z: &zenoh::Session, host: &str, connect: &str) -> Result<(), String> {
    let asked = Instant::now();
    loop {
        let replies = z
            .liveliness()
            .get(keys::agent(host))
            .timeout(Duration::from_millis(500))
            .wait()
            .map_err(|e| e.to_string())?;
        if replies.recv().is_ok() {
            return Ok(());
        }
        if asked.elapsed() > Duration::from_secs(2) {
            return Err(format!(
                "no agent answers at {connect} (start `uio-launcher agent --host {host} --listen {connect}` there)"
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn lost(name: &str) -> String {
    format!("lost its agent while {name} ran (the link was cut, or the agent or the host stopped)")
}

/// Ends the proxy (exit 3, naming the host) when the agent's link is gone or the worker's
/// sealed heartbeat stops — from a thread of its own, every 100 ms, since the loop may be
/// blocked in a publish on that dead link: over QUIC a killed agent sends nothing, and Zenoh's
/// lease alone let such a run go on past the launcher's 5 s hang rule.
fn watchdog(z: &zenoh::Session, pulse: Pulse, host: &str, name: &str) {
    let (z, host, name) = (z.clone(), host.to_string(), name.to_string());
    std::thread::spawn(move || {
        loop {
            std::thread::sleep(Duration::from_millis(100));
            if z.info().routers_zid().wait().next().is_none() || !pulse.alive() {
                say!("host {host}: {}", lost(&name));
                std::process::exit(FAILED);
            }
        }
    });
}

/// Opens the client session to the agent. A flood of idle connections can hold the agent's
/// handshake slots for up to its accept timeout: the session is retried for 10 s before the
/// agent is called unreachable.
fn connect_to(
    connect: &str,
    tls: Option<&credentials::Credentials>,
) -> Result<zenoh::Session, String> {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        match open(Role::Client { connect }, tls) {
            Ok(z) => return Ok(z),
            Err(e) if Instant::now() >= deadline => {
                return Err(format!("cannot reach its agent at {e}"));
            }
            Err(_) => std::thread::sleep(Duration::from_millis(250)),
        }
    }
}

/// Round trips with the worker ([`crate::clock`]): 16 exchanges, the shortest one's offset.
fn probe_clock(
    z: &zenoh::Session,
    secret: &Secret,
    run: &str,
    name: &str,
) -> Result<Offset, String> {
    let mut pongs = SealedSubscriber::new(z, secret, keys::pong(run, name))?;
    let mut ping = SealedPublisher::new(z, secret, keys::ping(run, name))?;
    let mut exchanges = Vec::new();
    for _ in 0..16 {
        let t1 = lockstep::now_ns();
        ping.put(&t1.to_le_bytes())?;
        let deadline = Instant::now() + Duration::from_secs(1);
        while Instant::now() < deadline {
            let Some(b) = pongs.recv_timeout(Duration::from_millis(100)) else {
                continue;
            };
            let t3 = lockstep::now_ns();
            if b.len() == 16 && b[..8] == t1.to_le_bytes() {
                exchanges.push((
                    t1,
                    u64::from_le_bytes(b[8..].try_into().expect("8 bytes")),
                    t3,
                ));
                break;
            }
        }
    }
    estimate(&exchanges)
        .ok_or_else(|| format!("its worker for {name} does not answer the clock probes"))
}

fn exit_message(name: &str, line: &str) -> String {
    let message = line.splitn(4, ' ').nth(3).unwrap_or(line);
    format!("{name} failed to start there: {message}")
}
