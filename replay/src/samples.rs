//! Mapped log values → plant samples on the run's grid, shared by every log format (CSV rows,
//! MCAP messages), so that the rules and the messages are the same whatever the file: which row
//! each grid time takes (`resample`), which cells hold (`missing`), and the assembly of
//! `[x │ y │ w │ v = 0 │ r = u_k │ u_{k−1}]` (PROTOCOL.md §4), where sample k carries r(t_k) = u_k
//! and, as the plant's u_{k−1}, the previous row's u (0 at k = 0).
//!
//! Time stamps must be strictly increasing; on the grid t_0 + k·dt within 10⁻⁶·dt unless
//! `resample = "zoh"`, which gives each grid time the last row at or before it (and counts the
//! grid samples that had no row of their own). A missing, unreadable or non-finite value is
//! refused naming the row and the column, or with `missing = "hold"` takes the column's previous
//! value (never the time: a row without its time has no place on the grid).

use crate::Params;
use crate::table::{Facts, Table, enough};

/// The mapped values of a log, row after row: `[t │ x │ y │ w │ u]`, t only when the log has a
/// time column (without one, row k is sample k).
pub struct Mapped {
    pub width: usize,
    pub timed: bool,
    pub cells: Vec<f64>,
    /// Cells that held their column's previous value.
    pub held_cells: u64,
    hold: bool,
}

impl Mapped {
    pub fn new(p: &Params, timed: bool, width: usize) -> Self {
        Mapped {
            width,
            timed,
            cells: Vec::new(),
            held_cells: 0,
            hold: p.missing == "hold",
        }
    }

    /// Rows complete so far.
    pub fn rows(&self) -> usize {
        self.cells.len() / self.width.max(1)
    }

    /// Appends column `j` of the current row: its value, or its reason for having none, which
    /// `missing = "hold"` answers with the previous row's value and otherwise refuses, `at`
    /// naming file, row and column.
    pub fn push(
        &mut self,
        j: usize,
        value: Result<f64, String>,
        at: impl FnOnce() -> String,
    ) -> Result<(), String> {
        let row = self.rows();
        let v = match value {
            Ok(v) => v,
            Err(_) if self.hold && row > 0 && !(self.timed && j == 0) => {
                self.held_cells += 1;
                self.cells[(row - 1) * self.width + j]
            }
            Err(why) => {
                let hint = if self.hold && row == 0 {
                    " (missing = \"hold\": no earlier value to hold)"
                } else if !self.hold {
                    " (missing = \"hold\" holds the previous value)"
                } else {
                    ""
                };
                return Err(format!("{}: {why}{hint}", at()));
            }
        };
        self.cells.push(v);
        Ok(())
    }
}

/// How a format names its rows and its time in messages: `row(i)` for the i-th row from 0
/// ("line 203 (row 202)", "row 202"), `time` for the time column ("time column", "log_time"),
/// `rows` for what a row is ("rows", "messages").
pub struct Naming<'a> {
    pub row: &'a dyn Fn(usize) -> String,
    pub time: &'a str,
    pub rows: &'a str,
}

/// The plant samples of `m` on the run's grid.
pub fn table(
    p: &Params,
    file: String,
    m: Mapped,
    states: bool,
    name: &Naming<'_>,
) -> Result<Table, String> {
    let rows = m.rows();
    let width = m.width;
    let cells = &m.cells;
    // Which row each grid sample k = 0 … K takes.
    let want = p.steps as usize + 1;
    let (pick, held_rows) = if m.timed {
        grid(&file, p, cells, width, rows, want, name)?
    } else {
        ((0..rows.min(want)).collect::<Vec<_>>(), 0)
    };
    let what = if m.timed && p.resample == "zoh" {
        "samples on the dt grid"
    } else {
        name.rows
    };
    enough(&file, pick.len() as u64, what, p.steps)?;

    let off = usize::from(m.timed);
    let nx = if states { p.n } else { 0 };
    let nw = p.disturbances.as_ref().map_or(0, Vec::len);
    let (n, pp, q, r, l) = (p.n, p.p, p.q, p.r, p.l);
    let out_w = n + pp + q + r + 2 * l;
    let zeros = vec![0.0; l];
    let held_u: Option<&[f64]> = (p.inputs.is_empty() && l > 0).then(|| {
        p.input_values
            .as_deref()
            .filter(|u| u.len() == l)
            .unwrap_or(&zeros)
    });
    let mut data = Vec::with_capacity(pick.len() * out_w);
    for (k, &i) in pick.iter().enumerate() {
        let c = &cells[i * width + off..(i + 1) * width];
        let (cx, rest) = c.split_at(nx);
        let (cy, rest) = rest.split_at(pp);
        let (cw, cu) = rest.split_at(nw);
        if states {
            data.extend_from_slice(cx)
        } else {
            data.extend(std::iter::repeat_n(0.0, n))
        }
        data.extend_from_slice(cy);
        if nw == 0 {
            data.extend(std::iter::repeat_n(0.0, q))
        } else {
            data.extend_from_slice(cw)
        }
        data.extend(std::iter::repeat_n(0.0, r));
        match held_u {
            // No input columns: u is the constant the scenario gives (u_op, or 0).
            Some(u) => {
                data.extend_from_slice(u);
                if k == 0 {
                    data.extend(std::iter::repeat_n(0.0, l))
                } else {
                    data.extend_from_slice(u)
                }
            }
            None => {
                data.extend_from_slice(cu);
                if k == 0 {
                    data.extend(std::iter::repeat_n(0.0, l));
                } else {
                    let prev = pick[k - 1];
                    data.extend_from_slice(&cells[prev * width + width - l..(prev + 1) * width]);
                }
            }
        }
    }
    let facts = Facts {
        file,
        rows: rows as u64,
        samples: pick.len() as u64,
        held_rows,
        held_cells: m.held_cells,
        states,
        disturbances: p.disturbances.is_some(),
    };
    Ok(Table {
        width: out_w,
        data,
        facts,
    })
}

/// The row each grid time t_0 + k·dt takes (k = 0 … `want` − 1, as far as the data reaches),
/// and how many grid times had no row of their own (zero-order hold).
fn grid(
    file: &str,
    p: &Params,
    cells: &[f64],
    width: usize,
    rows: usize,
    want: usize,
    name: &Naming<'_>,
) -> Result<(Vec<usize>, u64), String> {
    let t = |i: usize| cells[i * width];
    let dt = p.dt;
    let tol = |tk: f64| 1e-6 * dt + 4.0 * f64::EPSILON * tk.abs();
    let t0 = t(0);
    for i in 1..rows {
        if t(i) <= t(i - 1) {
            return Err(format!(
                "{file}: {}, {}: t = {} after t = {}: time stamps must increase",
                (name.row)(i),
                name.time,
                t(i),
                t(i - 1)
            ));
        }
    }
    if p.resample != "zoh" {
        for i in 0..rows.min(want) {
            let tk = t0 + i as f64 * dt;
            if (t(i) - tk).abs() > tol(tk) {
                return Err(format!(
                    "{file}: {}, {}: t = {} where the grid has t = {tk} (t_0 + {i}·dt, dt = {dt}): non-uniform time stamps (resample = \"zoh\" holds them onto the grid)",
                    (name.row)(i),
                    name.time,
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
