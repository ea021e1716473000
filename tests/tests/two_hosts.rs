//! Issue 14: a run with components on another host, over Zenoh, tested on one machine as two
//! hosts (network namespaces joined by a veth pair, scripts/two-hosts.sh). The script checks each
//! case itself and this test runs it and reads its verdict:
//! - the recording against a single-host run, bit for bit;
//! - a killed plant, a killed agent and a cut link each stop the run within 2 s, naming a
//!   component on the other host;
//! - a killed local controller stops the other host's side too;
//! - nothing is left in either namespace;
//! - links are mutual TLS: a peer without a certificate, with another CA's, or on plain TCP is
//!   refused, and so is a launcher with another CA's credentials;
//! - a peer with the user's own launcher credential, during a run, cannot subscribe to `uio/**`,
//!   reads only sealed bytes, cannot forge inputs or a status, start run `**` or the running
//!   plant again, intercept start requests, exhaust the agent with a 200 MB query or 12 start
//!   requests, or keep a second run out with 200 idle connections — and the run's recording
//!   equals a single-host run's;
//! - two runs at once through one agent both pass; plain TCP only with `--insecure`.
//!
//! Where network namespaces are not allowed the script says "skipped" (exit 77), and so does this
//! test.

use std::process::Command;

use tests::*;

fn case(name: &str) {
    let out = Command::new(repo().join("scripts/two-hosts.sh"))
        .arg(name)
        .env("CARGO_TARGET_DIR", bin_dir().parent().expect("release/'s parent"))
        .output()
        .expect("runs scripts/two-hosts.sh");
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    if out.status.code() == Some(77) {
        eprintln!("{name}: {stdout}");
        return;
    }
    assert!(out.status.success(), "two-hosts.sh {name}: {stdout}{stderr}");
    assert!(stdout.contains(&format!("ok {name}:")), "{stdout}{stderr}");
    eprintln!("{stdout}");
}

// One case at a time: each builds and removes its own namespaces, and they share the machine's
// two cores with the runs.
#[test]
fn two_hosts() {
    for c in ["run", "kill-component", "kill-agent", "cut-link", "kill-local", "refused", "attacks", "concurrent", "insecure"] {
        case(c);
    }
}
