//! `[hosts]` and `host = …`: which components run on another host, refused with a one-line
//! error naming the field when the host is unknown, the endpoint is not one to connect to, or
//! the component is an external command.

use std::path::Path;

use scenario::{Remote, Scenario};

const BASE: &str = r#"name = "hosts"
dt = 0.01
duration = 1.0

[plant]
A = [[0.0, 1.0], [-2.0, -3.0]]
B = [[0.0], [1.0]]
C = [[1.0, 0.0]]
x0 = [1.0, 0.0]
HOST

[[input]]
kind = "constant"
value = 0.0

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-4.0, -5.0]
"#;

fn parse(host_line: &str, tail: &str) -> Result<Scenario, String> {
    let text = format!("{}{tail}", BASE.replace("HOST", host_line));
    Scenario::parse(Path::new("hosts.toml"), &text).map_err(|e| e.to_string())
}

#[test]
fn a_plant_on_a_named_host() {
    let s = parse("host = \"rig\"", "[hosts]\nrig = \"quic/10.77.0.2:7447\"\n").unwrap();
    assert_eq!(
        s.remote.get("plant"),
        Some(&Remote {
            host: "rig".into(),
            endpoint: "quic/10.77.0.2:7447".into()
        })
    );
    assert!(!s.remote.contains_key("luenberger"));
    assert!(parse("", "").unwrap().remote.is_empty());
}

#[test]
fn bad_placements_are_named() {
    let unknown = parse("host = \"rig\"", "").unwrap_err();
    assert!(
        unknown.contains("plant.host") && unknown.contains("'rig' is not in [hosts]"),
        "{unknown}"
    );
    for (endpoint, why) in [
        ("udp/10.0.0.1:7447", "quic/"),
        ("tcp/10.0.0.1", "port"),
        ("quic/0.0.0.0:7447", "wildcard"),
        ("tcp/:7447", "missing"),
        ("tls/10.0.0.1:7447", "use quic/"),
    ] {
        let e = parse(
            "host = \"rig\"",
            &format!("[hosts]\nrig = \"{endpoint}\"\n"),
        )
        .unwrap_err();
        assert!(
            e.contains("hosts.rig") && e.contains(why),
            "{endpoint}: {e}"
        );
    }
    let bad_name = parse("", "[hosts]\n\"a b\" = \"tcp/10.0.0.1:7447\"\n").unwrap_err();
    assert!(
        bad_name.contains("'a b' must be non-empty letters, digits")
            && bad_name.contains("names a host"),
        "{bad_name}"
    );
    let external = parse(
        "host = \"rig\"\n[plant.process]\ncommand = [\"python3\", \"p.py\"]",
        "[hosts]\nrig = \"tcp/10.0.0.1:7447\"\n",
    )
    .unwrap_err();
    assert!(
        external.contains("plant.host") && external.contains("built-in"),
        "{external}"
    );
    for e in [unknown, bad_name, external] {
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}
