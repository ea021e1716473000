//! Components on other hosts: `[hosts]` names each host's agent endpoint, and `host = "<name>"`
//! in `[plant]`, an `[[observer]]` or `[controller]` runs that component there (through the
//! bridge, `uio-bridge`, over Zenoh). Only built-in components travel: an external command is a
//! path on the launcher's machine.

use std::collections::BTreeMap;

use super::raw::RawScenario;
use super::untrusted::quoted;
use crate::check::{Bad, bad, check_name};

/// Where a component runs when not on the launcher's host.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Remote {
    /// The host's name, as `[hosts]` gives it.
    pub host: String,
    /// Its agent's Zenoh endpoint, e.g. `tcp/10.0.0.2:7447`.
    pub endpoint: String,
}

/// The remote placements, by component name (`plant`, `controller`, or the observer's name).
pub(crate) fn placements(raw: &RawScenario) -> Result<BTreeMap<String, Remote>, Bad> {
    let hosts = raw.hosts.clone().unwrap_or_default();
    for (name, endpoint) in &hosts {
        let f = format!("hosts.{name}");
        check_name(&f, name, "it names a host")?;
        endpoint_ok(endpoint).map_err(|why| bad(&f, format!("{}: {why}", quoted(endpoint))))?;
    }
    let mut out = BTreeMap::new();
    let mut place = |field: String,
                     component: &str,
                     host: &Option<String>,
                     external: bool|
     -> Result<(), Bad> {
        let Some(h) = host else { return Ok(()) };
        let Some(endpoint) = hosts.get(h) else {
            return Err(bad(
                field,
                format!(
                    "{} is not in [hosts] ({})",
                    quoted(h),
                    if hosts.is_empty() {
                        "there is none".to_string()
                    } else {
                        hosts.keys().cloned().collect::<Vec<_>>().join(", ")
                    }
                ),
            ));
        };
        if external {
            return Err(bad(
                field,
                "only built-in components run on another host: an external command is a program on the launcher's machine",
            ));
        }
        out.insert(
            component.to_string(),
            Remote {
                host: h.clone(),
                endpoint: endpoint.clone(),
            },
        );
        Ok(())
    };
    place(
        "plant.host".into(),
        "plant",
        &raw.plant.host,
        raw.plant.process.is_some() || raw.plant.fmu.is_some(),
    )?;
    for (i, o) in raw.observer.iter().enumerate() {
        place(
            format!("observer[{}].host", i + 1),
            &o.name,
            &o.host,
            o.kind == "process",
        )?;
    }
    if let Some(c) = &raw.controller {
        place(
            "controller.host".into(),
            "controller",
            &c.host,
            c.kind == "process",
        )?;
    }
    Ok(out)
}

/// `quic/<address>:<port>` (mutual TLS over QUIC) or `tcp/…` (plain, for an `--insecure`
/// agent), a concrete address (the agent listens on exactly what it is told, and the launcher
/// connects to it). `tls/…` is refused: Zenoh 1.10's TLS link drops busy links (see the bridge).
fn endpoint_ok(e: &str) -> Result<(), &'static str> {
    if e.starts_with("tls/") {
        return Err(
            "tls/ links are not used (Zenoh 1.10's TLS link closes under concurrent reads and writes); use quic/<address>:<port>, the same mutual TLS over QUIC",
        );
    }
    let Some(rest) = e.strip_prefix("quic/").or_else(|| e.strip_prefix("tcp/")) else {
        return Err("a Zenoh endpoint is quic/<address>:<port> (or tcp/… for an --insecure agent)");
    };
    let Some((addr, port)) = rest.rsplit_once(':') else {
        return Err("no port");
    };
    if addr.is_empty() || port.parse::<u16>().is_err() {
        return Err("the address or the port is missing or malformed");
    }
    if matches!(addr, "0.0.0.0" | "[::]") {
        return Err("an agent's endpoint is an address to connect to, not a wildcard");
    }
    Ok(())
}
