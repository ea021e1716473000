//! The Zenoh key expressions of a run across hosts. A run is named by the launcher's run id; a
//! component by its name; a host by the name the scenario gives it.

/// An agent's liveliness token: present while `uio-bridge agent --host <host>` runs.
pub fn agent(host: &str) -> String {
    format!("uio/agent/{host}")
}

/// The agent's queryable that starts a component.
pub fn start(host: &str) -> String {
    format!("uio/agent/{host}/start")
}

/// The samples of `service` that the remote component `name` reads, sent by its proxy. Every
/// crossing is between a remote component and the launcher's host, where every service exists
/// (the remote ones as their proxies republish them): one publisher and one subscriber per key,
/// so no sample can arrive twice, even when several remote components read one service.
pub fn to_component(run: &str, name: &str, service: &str) -> String {
    format!("uio/run/{run}/c/{name}/in/{service}")
}

/// The samples the remote component `name` publishes, sent by its worker.
pub fn from_component(run: &str, name: &str) -> String {
    format!("uio/run/{run}/c/{name}/out")
}

/// A remote component's status, from its host's worker: `ready`, then `exit …`.
pub fn status(run: &str, name: &str) -> String {
    format!("uio/run/{run}/c/{name}/status")
}

/// The launcher's `go`, relayed by the proxy.
pub fn go(run: &str, name: &str) -> String {
    format!("uio/run/{run}/c/{name}/go")
}

/// The proxy's clock probes, and the worker's answers ([`crate::clock`]).
pub fn ping(run: &str, name: &str) -> String {
    format!("uio/run/{run}/c/{name}/ping")
}

/// The worker's answers to [`ping`].
pub fn pong(run: &str, name: &str) -> String {
    format!("uio/run/{run}/c/{name}/pong")
}

/// The sealed heartbeat of one side (`proxy` or `worker`) of a remote component.
pub fn beat(run: &str, name: &str, side: &str) -> String {
    format!("uio/run/{run}/c/{name}/beat/{side}")
}

/// Liveliness of the proxy (launcher's host) and of the worker (component's host).
pub fn alive(run: &str, name: &str, side: &str) -> String {
    format!("uio/run/{run}/c/{name}/{side}")
}

/// 1–64 letters, digits, `-` and `_`: one key chunk, never a wildcard or a separator.
fn chunk(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 64
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// A host name is one key chunk: letters, digits, `-` and `_`.
pub fn check_host(host: &str) -> Result<(), String> {
    if !chunk(host) {
        return Err(format!(
            "'{}' is not a host name (1–64 letters, digits, - and _)",
            host.escape_debug()
        ));
    }
    Ok(())
}

/// A component's name is one key chunk (as scenario names are).
pub fn check_component(name: &str) -> Result<(), String> {
    if !chunk(name) {
        return Err(format!(
            "'{}' is not a component name (1–64 letters, digits, - and _)",
            name.escape_debug()
        ));
    }
    Ok(())
}

/// A service name is key chunks joined by `/` (`plant`, `observer/uio`): no wildcards.
pub fn check_service(service: &str) -> Result<(), String> {
    if service.len() > 200 || !service.split('/').all(chunk) {
        return Err(format!(
            "'{}' is not a service name (chunks of letters, digits, - and _ joined by /)",
            service.escape_debug()
        ));
    }
    Ok(())
}

/// A run id is what a launcher's `RunSpace` makes ([`lockstep::is_run_id`]).
pub fn check_run(run: &str) -> Result<(), String> {
    if !lockstep::is_run_id(run) {
        return Err(format!(
            "'{}' is not a run id (a launcher's run id is <pid>x<n>x<nonce>, in digits)",
            run.escape_debug()
        ));
    }
    Ok(())
}
