//! The plant model every design starts from:
//!
//! ```text
//! ẋ = A x + B u + E w,     y = C x + D v,
//! ```
//!
//! u known, w unknown (state disturbance, "unknown input"), v unknown (measurement disturbance).
//! E and D may have no columns.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::discretize::zoh;

/// A continuous-time LTI plant with unknown inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// State matrix, n×n.
    pub a: DMatrix<f64>,
    /// Known-input matrix, n×l.
    pub b: DMatrix<f64>,
    /// Output matrix, p×n.
    pub c: DMatrix<f64>,
    /// Unknown-input distribution, n×q (q may be 0).
    pub e: DMatrix<f64>,
    /// Measurement-disturbance distribution, p×r (r may be 0).
    pub d: DMatrix<f64>,
}

/// The exact zero-order-hold sampling of a [`Model`] with period dt:
/// x_{k+1} = A_d x_k + B_d u_k + E_d w_k, y_k = C x_k + D v_k, for u and w held over the step.
#[derive(Debug, Clone, PartialEq)]
pub struct Discrete {
    /// e^{A dt}.
    pub a: DMatrix<f64>,
    /// ∫₀^dt e^{As} ds B.
    pub b: DMatrix<f64>,
    /// C (unchanged).
    pub c: DMatrix<f64>,
    /// ∫₀^dt e^{As} ds E.
    pub e: DMatrix<f64>,
    /// D (unchanged).
    pub d: DMatrix<f64>,
    /// The sample period.
    pub dt: f64,
}

impl Model {
    /// Number of states.
    pub fn n(&self) -> usize {
        self.a.nrows()
    }

    /// Number of outputs.
    pub fn p(&self) -> usize {
        self.c.nrows()
    }

    /// Number of known inputs.
    pub fn l(&self) -> usize {
        self.b.ncols()
    }

    /// Exact sampling with period dt.
    pub fn discretize(&self, dt: f64) -> Discrete {
        let (a, b, e) = if self.n() > crate::expm::DOUBLE_DOUBLE_MAX {
            // Both already take the double-precision exponential: one of [[A, B E], [0, 0]]
            // gives Φ, Γ and Γ_E at once (half of a 1000-state model's sampling time).
            let (l, q) = (self.b.ncols(), self.e.ncols());
            let mut be = DMatrix::zeros(self.n(), l + q);
            be.columns_mut(0, l).copy_from(&self.b);
            be.columns_mut(l, q).copy_from(&self.e);
            let (a, gamma) = zoh(&self.a, &be, dt);
            (
                a,
                gamma.columns(0, l).into_owned(),
                gamma.columns(l, q).into_owned(),
            )
        } else {
            let (a, b) = zoh(&self.a, &self.b, dt);
            let (_, e) = zoh(&self.a, &self.e, dt);
            (a, b, e)
        };
        Discrete {
            a,
            b,
            c: self.c.clone(),
            e,
            d: self.d.clone(),
            dt,
        }
    }
}

/// A dense matrix in a serialisable, row-major form.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MatData {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// Entries, row by row.
    pub data: Vec<f64>,
}

impl From<&DMatrix<f64>> for MatData {
    fn from(m: &DMatrix<f64>) -> Self {
        let data = (0..m.nrows())
            .flat_map(|i| m.row(i).iter().copied().collect::<Vec<_>>())
            .collect();
        MatData {
            rows: m.nrows(),
            cols: m.ncols(),
            data,
        }
    }
}

impl From<&MatData> for DMatrix<f64> {
    fn from(m: &MatData) -> Self {
        DMatrix::from_row_slice(m.rows, m.cols, &m.data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_large_model_samples_its_inputs_as_separate_holds_would() {
        // 110 states: Φ, Γ and Γ_E from one exponential of [[A, B E], [0, 0]] agree with a
        // ZOH of B and of E each (the same double-precision path) to rounding.
        let n = 110;
        let a = DMatrix::from_fn(n, n, |i, j| {
            ((i * 7 + j * 13) as f64 * 0.17).sin() / 10.0 - if i == j { 2.0 } else { 0.0 }
        });
        let b = DMatrix::from_fn(n, 3, |i, j| ((i + 5 * j) as f64 * 0.3).cos());
        let e = DMatrix::from_fn(n, 2, |i, j| ((2 * i + j) as f64 * 0.7).sin());
        let m = Model {
            a: a.clone(),
            b: b.clone(),
            c: DMatrix::identity(4, n),
            e: e.clone(),
            d: DMatrix::zeros(4, 0),
        };
        let d = m.discretize(0.05);
        let (phi, gamma) = zoh(&a, &b, 0.05);
        let (_, gamma_e) = zoh(&a, &e, 0.05);
        assert!((&d.a - &phi).amax() <= 1e-14 * phi.amax());
        assert!((&d.b - &gamma).amax() <= 1e-14 * gamma.amax());
        assert!((&d.e - &gamma_e).amax() <= 1e-14 * gamma_e.amax());
    }
}
