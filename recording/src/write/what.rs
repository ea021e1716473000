//! The unknown-input estimate ŵ of an observer, formed from the recorded samples:
//!
//! ```text
//! ŵ_k = W y_{k+1} − (WCΦ) x̂_k − (WCΓ_B) u_k
//! ```
//!
//! (`observer::design::InputEstimator`). It needs y_{k+1}, so it completes with row k + 1 and is
//! recorded at t_k, beside the w_k it estimates; its error is w_k − ŵ_k with w_k the plant's
//! recorded w(t_k) — the value held over the step for steps and piecewise inputs.

use lti::Mat;
use lti::input_estimate::InputEstimateStep;

use super::tail::BlockMax;
use crate::nan::nan_max;

/// One observer's ŵ, step by step, and its error against the recorded w.
#[derive(Debug, Clone)]
pub struct InputEstimate {
    step: InputEstimateStep,
    prev_w: Vec<f64>,
    /// Whether `value()` holds ŵ_{k−1} (false at the first row).
    pub ready: bool,
    /// max_j |w_j − ŵ_j| of each completed estimate, by the step it estimates.
    errors: BlockMax,
    exact_tail: f64,
    planned_tail: u64,
}

impl InputEstimate {
    /// From W, WCΦ, WCΓ_B (and the constant c at an operating point), for a run of `steps`
    /// steps whose tail starts at `planned_tail`.
    pub fn new(
        w: Mat,
        w_c_phi: &Mat,
        w_c_gamma_b: &Mat,
        offset: Option<Vec<f64>>,
        steps: u64,
        planned_tail: u64,
    ) -> Self {
        let q = w.nrows();
        let step = InputEstimateStep::new(w, w_c_phi, w_c_gamma_b);
        let step = match offset {
            Some(c) => step.with_offset(c),
            None => step,
        };
        InputEstimate {
            step,
            prev_w: vec![0.0; q],
            ready: false,
            errors: BlockMax::new(steps),
            exact_tail: 0.0,
            planned_tail,
        }
    }

    /// ŵ_{k−1}, completed by the last row (valid when `ready`).
    pub fn value(&self) -> &[f64] {
        &self.step.value
    }

    /// Row k: y_k, u_{k−1} (what the plant held over step k − 1), w(t_k) and x̂_k.
    pub fn push(&mut self, k: u64, y: &[f64], u_prev: &[f64], w: &[f64], xhat: &[f64]) {
        self.ready = self.step.push(y, u_prev, xhat);
        if self.ready {
            let err = self
                .step
                .value
                .iter()
                .zip(&self.prev_w)
                .fold(0.0, |m, (a, b)| nan_max(m, (a - b).abs()));
            self.errors.push(k - 1, err);
            if k > self.planned_tail {
                self.exact_tail = nan_max(self.exact_tail, err);
            }
        }
        lti::kernel::copy(&mut self.prev_w, w);
    }
    /// max |w − ŵ| over the tail [start, …) of the estimates completed; exact for a completed run.
    pub fn tail_max_abs_error(&self, start: u64, completed: bool) -> f64 {
        if completed {
            self.exact_tail
        } else {
            self.errors.max_from(start)
        }
    }
}
