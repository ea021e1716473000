//! Zenoh sessions as a run uses them. Nothing listens unless told where: the agent is a router
//! listening on the one endpoint it is given; proxies and workers are clients that connect to
//! it. Multicast scouting is off (it would listen on UDP on every interface), and the link's
//! lease is 1 s, so a cut link or a killed peer is noticed within about a second.
//!
//! A `quic/…` endpoint is mutual TLS 1.3 (over QUIC) with the user's credentials ([`crate::credentials`]): each
//! side presents its certificate and accepts only a peer whose certificate the user's CA
//! signed (the name in the agent's certificate is not matched against its address: the CA is
//! the user's own and signs nothing else). A `tcp/…` endpoint is plain TCP, which an agent
//! accepts only when started `--insecure`.
//!
//! Bounds, so that a peer cannot exhaust the agent: a message of at most [`MAX_MESSAGE`]
//! bytes, at most [`MAX_SESSIONS`] sessions, and a link that has not finished its handshake
//! within [`ACCEPT_TIMEOUT_MS`] is dropped (with room for [`ACCEPT_PENDING`] such links, so idle
//! connections cannot keep a launcher out).
//!
//! `UIO_ZENOH_CONFIG`, when set, names a Zenoh configuration file (JSON5) to start from; the
//! settings above are applied on top of it.

use serde_json::{Value, json};
use zenoh::{Config, Session, Wait};

use crate::credentials::Credentials;

/// Link lease, ms: a peer silent this long is gone (keep-alives every quarter of it).
pub const LEASE_MS: u64 = 1000;

/// The largest message a session accepts, bytes: a component's configuration (a start request)
/// is the largest thing sent, and an n = 1000 observer's is ~60 MB.
pub const MAX_MESSAGE: usize = 128 << 20;

/// The largest message a proxy or a worker accepts, bytes: a sample of 131 000 values.
pub const MAX_CLIENT_MESSAGE: usize = 1 << 20;

/// Sessions an agent holds at once (two per remote component and run: proxy and worker).
pub const MAX_SESSIONS: usize = 256;

/// How long a new link may take to finish its (TLS and Zenoh) handshake, ms.
pub const ACCEPT_TIMEOUT_MS: u64 = 2000;

/// Links that may be in their handshake at once.
pub const ACCEPT_PENDING: usize = 4096;

/// Why `tls/` endpoints are refused: Zenoh 1.10's TLS link reads and writes one rustls
/// connection from two tasks at once (through an `UnsafeCell`), and a write that meets the
/// reader inside `process_new_packets` fails with "handshake not complete" and closes the link
/// — a paced run lost its agent within 0.4–1 s, 3 runs of 3. QUIC carries the same mutual TLS
/// 1.3 without that.
pub const TLS_OVER_TCP: &str = "tls/ links are not used: Zenoh 1.10's TLS link closes under concurrent reads and writes (runs lose their agent within seconds); use quic/<address>:<port>, the same mutual TLS over QUIC";

/// Whether an endpoint is secured with the user's credentials: QUIC, TLS 1.3 inside (`tls/`
/// is refused before a session is opened: [`TLS_OVER_TCP`]).
pub fn secured(endpoint: &str) -> bool {
    endpoint.starts_with("quic/")
}

/// How a session joins.
pub enum Role<'a> {
    /// A router listening on this endpoint (the agent), with its access rules.
    Router { listen: &'a str, access: Value },
    /// A client of the router at this endpoint.
    Client { connect: &'a str },
}

/// Opens a session; `tls` is required for a `tls/…` endpoint. The error says which endpoint
/// failed.
pub fn open(role: Role, tls: Option<&Credentials>) -> Result<Session, String> {
    let mut c = match std::env::var_os("UIO_ZENOH_CONFIG") {
        Some(path) => Config::from_file(&path)
            .map_err(|e| format!("UIO_ZENOH_CONFIG {}: {e}", path.to_string_lossy()))?,
        None => Config::default(),
    };
    let set = |c: &mut Config, k: &str, v: Value| {
        c.insert_json5(k, &v.to_string())
            .map_err(|e| format!("zenoh configuration {k}: {e}"))
    };
    let endpoint = match &role {
        Role::Router { listen, access } => {
            set(&mut c, "mode", json!("router"))?;
            set(&mut c, "listen/endpoints", json!([listen]))?;
            set(&mut c, "access_control", access.clone())?;
            *listen
        }
        Role::Client { connect } => {
            set(&mut c, "mode", json!("client"))?;
            set(&mut c, "connect/endpoints", json!([connect]))?;
            set(&mut c, "listen/endpoints", json!([]))?;
            *connect
        }
    };
    if secured(endpoint) {
        let Some(t) = tls else {
            return Err(format!("{endpoint}: a secured endpoint needs credentials"));
        };
        let path = |p: &std::path::Path| json!(p.to_string_lossy());
        set(
            &mut c,
            "transport/link/tls/root_ca_certificate",
            path(&t.ca),
        )?;
        set(&mut c, "transport/link/tls/enable_mtls", json!(true))?;
        set(
            &mut c,
            "transport/link/tls/verify_name_on_connect",
            json!(false),
        )?;
        let (cert, key) = match role {
            Role::Router { .. } => ("listen_certificate", "listen_private_key"),
            Role::Client { .. } => ("connect_certificate", "connect_private_key"),
        };
        set(&mut c, &format!("transport/link/tls/{cert}"), path(&t.cert))?;
        set(&mut c, &format!("transport/link/tls/{key}"), path(&t.key))?;
    }
    set(&mut c, "scouting/multicast/enabled", json!(false))?;
    set(&mut c, "scouting/gossip/enabled", json!(false))?;
    set(&mut c, "transport/link/tx/lease", json!(LEASE_MS))?;
    // Only the agent receives start requests; a proxy or a worker receives samples and short
    // control messages, so a peer cannot fill them with large forgeries.
    let max = if matches!(role, Role::Router { .. }) {
        MAX_MESSAGE
    } else {
        MAX_CLIENT_MESSAGE
    };
    set(&mut c, "transport/link/rx/max_message_size", json!(max))?;
    // A publisher blocked on a dead link (QUIC: a killed peer sends nothing) gives up with the
    // lease, not Zenoh's default 5 s.
    set(
        &mut c,
        "transport/link/tx/queue/congestion_control/block/wait_before_close",
        json!(LEASE_MS * 1000),
    )?;
    set(
        &mut c,
        "transport/unicast/max_sessions",
        json!(MAX_SESSIONS),
    )?;
    set(
        &mut c,
        "transport/unicast/accept_timeout",
        json!(ACCEPT_TIMEOUT_MS),
    )?;
    set(
        &mut c,
        "transport/unicast/accept_pending",
        json!(ACCEPT_PENDING),
    )?;
    // Zenoh's messages end with the source location that raised them: not the user's concern.
    zenoh::open(c).wait().map_err(|e| {
        let e = e.to_string();
        format!(
            "{endpoint}: {}",
            e.split("  at ")
                .next()
                .unwrap_or(&e)
                .trim_end_matches(['!', ' '])
        )
    })
}
