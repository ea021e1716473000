//! The replayed samples on the run's grid: row k is plant sample k without its fault slots,
//! `[x_k │ y_k │ w(t_k) │ v(t_k) │ r(t_k) │ u_{k−1}]` (PROTOCOL.md §4).

use serde::Serialize;

/// Rows of plant samples.
#[derive(Debug, Clone)]
pub struct Table {
    /// Values per row: n + p + q + r + 2l.
    pub width: usize,
    /// Row after row.
    pub data: Vec<f64>,
    /// What the summary says of the data.
    pub facts: Facts,
}

/// What a replay tells the run's summary.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Facts {
    /// The data file.
    pub file: String,
    /// Data rows in the file.
    pub rows: u64,
    /// Grid samples the run takes from it (steps + 1: the plant's end sample too).
    pub samples: u64,
    /// Grid samples filled by zero-order hold (`resample = "zoh"`): no row at their time.
    pub held_rows: u64,
    /// Cells that held their column's previous value (`missing = "hold"`).
    pub held_cells: u64,
    /// Whether the data carries the true state; without it x is 0 and the recorded errors are
    /// not estimation errors.
    pub states: bool,
    /// Whether the data carries the unknown inputs w; without them w is 0 and |w − ŵ| is |ŵ|,
    /// not an estimation error.
    pub disturbances: bool,
}

impl Table {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.data.len() / self.width.max(1)
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Sample k; past the last row (the plant's end sample of a run as long as its data) the
    /// last row holds.
    pub fn row(&self, k: u64) -> &[f64] {
        let i = (k as usize).min(self.len().saturating_sub(1));
        &self.data[i * self.width..(i + 1) * self.width]
    }
}

/// Refuses data shorter than the run: every step k = 0 … K − 1 needs its own sample.
pub fn enough(file: &str, have: u64, what: &str, steps: u64) -> Result<(), String> {
    if have < steps {
        return Err(format!(
            "{file}: {have} {what}; the scenario runs {steps} steps (duration / dt) and needs one per step"
        ));
    }
    Ok(())
}
