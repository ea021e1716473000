//! The unknown input, one sample late, from an observer's estimate (the recursion of
//! `observer::design::InputEstimator`):
//!
//! ```text
//! ŵ_{k−1} = W y_k − (WCΦ) x̂_{k−1} − (WCΓ_B) u_{k−1}
//! ```
//!
//! At an operating point ([`crate::OperatingPoint`]) the recursion runs in deviations and a
//! constant c = w_op − W(y_op − CΦx_op − CΓ_Bu_op) is added ([`InputEstimateStep::with_offset`]).
//! It needs y_k, so ŵ_{k−1} completes with sample k. A left factor M may be folded into all three
//! matrices (MW, MWCΦ, MWCΓ_B) to get Mŵ directly — the controller's cancellation of w. One pass
//! of products and sums, in a fixed order, so the recorder and the controller form the same bits.

use crate::Mat;
use crate::kernel::{copy, mul_into};

/// W y − WCΦ x − WCΓ_B u at a constant point (x, u, y): what the recursion gives there (q
/// values; with M folded in, M times it). At an operating point the estimator's offset is
/// w_op minus it, and a controller's cancellation of Mδŵ adds minus it.
pub fn at_rest(
    w: &Mat,
    w_c_phi: &Mat,
    w_c_gamma_b: &Mat,
    x: &[f64],
    u: &[f64],
    y: &[f64],
) -> Vec<f64> {
    let col = |v: &[f64]| Mat::from_column_slice(v.len(), 1, v);
    (w * col(y) - w_c_phi * col(x) - w_c_gamma_b * col(u))
        .iter()
        .copied()
        .collect()
}

/// ŵ_{k−1} from sample k, step by step.
#[derive(Debug, Clone)]
pub struct InputEstimateStep {
    /// [W  −WCΦ  −WCΓ_B], so that one pass over each row forms ŵ, summed in the order of the
    /// three products one after another.
    m: Mat,
    /// [y_k; x̂_{k−1}; u_{k−1}] as `m` reads it (x̂'s part holds x̂_k between samples).
    stacked: Vec<f64>,
    /// p and n: where x̂'s and u's parts start.
    p: usize,
    n: usize,
    started: bool,
    /// The constant of an estimate made in deviations from an operating point, if any.
    offset: Option<Vec<f64>>,
    /// ŵ_{k−1}, completed by the last sample (valid once [`Self::push`] returned true).
    pub value: Vec<f64>,
}

impl InputEstimateStep {
    /// From W (q×p), WCΦ (q×n) and WCΓ_B (q×l).
    pub fn new(w: Mat, w_c_phi: &Mat, w_c_gamma_b: &Mat) -> Self {
        let (q, p, n, l) = (w.nrows(), w.ncols(), w_c_phi.ncols(), w_c_gamma_b.ncols());
        let mut m = Mat::zeros(q, p + n + l);
        m.columns_mut(0, p).copy_from(&w);
        m.columns_mut(p, n).copy_from(&-w_c_phi);
        m.columns_mut(p + n, l).copy_from(&-w_c_gamma_b);
        InputEstimateStep {
            m,
            stacked: vec![0.0; p + n + l],
            p,
            n,
            started: false,
            offset: None,
            value: vec![0.0; q],
        }
    }

    /// The same recursion with a constant added to every estimate (q values): at an operating
    /// point, c = w_op − W(y_op − CΦx_op − CΓ_Bu_op) (M c when M is folded in).
    pub fn with_offset(mut self, c: Vec<f64>) -> Self {
        debug_assert_eq!(c.len(), self.value.len(), "one offset per estimate");
        self.offset = Some(c);
        self
    }

    /// Sample k: y_k, the u_{k−1} the plant held over step k − 1, and x̂_k. Returns whether
    /// `value` now holds ŵ_{k−1} (false at the first sample).
    pub fn push(&mut self, y: &[f64], u_prev: &[f64], xhat: &[f64]) -> bool {
        let ready = self.started;
        if ready {
            let (yy, rest) = self.stacked.split_at_mut(self.p);
            copy(yy, y);
            copy(&mut rest[self.n..], u_prev);
            mul_into(&mut self.value, &self.m, &self.stacked);
            if let Some(c) = &self.offset {
                for (v, c) in self.value.iter_mut().zip(c) {
                    *v += c;
                }
            }
        }
        copy(&mut self.stacked[self.p..self.p + self.n], xhat);
        self.started = true;
        ready
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For x_{k+1} = Φx_k + Γ_Bu_k + Γ_Ew_k, y = Cx and x̂ = x, the recursion gives back w_{k−1}.
    #[test]
    fn it_recovers_the_unknown_input_of_a_sampled_plant() {
        let phi = Mat::from_row_slice(2, 2, &[0.9, 0.1, 0.0, 0.8]);
        let (gb, ge, c) = (
            Mat::from_row_slice(2, 1, &[0.0, 1.0]),
            Mat::from_row_slice(2, 1, &[1.0, 0.5]),
            Mat::identity(2, 2),
        );
        let w = crate::pinv::pinv(&(&c * &ge));
        let mut est = InputEstimateStep::new(w.clone(), &(&w * &c * &phi), &(&w * &c * &gb));
        let mut x = nalgebra::DVector::from_vec(vec![1.0, -1.0]);
        let mut u_prev = [0.0];
        let mut w_prev = 0.0;
        for k in 0..20 {
            let y = &c * &x;
            if est.push(y.as_slice(), &u_prev, x.as_slice()) {
                assert!(
                    (est.value[0] - w_prev).abs() < 1e-12,
                    "step {k}: {} vs {w_prev}",
                    est.value[0]
                );
            }
            let (u, wk) = ((k as f64).sin(), 0.3 * k as f64);
            x = &phi * &x + &gb * u + &ge * wk;
            u_prev = [u];
            w_prev = wk;
        }
    }
}
