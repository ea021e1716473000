//! `launcher export --csv DIR`: one CSV per entity group (e.g. `/observer/uio/error` →
//! `observer_uio_error.csv`) with columns `step,sim_time,<member>…`, each member headed by its
//! name and unit from the recorded scenario (`eta [rad]`, `e3 [rad]`, `plant->observer/uio [ns]`).
//! Floats are written in Rust's shortest round-trip form, so they parse back to the same bits;
//! a member with no value at a step (latency can lag one) leaves its cell empty.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use scenario::Scenario;

use super::staged;
use super::table::{aligned, array_name, labelled, name_and_label, sim_time};
use crate::read::Recording;

/// File name of a group: "/observer/uio/error" → "observer_uio_error.csv".
pub fn file_name(group: &str) -> String {
    format!("{}.csv", array_name(group))
}

/// The column header of `member` of `group`: its label ([`name_and_label`]), quoted
/// where CSV needs it.
pub fn header(s: Option<&Scenario>, r: &Recording, group: &str, member: &str) -> String {
    csv_field(&name_and_label(s, r, group, member).1)
}

/// Quotes a field holding a comma or a quote (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// Writes the CSV files; returns them. `dt` converts steps to sim_time.
pub fn export(r: &Recording, dir: &Path, dt: Option<f64>) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let mut written = Vec::new();
    for group in labelled(r) {
        // Union of steps (series of one group share them; latency may lag by one).
        let steps = group.steps();
        let mut text = String::from("step,sim_time");
        for m in &group.members {
            text += &format!(",{}", csv_field(&m.label));
        }
        text.push('\n');
        let mut columns: Vec<_> = group.members.iter().map(|m| aligned(&steps, m.series)).collect();
        for &k in &steps {
            let _ = write!(text, "{k},{}", sim_time(k, dt).map_or(String::new(), |t| format!("{t}")));
            for column in &mut columns {
                text.push(',');
                if let Some(v) = column.next().flatten() {
                    let _ = write!(text, "{v}");
                }
            }
            text.push('\n');
        }
        let path = dir.join(file_name(&group.path));
        staged::write(&path, |w| w.write_all(text.as_bytes()).map_err(|e| staged::cannot_write(&path, &e)))?;
        written.push(path);
    }
    Ok(written)
}
