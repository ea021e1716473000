//! What an external plant needs from its configuration (PROTOCOL.md §3), read from the protocol's
//! public fields only — `model`, `signals`, `params` — as any component in any language would.

use lockstep::component::ComponentConfig;
use lockstep::PlantLayout;
use lti::signal::Signal;
use lti::Mat;
use serde::Deserialize;

/// The scenario's design model: A, B, C, D, E and x0.
#[derive(Debug, Clone)]
pub struct DesignModel {
    /// State matrix.
    pub a: Mat,
    /// Known-input matrix.
    pub b: Mat,
    /// Output matrix.
    pub c: Mat,
    /// Measurement-disturbance distribution (may have no columns).
    pub d: Mat,
    /// Unknown-input distribution (may have no columns).
    pub e: Mat,
    /// Initial state.
    pub x0: Vec<f64>,
}

#[derive(Deserialize)]
#[allow(non_snake_case)]
struct RawModel {
    A: Vec<Vec<f64>>,
    B: Vec<Vec<f64>>,
    C: Vec<Vec<f64>>,
    D: Vec<Vec<f64>>,
    E: Vec<Vec<f64>>,
    x0: Vec<f64>,
}

/// A matrix from rows; `rows` rows of `cols` columns when it has no entries.
fn mat(rows: &[Vec<f64>], nrows: usize) -> Mat {
    let cols = rows.first().map_or(0, Vec::len);
    Mat::from_fn(nrows, cols, |i, j| rows[i][j])
}

impl DesignModel {
    /// From the configuration's `model`.
    pub fn of(cfg: &ComponentConfig) -> Result<Self, String> {
        let m: RawModel = serde_json::from_value(cfg.model.clone()).map_err(|e| format!("model: {e}"))?;
        let (n, p) = (m.A.len(), m.C.len());
        Ok(DesignModel { a: mat(&m.A, n), b: mat(&m.B, n), c: mat(&m.C, p), d: mat(&m.D, p), e: mat(&m.E, n), x0: m.x0 })
    }

    /// Where each signal sits in the plant's sample (PROTOCOL.md §4).
    pub fn layout(&self) -> PlantLayout {
        PlantLayout { n: self.a.nrows(), p: self.c.nrows(), q: self.e.ncols(), r: self.d.ncols(), l: self.b.ncols() }
    }
}

/// The scenario's signals, one per column of E, D and B, and the state bound.
#[derive(Debug, Clone, Deserialize)]
pub struct Signals {
    /// Unknown inputs w.
    pub disturbances: Vec<Signal>,
    /// Measurement disturbances v.
    pub measurement_disturbances: Vec<Signal>,
    /// Known inputs / references r.
    pub inputs: Vec<Signal>,
    /// |x_i| beyond this stops the run.
    pub state_bound: f64,
}

impl Signals {
    /// From the configuration's `signals`.
    pub fn of(cfg: &ComponentConfig) -> Result<Self, String> {
        serde_json::from_value(cfg.signals.clone()).map_err(|e| format!("signals: {e}"))
    }
}
