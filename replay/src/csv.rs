//! A CSV log as plant samples. The first line names the columns; `[plant.replay]` maps them by
//! name to u, y and optionally w and x, and names the time column if there is one. Row i holds
//! the signals at t_i, with u_i the input applied from t_i on: on the grid, sample k carries
//! r(t_k) = u_k and, as the plant's u_{k−1} (PROTOCOL.md §4), the previous row's u (0 at k = 0).
//!
//! Time stamps must be strictly increasing; on the grid t_0 + k·dt within 10⁻⁶·dt unless
//! `resample = "zoh"`, which gives each grid time the last row at or before it (and counts the
//! grid samples that had no row of their own). An empty, unreadable or non-finite cell is
//! refused naming the line and column, or with `missing = "hold"` takes the column's previous
//! value. Every message is one line: file, where, why.

use scenario::suggest::did_you_mean;

use crate::table::{enough, Facts, Table};
use crate::Params;

/// Reads the CSV log the parameters name.
pub fn load(p: &Params) -> Result<Table, String> {
    let file = p.file();
    let bytes = std::fs::read(&p.path).map_err(|e| format!("{file}: {e}"))?;
    let text = String::from_utf8(bytes).map_err(|e| format!("{file}: not UTF-8 text (byte {})", e.utf8_error().valid_up_to()))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else { return Err(format!("{file}: empty: no header line")) };
    let names: Vec<String> = split(header).map(|c| unquote(c).to_string()).collect();

    // The mapped columns, in sample order: x, y, w, u; the time column apart.
    let find = |key: &str, i: usize, name: &str| -> Result<usize, String> {
        names.iter().position(|h| h == name).ok_or_else(|| {
            format!("{file}: no column {name:?} (plant.replay.{key}[{}]){}; the header has {}", i + 1, did_you_mean(name, names.iter().map(String::as_str)), names.join(", "))
        })
    };
    let group = |key: &str, list: &[String]| -> Result<Vec<usize>, String> { list.iter().enumerate().map(|(i, n)| find(key, i, n)).collect() };
    let states = p.states.is_some();
    let x = group("states", p.states.as_deref().unwrap_or_default())?;
    let y = group("outputs", &p.outputs)?;
    let w = group("disturbances", p.disturbances.as_deref().unwrap_or_default())?;
    let u = group("inputs", &p.inputs)?;
    let time = match &p.time {
        Some(t) => Some(names.iter().position(|h| h == t).ok_or_else(|| format!("{file}: no time column {t:?} (plant.replay.time){}; the header has {}", did_you_mean(t, names.iter().map(String::as_str)), names.join(", ")))?),
        None => None,
    };
    let cols: Vec<usize> = time.iter().chain(&x).chain(&y).chain(&w).chain(&u).copied().collect();
    let hold = p.missing == "hold";

    // Parse: per row the time (or the row index) and the mapped cells in `cols` order.
    let width = cols.len();
    let mut cells: Vec<f64> = Vec::new();
    let mut line_of: Vec<usize> = Vec::new();
    let mut held_cells = 0u64;
    let mut cut: Vec<&str> = Vec::with_capacity(names.len());
    for (ln, line) in lines {
        cut.clear();
        cut.extend(split(line));
        let row = line_of.len();
        for (j, &c) in cols.iter().enumerate() {
            let at = || format!("{file}: line {} (row {}), column {:?}", ln + 1, row + 1, names[c]);
            let Some(cell) = cut.get(c) else {
                return Err(format!("{}: the line has {} cells, the header {} columns", at(), cut.len(), names.len()));
            };
            let cell = unquote(cell);
            let v = match cell.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(v) => Err(format!("{v} is not finite")),
                Err(_) if cell.is_empty() => Err("empty cell".to_string()),
                Err(_) => Err(format!("{cell:?} is not a number")),
            };
            let v = match v {
                Ok(v) => v,
                // The time column never holds: a row without its time has no place on the grid.
                Err(why) if hold && row > 0 && !(time.is_some() && j == 0) => {
                    held_cells += 1;
                    let _ = why;
                    cells[(row - 1) * width + j]
                }
                Err(why) => {
                    let hint = if hold && row == 0 { " (missing = \"hold\": no earlier value to hold)" } else if !hold { " (missing = \"hold\" holds the previous value)" } else { "" };
                    return Err(format!("{}: {why}{hint}", at()));
                }
            };
            cells.push(v);
        }
        line_of.push(ln + 1);
    }
    let rows = line_of.len();
    if rows == 0 {
        return Err(format!("{file}: no data rows under the header"));
    }

    // Which row each grid sample k = 0 … K takes.
    let want = p.steps as usize + 1;
    let (pick, held_rows) = match time {
        None => ((0..rows.min(want)).collect::<Vec<_>>(), 0),
        Some(_) => grid(&file, p, &cells, width, &line_of, want)?,
    };
    let what = if time.is_some() && p.resample == "zoh" { "samples on the dt grid" } else { "rows" };
    enough(&file, pick.len() as u64, what, p.steps)?;

    // Assemble [x │ y │ w │ v = 0 │ r = u_k │ u_{k−1}].
    let off = usize::from(time.is_some());
    let (n, pp, q, r, l) = (p.n, p.p, p.q, p.r, p.l);
    let out_w = n + pp + q + r + 2 * l;
    let mut data = Vec::with_capacity(pick.len() * out_w);
    for (k, &i) in pick.iter().enumerate() {
        let c = &cells[i * width + off..(i + 1) * width];
        let (cx, rest) = c.split_at(x.len());
        let (cy, rest) = rest.split_at(pp);
        let (cw, cu) = rest.split_at(w.len());
        if states { data.extend_from_slice(cx) } else { data.extend(std::iter::repeat_n(0.0, n)) }
        data.extend_from_slice(cy);
        if w.is_empty() { data.extend(std::iter::repeat_n(0.0, q)) } else { data.extend_from_slice(cw) }
        data.extend(std::iter::repeat_n(0.0, r));
        data.extend_from_slice(cu);
        if k == 0 {
            data.extend(std::iter::repeat_n(0.0, l));
        } else {
            let prev = pick[k - 1];
            data.extend_from_slice(&cells[prev * width + width - l..(prev + 1) * width]);
        }
    }
    let facts = Facts { file, rows: rows as u64, samples: pick.len() as u64, held_rows, held_cells, states };
    Ok(Table { width: out_w, data, facts })
}

/// The row each grid time t_0 + k·dt takes (k = 0 … `want` − 1, as far as the data reaches),
/// and how many grid times had no row of their own (zero-order hold).
fn grid(file: &str, p: &Params, cells: &[f64], width: usize, line_of: &[usize], want: usize) -> Result<(Vec<usize>, u64), String> {
    let t = |i: usize| cells[i * width];
    let dt = p.dt;
    let tol = |tk: f64| 1e-6 * dt + 4.0 * f64::EPSILON * tk.abs();
    let t0 = t(0);
    let rows = line_of.len();
    for i in 1..rows {
        if t(i) <= t(i - 1) {
            return Err(format!("{file}: line {} (row {}), time column: t = {} after t = {}: time stamps must increase", line_of[i], i + 1, t(i), t(i - 1)));
        }
    }
    if p.resample != "zoh" {
        for i in 0..rows.min(want) {
            let tk = t0 + i as f64 * dt;
            if (t(i) - tk).abs() > tol(tk) {
                return Err(format!(
                    "{file}: line {} (row {}), time column: t = {} where the grid has t = {tk} (t_0 + {i}·dt, dt = {dt}): non-uniform time stamps (resample = \"zoh\" holds them onto the grid)",
                    line_of[i],
                    i + 1,
                    t(i)
                ));
            }
        }
        return Ok(((0..rows.min(want)).collect(), 0));
    }
    let last = t(rows - 1);
    let (mut pick, mut held, mut j) = (Vec::with_capacity(want), 0u64, 0usize);
    for k in 0..want {
        let tk = t0 + k as f64 * dt;
        if tk > last + tol(tk) {
            break;
        }
        while j + 1 < rows && t(j + 1) <= tk + tol(tk) {
            j += 1;
        }
        if t(j) < tk - tol(tk) {
            held += 1;
        }
        pick.push(j);
    }
    Ok((pick, held))
}

/// The cells of a line (comma-separated; quotes around a cell are dropped, commas inside quotes
/// are not supported: a log of numbers has none).
fn split(line: &str) -> impl Iterator<Item = &str> {
    line.trim_end_matches('\r').split(',').map(str::trim)
}

fn unquote(cell: &str) -> &str {
    cell.strip_prefix('"').and_then(|c| c.strip_suffix('"')).unwrap_or(cell).trim()
}
