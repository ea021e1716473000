//! Cancelling the unknown input with its estimate (`feedforward = "what"`). When w enters
//! through the inputs' columns — Γ_E = Γ_B M (matching condition; for a sampled continuous
//! plant it holds iff E = BM) — the input
//!
//! ```text
//! u_k = … − M ŵ_{k−1},      M = Γ_B⁺ Γ_E,
//! ```
//!
//! removes w's effect on the state up to the estimate's error and its one-step delay (ŵ_{k−1},
//! the latest estimate: `observer::design::InputEstimator` needs y_k). A step w is then cancelled
//! exactly once the estimate has converged.

use lti::pinv::pinv;
use lti::{Discrete, Mat};

/// Relative part of a column of Γ_E outside the range of Γ_B below which it counts as matched.
pub const MATCHED: f64 = 1e-8;

/// M with Γ_B M = Γ_E, or which unknown input does not enter through the inputs and by how much.
pub fn matched_gain(dm: &Discrete) -> Result<Mat, String> {
    let q = dm.e.ncols();
    if q == 0 {
        return Err(
            "the plant has no unknown input (E has no columns): there is no ŵ to cancel".into(),
        );
    }
    let m = pinv(&dm.b) * &dm.e;
    let outside = &dm.e - &dm.b * &m;
    for j in 0..q {
        let (off, size) = (outside.column(j).norm(), dm.e.column(j).norm());
        if off > MATCHED * size {
            return Err(format!(
                "w{} does not enter through the inputs (matching condition Γ_E = Γ_B M fails: {:.2e} of its column lies outside the range of Γ_B), so u cannot cancel it",
                j + 1,
                off / size.max(f64::MIN_POSITIVE)
            ));
        }
    }
    Ok(m)
}
