//! Zenoh sessions as a run uses them. Nothing listens unless told where: the agent is a router
//! listening on the one endpoint it is given; proxies and workers are clients that connect to
//! it. Multicast scouting is off (it would listen on UDP on every interface), and the link's
//! lease is 1 s, so a cut link or a killed peer is noticed within about a second.
//!
//! `UIO_ZENOH_CONFIG`, when set, names a Zenoh configuration file (JSON5) to start from — for
//! TLS (`tls/…` endpoints with `transport.link.tls`'s certificates) or anything else Zenoh
//! offers; the settings above are applied on top of it.

use zenoh::{Config, Session, Wait};

/// Link lease, ms: a peer silent this long is gone (keep-alives every quarter of it).
pub const LEASE_MS: u64 = 1000;

/// How a session joins.
pub enum Role<'a> {
    /// A router listening on this endpoint (the agent).
    Router { listen: &'a str },
    /// A client of the router at this endpoint.
    Client { connect: &'a str },
}

/// Opens a session; the error says which endpoint failed.
pub fn open(role: Role) -> Result<Session, String> {
    let mut c = match std::env::var_os("UIO_ZENOH_CONFIG") {
        Some(path) => Config::from_file(&path).map_err(|e| format!("UIO_ZENOH_CONFIG {}: {e}", path.to_string_lossy()))?,
        None => Config::default(),
    };
    let set = |c: &mut Config, k: &str, v: String| c.insert_json5(k, &v).map_err(|e| format!("zenoh configuration {k}: {e}"));
    let endpoint = match role {
        Role::Router { listen } => {
            set(&mut c, "mode", "\"router\"".into())?;
            set(&mut c, "listen/endpoints", serde_json::json!([listen]).to_string())?;
            listen
        }
        Role::Client { connect } => {
            set(&mut c, "mode", "\"client\"".into())?;
            set(&mut c, "connect/endpoints", serde_json::json!([connect]).to_string())?;
            set(&mut c, "listen/endpoints", "[]".into())?;
            connect
        }
    };
    set(&mut c, "scouting/multicast/enabled", "false".into())?;
    set(&mut c, "scouting/gossip/enabled", "false".into())?;
    set(&mut c, "transport/link/tx/lease", LEASE_MS.to_string())?;
    // Zenoh's messages end with the source location that raised them: not the user's concern.
    zenoh::open(c).wait().map_err(|e| {
        let e = e.to_string();
        format!("{endpoint}: {}", e.split("  at ").next().unwrap_or(&e).trim_end_matches(['!', ' ']))
    })
}
