//! `uio-launcher export --mcap FILE`: an MCAP file for Foxglove and PlotJuggler, which both read
//! JSON messages described by a JSON Schema. One channel per entity group, its topic the group's
//! path (`/observer/uio/xhat`); one message per step at which the group has a value, stamped
//! (log and publish time) with sim_time in ns as the `.rrd` stamps it (round(k·dt·1e9); the
//! step itself without `dt`), holding `step`, `sim_time` (s, as the CSV's column) and a number
//! per member. A member's field is its signal name made an identifier (`eta`, `e3`; a latency
//! hop's entity name, `plant_to_observer_uio`), which plot paths such as `/observer/uio/xhat.eta` can name; the
//! schema gives each field the CSV header as its `title` (`eta [rad]`). A member with no value
//! at a step (latency can lag one) is left out of that message, where the CSV leaves a cell
//! empty; a non-finite value, which JSON cannot hold, is written as `null`. Messages are in time
//! order across channels, in zstd-compressed chunks with the usual summary and indexes.

use std::collections::BTreeMap;
use std::io::{Seek, Write};
use std::path::Path;

use mcap::records::MessageHeader;
use mcap::{Compression, WriteOptions};

use super::staged;
use super::table::{Group, aligned, array_name, labelled, sim_time};
use crate::read::Recording;

/// Writes `path`; returns how many channels it holds.
pub fn export(r: &Recording, path: &Path, dt: Option<f64>) -> Result<usize, String> {
    let groups = labelled(r);
    let fail = |e: &dyn std::fmt::Display| staged::cannot_write(path, e);
    staged::write(path, |w| write(w, &groups, dt).map_err(|e| fail(&e)))?;
    Ok(groups.len())
}

/// The field of each member: its name as an identifier, unique in the group and not `step` or
/// `sim_time`.
pub fn field_names(g: &Group<'_>) -> Vec<String> {
    let mut taken: Vec<String> = vec!["step".into(), "sim_time".into()];
    let mut out = Vec::with_capacity(g.members.len());
    for m in &g.members {
        // A hop's entity segment is an identifier already; its name has "->" and "/".
        let hop = g.path == "/latency" && m.member != "step";
        let mut base = identifier(if hop { &m.member } else { &m.name });
        if base.is_empty() {
            base = identifier(&format!("m{}", m.member));
        }
        let mut name = base.clone();
        let mut n = 1;
        while taken.contains(&name) {
            n += 1;
            name = format!("{base}_{n}");
        }
        taken.push(name.clone());
        out.push(name);
    }
    out
}

/// ASCII letters, digits and `_`, every other run of characters one `_`, none at the ends, and
/// `_` before a leading digit.
fn identifier(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() || c == '_' {
            out.push(c);
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    let out = out.trim_matches('_');
    if out.starts_with(|c: char| c.is_ascii_digit()) {
        format!("_{out}")
    } else {
        out.to_string()
    }
}

/// The JSON Schema of a group's messages.
fn schema(g: &Group<'_>, fields: &[String]) -> serde_json::Value {
    let mut properties = serde_json::Map::new();
    properties.insert(
        "step".into(),
        serde_json::json!({ "type": "integer", "title": "step" }),
    );
    properties.insert(
        "sim_time".into(),
        serde_json::json!({ "type": "number", "title": "sim_time [s]" }),
    );
    for (m, f) in g.members.iter().zip(fields) {
        properties.insert(f.clone(), serde_json::json!({ "type": ["number", "null"], "title": m.label, "description": m.entity }));
    }
    serde_json::json!({ "type": "object", "title": g.path, "properties": properties, "required": ["step"] })
}

fn write<W: Write + Seek>(
    w: W,
    groups: &[Group<'_>],
    dt: Option<f64>,
) -> Result<(), Box<dyn std::error::Error>> {
    let options = WriteOptions::new()
        .compression(Some(Compression::Zstd))
        .profile("")
        .library(concat!("uio-observers ", env!("CARGO_PKG_VERSION")));
    let mut out = options.create(w)?;
    // Per group: its channel, JSON keys (quoted, with the colon), steps, and a cursor per member.
    struct Open<'a> {
        channel: u16,
        keys: Vec<String>,
        steps: &'a [i64],
        next: usize,
        columns: Vec<Box<dyn Iterator<Item = Option<f64>> + 'a>>,
    }
    let steps: Vec<Vec<i64>> = groups.iter().map(Group::steps).collect();
    let mut open = Vec::with_capacity(groups.len());
    for (g, steps) in groups.iter().zip(&steps) {
        let fields = field_names(g);
        let schema_id = out.add_schema(
            &array_name(&g.path),
            "jsonschema",
            serde_json::to_string(&schema(g, &fields))?.as_bytes(),
        )?;
        let channel = out.add_channel(schema_id, &g.path, "json", &BTreeMap::new())?;
        let keys = fields
            .iter()
            .map(|f| format!(",{}:", serde_json::to_string(f).unwrap_or_default()))
            .collect();
        let columns = g
            .members
            .iter()
            .map(|m| Box::new(aligned(steps, m.series)) as Box<dyn Iterator<Item = Option<f64>>>)
            .collect();
        open.push(Open {
            channel,
            keys,
            steps,
            next: 0,
            columns,
        });
    }
    let all = super::table::union_steps(
        groups
            .iter()
            .flat_map(|g| g.members.iter().map(|m| m.series)),
    );
    let mut data = Vec::new();
    for &k in &all {
        let stamp = match dt {
            Some(dt) => (k as f64 * dt * 1e9).round().max(0.0) as u64,
            None => k.max(0) as u64,
        };
        for o in open.iter_mut().filter(|o| o.steps.get(o.next) == Some(&k)) {
            data.clear();
            write!(data, "{{\"step\":{k}")?;
            if let Some(t) = sim_time(k, dt) {
                data.extend(b",\"sim_time\":");
                serde_json::to_writer(&mut data, &t)?;
            }
            for (key, column) in o.keys.iter().zip(&mut o.columns) {
                if let Some(v) = column.next().flatten() {
                    data.extend(key.as_bytes());
                    serde_json::to_writer(&mut data, &v)?;
                }
            }
            data.push(b'}');
            let header = MessageHeader {
                channel_id: o.channel,
                sequence: o.next as u32,
                log_time: stamp,
                publish_time: stamp,
            };
            out.write_to_known_channel(&header, &data)?;
            o.next += 1;
        }
    }
    out.finish()?;
    Ok(())
}
