//! `launcher export --csv DIR`: one CSV per entity group (e.g. `/observer/uio/error` →
//! `observer_uio_error.csv`) with columns `step,sim_time,<member>…`, each member headed by its
//! name and unit from the recorded scenario (`eta [rad]`, `e3 [rad]`, `plant->observer/uio [ns]`).
//! Floats are written in Rust's shortest round-trip form, so they parse back to the same bits.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use scenario::Scenario;

use crate::read::{Recording, Series};
use crate::signals;
use crate::tools::recorded_scenario;

/// Groups series by their parent path: "/plant/x/1" → ("/plant/x", "1").
pub fn groups(r: &Recording) -> BTreeMap<String, Vec<(String, &Series)>> {
    let mut out: BTreeMap<String, Vec<(String, &Series)>> = BTreeMap::new();
    for (path, s) in &r.series {
        let (group, member) = match path.rsplit_once('/') {
            Some((g, m)) if !g.is_empty() && (m.parse::<usize>().is_ok() || g == "/latency") => (g.to_string(), m.to_string()),
            _ => (path.clone(), "value".to_string()),
        };
        out.entry(group).or_default().push((member, s));
    }
    for members in out.values_mut() {
        members.sort_by_key(|(m, _)| m.parse::<usize>().map_or((1, m.clone()), |i| (0, format!("{i:09}"))));
    }
    out
}

/// File name of a group: "/observer/uio/error" → "observer_uio_error.csv".
pub fn file_name(group: &str) -> String {
    format!("{}.csv", group.trim_start_matches('/').replace('/', "_"))
}

/// The column header of `member` of `group`: the signal's name and unit where the scenario is
/// known (`eta [rad]`), a latency's hop name in ns (the `step` member becomes `step_latency`,
/// not a second `step` column), else the member itself.
pub fn header(s: Option<&Scenario>, r: &Recording, group: &str, member: &str) -> String {
    let path = format!("{group}/{member}");
    if group == "/latency" {
        let name = if member == "step" { "step_latency".to_string() } else { r.names.get(&path).cloned().unwrap_or_else(|| member.to_string()) };
        return csv_field(&format!("{name} [ns]"));
    }
    match signals::named(s, &path) {
        Some(n) => csv_field(&n.with_unit()),
        None => csv_field(member),
    }
}

/// Quotes a field holding a comma or a quote (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// Writes the CSV files; returns them. `dt` converts steps to sim_time.
pub fn export(r: &Recording, dir: &Path, dt: Option<f64>) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let scenario = recorded_scenario(r);
    let mut written = Vec::new();
    for (group, members) in groups(r) {
        // Union of steps (series of one group share them; latency may lag by one).
        let mut steps: Vec<i64> = members.iter().flat_map(|(_, s)| s.steps.iter().copied()).collect();
        steps.sort_unstable();
        steps.dedup();
        let mut text = String::from("step,sim_time");
        for (m, _) in &members {
            text += &format!(",{}", header(scenario.as_ref(), r, &group, m));
        }
        text.push('\n');
        let mut cursors = vec![0usize; members.len()];
        for &k in &steps {
            let _ = write!(text, "{k},{}", dt.map_or(String::new(), |dt| format!("{}", k as f64 * dt)));
            for (i, (_, s)) in members.iter().enumerate() {
                text.push(',');
                if cursors[i] < s.steps.len() && s.steps[cursors[i]] == k {
                    let _ = write!(text, "{}", s.values[cursors[i]]);
                    cursors[i] += 1;
                }
            }
            text.push('\n');
        }
        let path = dir.join(file_name(&group));
        std::fs::write(&path, text).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}
