//! The operating point a design model is linearised at.
//!
//! Real plants sit away from the origin: a building at 20 °C with its heaters at a nominal power,
//! tanks at their levels with their pumps running. The design model (A, B, C, E) is then the
//! linearisation there, in deviations
//!
//! ```text
//! δx = x − x_op,   δu = u − u_op,   δw = w − w_op,   δy = y − y_op,
//! δẋ = A δx + B δu + E δw,          δy = C δx,
//! ```
//!
//! while the plant (built-in, an FMU, a log, a component in any language) speaks absolute units.
//! For the built-in linear plant the point must be an equilibrium,
//!
//! ```text
//! A x_op + B u_op + E w_op = 0          (continuous),
//! Φ x_op + Γ_B u_op + Γ_E w_op = x_op   (discrete),
//! ```
//!
//! so that the plant in absolute units is the model itself and y_op = C x_op. The observers and
//! the controller work in deviations and exchange absolute signals: the offsets they add are
//! formed where they are designed (`observer::Designed::at_operating_point`).

use serde::{Deserialize, Serialize};

use crate::Mat;

/// (x_op, u_op, w_op, y_op): n, l, q and p values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OperatingPoint {
    /// The state x_op.
    pub x: Vec<f64>,
    /// The known inputs u_op (columns of B).
    pub u: Vec<f64>,
    /// The unknown inputs w_op (columns of E).
    pub w: Vec<f64>,
    /// The outputs y_op.
    pub y: Vec<f64>,
}

impl OperatingPoint {
    /// Whether every value is 0 (the origin: nothing to offset).
    pub fn is_origin(&self) -> bool {
        [&self.x, &self.u, &self.w, &self.y]
            .iter()
            .all(|v| v.iter().all(|&x| x == 0.0))
    }

    /// c_r = y_op − C x_op: what a residual of absolute signals, y − C x̂, carries at this point
    /// beyond the deviation residual δy − C δx̂ (0 where the output map is linear, as for the
    /// built-in plant; an FMU's trimmed outputs need not be).
    ///
    /// Preconditions: `c` p×n, and the point's sizes n and p.
    pub fn output_offset(&self, c: &Mat) -> Vec<f64> {
        let cx = c * Mat::from_column_slice(self.x.len(), 1, &self.x);
        self.y.iter().zip(cx.iter()).map(|(y, cx)| y - cx).collect()
    }

    /// The equilibrium residual of the model at this point: A x + B u + E w (continuous,
    /// `discrete` false) or Φ x + Γ_B u + Γ_E w − x, and the scale it is judged against,
    /// max_i Σ_j (|A_ij||x_j| + |B_ij||u_j| + |E_ij||w_j|) (+ |x_i| when discrete): rounding of
    /// the sums leaves a few ε of it.
    ///
    /// Preconditions: `a` n×n, `b` n×l, `e` n×q, and the point's sizes n, l, q.
    pub fn equilibrium_residual(
        &self,
        a: &Mat,
        b: &Mat,
        e: &Mat,
        discrete: bool,
    ) -> (Vec<f64>, f64) {
        let n = a.nrows();
        let mut residual = vec![0.0; n];
        let mut scale: f64 = 0.0;
        for (i, r) in residual.iter_mut().enumerate() {
            let mut sum = 0.0;
            let mut size = 0.0;
            for (m, v) in [(a, &self.x), (b, &self.u), (e, &self.w)] {
                for (j, &vj) in v.iter().enumerate() {
                    sum += m[(i, j)] * vj;
                    size += (m[(i, j)] * vj).abs();
                }
            }
            if discrete {
                sum -= self.x[i];
                size += self.x[i].abs();
            }
            *r = sum;
            scale = scale.max(size);
        }
        (residual, scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_equilibrium_leaves_no_residual_and_a_shifted_state_does() {
        // ẋ = −2x + u + 0.5w: x_op = (u + 0.5 w)/2.
        let (a, b, e) = (
            Mat::from_element(1, 1, -2.0),
            Mat::from_element(1, 1, 1.0),
            Mat::from_element(1, 1, 0.5),
        );
        let mut op = OperatingPoint {
            x: vec![2.5],
            u: vec![4.0],
            w: vec![2.0],
            y: vec![2.5],
        };
        let (r, scale) = op.equilibrium_residual(&a, &b, &e, false);
        assert_eq!((r, scale), (vec![0.0], 10.0)); // |−5| + |4| + |1|
        op.x[0] = 3.0;
        assert_eq!(op.equilibrium_residual(&a, &b, &e, false).0, vec![-1.0]);
        // Discrete: x⁺ = 0.5x + u: x_op = 2u.
        let (phi, gb) = (Mat::from_element(1, 1, 0.5), Mat::from_element(1, 1, 1.0));
        let op = OperatingPoint {
            x: vec![2.0],
            u: vec![1.0],
            w: vec![],
            y: vec![],
        };
        assert_eq!(
            op.equilibrium_residual(&phi, &gb, &Mat::zeros(1, 0), true)
                .0,
            vec![0.0]
        );
        assert!(!op.is_origin());
    }
}
