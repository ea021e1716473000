//! A run with components on another host, over Zenoh, tested on one machine as two
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
//! test. A case that fails is run once more (see [`case`]).

use std::process::Command;

use tests::*;

/// Runs one case of the script: Ok with what it printed, Err with why it failed.
fn attempt(name: &str) -> Result<Option<String>, String> {
    let out = Command::new(repo().join("scripts/two-hosts.sh"))
        .arg(name)
        .env(
            "CARGO_TARGET_DIR",
            bin_dir().parent().expect("release/'s parent"),
        )
        .output()
        .expect("runs scripts/two-hosts.sh");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    if out.status.code() == Some(77) {
        tests::skip("two_hosts", &format!("{name}: {}", stdout.trim()));
        return Ok(None);
    }
    if out.status.success() && stdout.contains(&format!("ok {name}:")) {
        Ok(Some(stdout.into_owned()))
    } else {
        Err(format!("two-hosts.sh {name}: {stdout}{stderr}"))
    }
}

/// A case that fails is run once more, and must pass then. The cases time the links' 1 s lease
/// and a 2 s stop on a machine whose two cores the runs share with whatever else runs: under
/// load a lease can lapse once (seen: the attacked run losing its agent during the 200 MB
/// query, a cut link taking 2.05 s to stop), while a broken case fails both times. The first
/// failure is printed.
/// Whether the case ran (false: this machine cannot make the namespaces, reported as skipped).
fn case(name: &str) -> bool {
    let outcome = attempt(name).or_else(|first| {
        eprintln!("{name} failed once; run again. The failure:\n{first}");
        attempt(name)
    });
    match outcome {
        Ok(Some(out)) => {
            eprintln!("{out}");
            true
        }
        Ok(None) => false,
        Err(why) => panic!("{why}"),
    }
}

// One case at a time: each builds and removes its own namespaces, and they share the machine's
// two cores with the runs.
#[test]
fn two_hosts() {
    for c in [
        "run",
        "kill-component",
        "kill-agent",
        "cut-link",
        "kill-local",
        "refused",
        "attacks",
        "concurrent",
        "insecure",
    ] {
        if !case(c) {
            return;
        }
    }
}
