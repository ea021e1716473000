//! A CSV log as plant samples. The first line names the columns; `[plant.replay]` maps them by
//! name to u, y and optionally w and x, and names the time column if there is one. Row i holds
//! the signals at t_i, with u_i the input applied from t_i on; samples.rs puts the rows on the
//! run's grid with the rules every log format shares. An empty, unreadable or non-finite cell
//! is refused naming the line and column (or held, `missing = "hold"`). Every message is one
//! line: file, where, why.

use scenario::suggest::did_you_mean;
use scenario::untrusted::{quoted, quoted_list};

use crate::Params;
use crate::samples::{self, Mapped, Naming};
use crate::table::Table;

/// Reads the CSV log the parameters name.
pub fn load(p: &Params) -> Result<Table, String> {
    let file = p.file();
    let bytes = std::fs::read(&p.path).map_err(|e| format!("{file}: {e}"))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        format!(
            "{file}: not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        )
    })?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(format!("{file}: empty: no header line"));
    };
    let names: Vec<String> = split(header).map(|c| unquote(c).to_string()).collect();

    // The mapped columns, in sample order: x, y, w, u; the time column apart.
    let find = |key: &str, i: usize, name: &str| -> Result<usize, String> {
        names.iter().position(|h| h == name).ok_or_else(|| {
            format!(
                "{file}: no column {} (plant.replay.{key}[{}]){}; the header has {}",
                quoted(name),
                i + 1,
                did_you_mean(name, names.iter().map(String::as_str)),
                quoted_list(names.iter().map(String::as_str))
            )
        })
    };
    let group = |key: &str, list: &[String]| -> Result<Vec<usize>, String> {
        list.iter()
            .enumerate()
            .map(|(i, n)| find(key, i, n))
            .collect()
    };
    let states = p.states.is_some();
    let x = group("states", p.states.as_deref().unwrap_or_default())?;
    let y = group("outputs", &p.outputs)?;
    let w = group(
        "disturbances",
        p.disturbances.as_deref().unwrap_or_default(),
    )?;
    let u = group("inputs", &p.inputs)?;
    let time = match &p.time {
        Some(t) => Some(names.iter().position(|h| h == t).ok_or_else(|| {
            format!(
                "{file}: no time column {} (plant.replay.time){}; the header has {}",
                quoted(t),
                did_you_mean(t, names.iter().map(String::as_str)),
                quoted_list(names.iter().map(String::as_str))
            )
        })?),
        None => None,
    };
    let cols: Vec<usize> = time
        .iter()
        .chain(&x)
        .chain(&y)
        .chain(&w)
        .chain(&u)
        .copied()
        .collect();

    // Parse: per row the time (if any) and the mapped cells in `cols` order.
    let mut m = Mapped::new(p, time.is_some(), cols.len());
    let mut line_of: Vec<usize> = Vec::new();
    let mut cut: Vec<&str> = Vec::with_capacity(names.len());
    for (ln, line) in lines {
        cut.clear();
        cut.extend(split(line));
        let row = line_of.len();
        for (j, &c) in cols.iter().enumerate() {
            let at = || {
                format!(
                    "{file}: line {} (row {}), column {:?}",
                    ln + 1,
                    row + 1,
                    names[c]
                )
            };
            let Some(cell) = cut.get(c) else {
                return Err(format!(
                    "{}: the line has {} cells, the header {} columns",
                    at(),
                    cut.len(),
                    names.len()
                ));
            };
            let cell = unquote(cell);
            let v = match cell.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(v) => Err(format!("{v} is not finite")),
                Err(_) if cell.is_empty() => Err("empty cell".to_string()),
                Err(_) => Err(format!("{cell:?} is not a number")),
            };
            m.push(j, v, at)?;
        }
        line_of.push(ln + 1);
    }
    if line_of.is_empty() {
        return Err(format!("{file}: no data rows under the header"));
    }
    let row = |i: usize| format!("line {} (row {})", line_of[i], i + 1);
    samples::table(
        p,
        file,
        m,
        states,
        &Naming {
            row: &row,
            time: "time column",
            rows: "rows",
        },
    )
}

/// The cells of a line (comma-separated; quotes around a cell are dropped, commas inside quotes
/// are not supported: a log of numbers has none).
fn split(line: &str) -> impl Iterator<Item = &str> {
    line.trim_end_matches('\r').split(',').map(str::trim)
}

fn unquote(cell: &str) -> &str {
    cell.strip_prefix('"')
        .and_then(|c| c.strip_suffix('"'))
        .unwrap_or(cell)
        .trim()
}
