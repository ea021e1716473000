//! PROTOCOL.md against the code: the header's layout byte by byte, its type name, the version,
//! the service settings and the launch environment — read out of the document, so that neither
//! can change without the other.

use std::mem::{align_of, offset_of, size_of};

use iceoryx2::prelude::ZeroCopySend;
use lockstep::settings::*;
use lockstep::{PROTOCOL_VERSION, WireHeader};

fn document() -> String {
    let root = std::env::var_os("CARGO_MANIFEST_DIR").map_or_else(
        || env!("CARGO_MANIFEST_DIR").into(),
        std::path::PathBuf::from,
    );
    std::fs::read_to_string(root.join("../PROTOCOL.md")).unwrap()
}

/// The document's text with every run of whitespace made one space (its lines wrap freely).
fn flat(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[test]
fn the_header_table_is_the_header() {
    let doc = document();
    // Rows "| offset | size | `name: type` | meaning |" of the §4 table.
    let rows: Vec<(usize, usize, String)> = doc
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l
                .trim()
                .trim_matches('|')
                .split('|')
                .map(str::trim)
                .collect();
            let (off, size, field) = (
                cells.first()?.parse().ok()?,
                cells.get(1)?.parse().ok()?,
                cells.get(2)?,
            );
            let name = field
                .trim_matches('`')
                .split(':')
                .next()?
                .trim()
                .to_string();
            Some((off, size, name))
        })
        .collect();
    let names: Vec<&str> = rows.iter().map(|(_, _, n)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "step", "sim_time", "sent_ns", "taken_ns", "protocol", "reserved"
        ],
        "{rows:?}"
    );
    let code = [
        (offset_of!(WireHeader, step), size_of::<u64>()),
        (offset_of!(WireHeader, sim_time), size_of::<f64>()),
        (offset_of!(WireHeader, sent_ns), size_of::<u64>()),
        (offset_of!(WireHeader, taken_ns), size_of::<u64>()),
        (offset_of!(WireHeader, protocol), size_of::<u32>()),
        (offset_of!(WireHeader, reserved), size_of::<u32>()),
    ];
    for ((off, size, name), (c_off, c_size)) in rows.iter().zip(code) {
        assert_eq!((*off, *size), (c_off, c_size), "{name}");
    }
    let flat = flat(&doc);
    assert!(
        flat.contains(&format!(
            "{} bytes, align {}",
            size_of::<WireHeader>(),
            align_of::<WireHeader>()
        )),
        "size and alignment"
    );
    // SAFETY: type_name only returns the static name the derive gave the type.
    let type_name = unsafe { <WireHeader as ZeroCopySend>::type_name() };
    assert!(
        flat.contains(&format!("**user header** `{type_name}`")),
        "type name {type_name}"
    );
    assert!(flat.contains(&format!(
        "| 32 | 4 | `protocol: u32` | {PROTOCOL_VERSION} |"
    )));
    assert!(flat.starts_with(&format!(
        "# The lockstep protocol, version {PROTOCOL_VERSION}"
    )));
}

#[test]
fn the_service_settings_are_the_code_s() {
    let doc = flat(&document());
    for phrase in [
        format!(
            "at most {MAX_PUBLISHERS} publisher, {MAX_SUBSCRIBERS} subscribers and {MAX_NODES} nodes; history {HISTORY}"
        ),
        format!("subscriber buffer up to {SUBSCRIBER_MAX_BUFFER} samples"),
        format!("Subscribers of a lockstep input use a buffer of {LOCKSTEP_BUFFER}"),
        format!("({MAX_NOTIFIERS} notifier, {MAX_LISTENERS} listeners, {MAX_NODES} nodes)"),
        "payload**: a slice of `f64` (iceoryx2 type name `f64`".to_string(),
    ] {
        assert!(doc.contains(&phrase), "PROTOCOL.md does not say: {phrase}");
    }
}

#[test]
fn the_environment_table_names_what_the_kit_reads() {
    let doc = document();
    for var in [
        "UIO_PROTOCOL",
        "UIO_RUN",
        "UIO_NAME",
        "UIO_ROLE",
        "UIO_CONFIG",
        "UIO_RUNS_DIR",
    ] {
        assert!(
            doc.contains(&format!("| `{var}` |")),
            "{var} is not in the table of §1"
        );
    }
    assert_eq!(lockstep::RUNS_DIR_ENV, "UIO_RUNS_DIR");
}
