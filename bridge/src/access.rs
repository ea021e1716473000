//! The agent's access rules (Zenoh's access control, enforced by the agent's router on every
//! message a peer sends it). Everything is denied unless listed here, and a rule admits a key
//! expression only when it includes the one a peer uses, so a wildcard broader than a rule
//! (`uio/**`) is refused. A launcher's proxy may ask agents to start components, send a
//! component its inputs, `go` and clock probes, and read what components publish; a worker (the
//! agent's certificate) the converse. No peer may declare a queryable (so none can intercept a
//! start request) or an agent's liveliness token (so none can stand in for an agent), and
//! neither side may hold the other side's liveliness token.
//!
//! Zenoh's rules cannot forbid a wildcard within what a rule admits: a launcher's credential may
//! subscribe to `uio/run/*/c/*/out` and so learn run ids, component names and message sizes
//! and times. What it reads there is sealed with each run's secret, and what it sends is
//! refused by the run's receivers ([`crate::seal`]); liveliness tokens, which cannot be sealed,
//! are backed by sealed heartbeats ([`crate::beat`]).

use serde_json::{Value, json};

use crate::credentials::{AGENT_CN, LAUNCHER_CN};

const RUN: &str = "uio/run/*/c/*";

fn rule(id: &str, messages: &[&str], keys: &[String]) -> Value {
    json!({ "id": id, "messages": messages, "flows": ["ingress"], "permission": "allow", "key_exprs": keys })
}

fn run_keys(ends: &[&str]) -> Vec<String> {
    ends.iter().map(|e| format!("{RUN}/{e}")).collect()
}

/// The rules of a proxy (launcher side) and of a worker (agent side).
fn rules() -> Vec<Value> {
    vec![
        rule(
            "proxy-put",
            &["put"],
            &run_keys(&["in/**", "go", "ping", "beat/proxy"]),
        ),
        rule(
            "proxy-sub",
            &["declare_subscriber"],
            &run_keys(&["out", "status", "pong", "beat/worker"]),
        ),
        rule("proxy-start", &["query"], &["uio/agent/*/start".into()]),
        rule("proxy-token", &["liveliness_token"], &run_keys(&["proxy"])),
        rule(
            "proxy-watch",
            &["declare_liveliness_subscriber"],
            &run_keys(&["worker"]),
        ),
        rule("proxy-find", &["liveliness_query"], &["uio/agent/*".into()]),
        rule(
            "worker-put",
            &["put"],
            &run_keys(&["out", "status", "pong", "beat/worker"]),
        ),
        rule(
            "worker-sub",
            &["declare_subscriber"],
            &run_keys(&["in/**", "go", "ping", "beat/proxy"]),
        ),
        rule(
            "worker-token",
            &["liveliness_token"],
            &run_keys(&["worker"]),
        ),
        rule(
            "worker-watch",
            &["declare_liveliness_subscriber"],
            &run_keys(&["proxy"]),
        ),
        // What the router forwards to a peer is what that peer was allowed to ask for.
        json!({ "id": "forward", "messages": ["put", "delete", "declare_subscriber", "query", "declare_queryable", "reply", "liveliness_token", "declare_liveliness_subscriber", "liveliness_query"], "flows": ["egress"], "permission": "allow", "key_exprs": ["**"] }),
    ]
}

/// The `access_control` section of the agent's Zenoh configuration. With certificates, the
/// proxy's rules go to launchers and the worker's to agents; on an `--insecure` TCP endpoint
/// nobody is told apart, and every peer gets both.
pub fn config(tls: bool) -> Value {
    let proxy = [
        "proxy-put",
        "proxy-sub",
        "proxy-start",
        "proxy-token",
        "proxy-watch",
        "proxy-find",
        "forward",
    ];
    let worker = [
        "worker-put",
        "worker-sub",
        "worker-token",
        "worker-watch",
        "forward",
    ];
    let (subjects, policies) = if tls {
        (
            json!([{ "id": "launchers", "cert_common_names": [LAUNCHER_CN] }, { "id": "agents", "cert_common_names": [AGENT_CN] }]),
            json!([{ "id": "launchers", "rules": proxy, "subjects": ["launchers"] }, { "id": "agents", "rules": worker, "subjects": ["agents"] }]),
        )
    } else {
        let both: Vec<&str> = proxy
            .iter()
            .chain(worker.iter())
            .copied()
            .filter(|r| *r != "forward")
            .chain(["forward"])
            .collect();
        (
            json!([{ "id": "anyone", "link_protocols": ["tcp"] }]),
            json!([{ "id": "anyone", "rules": both, "subjects": ["anyone"] }]),
        )
    };
    json!({ "enabled": true, "default_permission": "deny", "rules": rules(), "subjects": subjects, "policies": policies })
}
