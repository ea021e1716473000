//! The unknown inputs themselves, reconstructed from an unknown-input observer's estimate.
//!
//! The sampled plant x_{k+1} = Φx_k + Γ_Bu_k + Γ_Ew_k, y = Cx (+ Dv) gives, for w held over the
//! step,
//!
//! ```text
//! y_{k+1} − CΦx_k − CΓ_Bu_k = CΓ_E w_k (+ D v_{k+1}),
//! ŵ_k = W (y_{k+1} − CΦx̂_k − CΓ_Bu_k),        W = (CΓ_E)⁺   (Hui–Żak: the first q rows of [CΓ_E D]⁺)
//! ```
//!
//! (the discrete form of Chen & Patton's ŵ = (CE)⁺(ẏ − CAx̂ − CBu), without a derivative). It
//! exists when CΓ_E has full column rank q (for Hui–Żak, [CΓ_E D] rank q + r), which is more than
//! the UIO's rank(CE) = rank(E): with dependent columns of E only their sum acts, and no single
//! w_j can be told.
//!
//! Delay and bias, the same for every family (they share this formula): ŵ_k needs y_{k+1}, so it
//! is known one sample late (recorded at t_k, beside the w_k it estimates). Once the estimate has
//! converged (x̂_k = x_k) it is exact, to rounding, for a w held over each step (steps,
//! piecewise-constant inputs that switch on samples); for a w that varies within a step it is
//! the Γ_E-weighted mean of w over the step, so it lags a sine by about dt/2. Before then the
//! error e_k = x_k − x̂_k enters as −WCΦe_k. Measurement noise enters as W(ν_{k+1} − CΦ(…)):
//! since CΓ_E ≈ CE·dt, W amplifies it by ~1/dt — ŵ is a differentiator, like ẏ in the
//! continuous form.

use lti::pinv::{pinv, rank};
use lti::{Discrete, Mat};

/// ŵ_k = W y_{k+1} − (WCΦ) x̂_k − (WCΓ_B) u_k.
#[derive(Debug, Clone, PartialEq)]
pub struct InputEstimator {
    /// W, q×p.
    pub w: Mat,
    /// WCΦ, q×n.
    pub w_c_phi: Mat,
    /// WCΓ_B, q×l.
    pub w_c_gamma_b: Mat,
    /// At an operating point, the constant c = w_op − W(y_op − CΦx_op − CΓ_Bu_op) added to every
    /// estimate: ŵ = w_op + δŵ with δŵ the recursion in deviations. `None` at the origin.
    pub offset: Option<Vec<f64>>,
}

impl InputEstimator {
    /// Sets the offset for the operating point `op` (its q values of w_op; module docs).
    pub fn at_operating_point(&mut self, op: &lti::OperatingPoint) {
        if op.is_origin() {
            self.offset = None;
            return;
        }
        let at = lti::input_estimate::at_rest(
            &self.w,
            &self.w_c_phi,
            &self.w_c_gamma_b,
            &op.x,
            &op.u,
            &op.y,
        );
        self.offset = Some(at.iter().zip(&op.w).map(|(a, w)| w - a).collect());
    }
}

/// The estimator of the sampled plant `m`, if CΓ_E (or [CΓ_E D], `with_d`) has full column rank.
pub(crate) fn estimator(m: &Discrete, with_d: bool) -> Option<InputEstimator> {
    let q = m.e.ncols();
    if q == 0 {
        return None;
    }
    let ce = &m.c * &m.e;
    let w = if with_d && m.d.ncols() > 0 {
        let mut both = Mat::zeros(ce.nrows(), q + m.d.ncols());
        both.columns_mut(0, q).copy_from(&ce);
        both.columns_mut(q, m.d.ncols()).copy_from(&m.d);
        if rank(&both) != both.ncols() {
            return None;
        }
        pinv(&both).rows(0, q).into_owned()
    } else {
        if rank(&ce) != q {
            return None;
        }
        pinv(&ce)
    };
    let w_c = &w * &m.c;
    Some(InputEstimator {
        w_c_phi: &w_c * &m.a,
        w_c_gamma_b: &w_c * &m.b,
        w,
        offset: None,
    })
}
