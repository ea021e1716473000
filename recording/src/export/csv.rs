//! `uio-launcher export --csv DIR`: one CSV per entity group (e.g. `/observer/uio/error` →
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

/// A header cell as a spreadsheet shows it, neither a formula nor text that reorders or breaks
/// lines, then quoted where it holds a comma, a quote or a line break (RFC 4180). Names come
/// from the recorded scenario, which anyone may have written:
/// - controls other than newline and tab, bidirectional controls and the line and paragraph
///   separators are written as `\u{…}` ([`scenario::untrusted::printable`]): they make a header
///   read other than it is;
/// - a cell starting with `=`, `+`, `-`, `@` or a tab is a formula to Excel and LibreOffice
///   (`=cmd|' /C calc'!A0`): it gets a leading `'`, the escape they document for text (OWASP,
///   "CSV Injection").
fn csv_field(s: &str) -> String {
    let mut s = scenario::untrusted::printable(s);
    if s.starts_with(['=', '+', '-', '@', '\t']) {
        s.insert(0, '\'');
    }
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s
    }
}

/// The files [`export`] writes for `r`, by name.
pub fn planned(r: &Recording) -> Vec<String> {
    labelled(r).iter().map(|g| file_name(&g.path)).collect()
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
        let mut columns: Vec<_> = group
            .members
            .iter()
            .map(|m| aligned(&steps, m.series))
            .collect();
        for &k in &steps {
            let _ = write!(
                text,
                "{k},{}",
                sim_time(k, dt).map_or(String::new(), |t| format!("{t}"))
            );
            for column in &mut columns {
                text.push(',');
                if let Some(v) = column.next().flatten() {
                    let _ = write!(text, "{v}");
                }
            }
            text.push('\n');
        }
        let path = dir.join(file_name(&group.path));
        staged::write(&path, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| staged::cannot_write(&path, &e))
        })?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::csv_field;

    #[test]
    fn a_header_that_a_spreadsheet_would_run_is_written_as_text() {
        assert_eq!(csv_field("=cmd|' /C calc'!A0"), "'=cmd|' /C calc'!A0");
        assert_eq!(csv_field("@SUM(A1)"), "'@SUM(A1)");
        assert_eq!(csv_field("+1"), "'+1");
        assert_eq!(csv_field("-x [m]"), "'-x [m]");
        assert_eq!(csv_field("=a,b"), "\"'=a,b\"");
    }

    #[test]
    fn bidi_controls_and_line_separators_are_escaped_and_plain_names_kept() {
        assert_eq!(csv_field("x\u{202e}gnp.exe"), "x\\u{202e}gnp.exe");
        assert_eq!(csv_field("a\u{2028}b\u{2069}"), "a\\u{2028}b\\u{2069}");
        assert_eq!(csv_field("\rx\u{1b}[2K"), "\\rx\\u{1b}[2K");
        assert_eq!(csv_field("eta [rad]"), "eta [rad]");
        assert_eq!(csv_field("θ−1 [°]"), "θ−1 [°]");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }
}
