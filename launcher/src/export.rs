//! `launcher export --csv DIR`: one CSV per entity group (e.g. `/observer/uio/error` →
//! `observer_uio_error.csv`) with columns `step,sim_time,<member>…`. Floats are written in
//! Rust's shortest round-trip form, so they parse back to the same bits.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::recording::{Recording, Series};

/// Groups series by their parent path: "/plant/x/0" → ("/plant/x", "0").
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

/// Writes the CSV files; returns them. `dt` converts steps to sim_time.
pub fn export(r: &Recording, dir: &Path, dt: Option<f64>) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let mut written = Vec::new();
    for (group, members) in groups(r) {
        // Union of steps (series of one group share them; latency may lag by one).
        let mut steps: Vec<i64> = members.iter().flat_map(|(_, s)| s.steps.iter().copied()).collect();
        steps.sort_unstable();
        steps.dedup();
        let mut text = String::from("step,sim_time");
        for (m, _) in &members {
            text += &format!(",{m}");
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
