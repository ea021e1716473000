//! Residual evaluation: one number per step and residual, and its threshold.
//!
//! * `norm`: J_k = ‖r_k‖₂;
//! * `rms`: J_k = √(Σ_{i<N} ‖r_{k−i}‖² / N) over a moving window of N samples (fewer at the start);
//! * `forgetting`: J_k² = λ J_{k−1}² + (1 − λ)‖r_k‖², J_{−1} = 0 (an exponential window of
//!   about 1/(1 − λ) samples);
//! * `chi2`: J_k = r_kᵀ Σ_r⁺ r_k with Σ_r the residual's stationary covariance under the noise
//!   ([`crate::covariance`]), through its eigendecomposition on the directions where it is not
//!   zero (rank d). A fault-free stationary Gaussian residual gives J_k ~ χ²(d), so the threshold
//!   χ²_d(1 − α) is exceeded by a fault-free sample with probability α.

use lti::Mat;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::spec::{DiagnoserSpec, Evaluation, Threshold};

/// Eigenvalues of Σ_r below this fraction of the largest count as zero (no noise that way).
const RANK_TOL: f64 = 1e-10;

/// (threshold, degrees of freedom) of a member.
pub fn threshold_for(spec: &DiagnoserSpec, cov: Option<&Mat>) -> Result<(f64, usize), String> {
    let dof = cov.map_or(0, |c| whitening(c).nrows());
    match spec.threshold {
        Threshold::Fixed(t) => Ok((t, dof)),
        // Not known until the fault-free realisations have run: nothing exceeds it meanwhile.
        Threshold::Calibrated { .. } => Ok((f64::INFINITY, dof)),
        Threshold::FalseAlarm(alpha) => {
            if spec.evaluation != Evaluation::Chi2 {
                return Err(
                    "a false-alarm probability sets a χ² threshold: it needs evaluation = \"chi2\""
                        .into(),
                );
            }
            if cov.is_none() {
                return Err("a false-alarm probability needs the noise statistics: the scenario has no [noise]".into());
            }
            if dof == 0 {
                return Err(
                    "the residual has no noise in any direction (Σ_r = 0): give a fixed threshold"
                        .into(),
                );
            }
            let chi = ChiSquared::new(dof as f64).map_err(|e| e.to_string())?;
            Ok((chi.inverse_cdf(1.0 - alpha), dof))
        }
    }
}

/// W with WᵀW = Σ_r⁺ on Σ_r's range: rows v_iᵀ/√λ_i for λ_i > RANK_TOL·λ_max.
pub fn whitening(cov: &Mat) -> Mat {
    let e = cov.clone().symmetric_eigen();
    let top = e.eigenvalues.iter().fold(0.0f64, |a, &b| a.max(b));
    let keep: Vec<usize> = (0..e.eigenvalues.len())
        .filter(|&i| e.eigenvalues[i] > RANK_TOL * top && top > 0.0)
        .collect();
    Mat::from_fn(keep.len(), cov.nrows(), |r, c| {
        e.eigenvectors[(c, keep[r])] / e.eigenvalues[keep[r]].sqrt()
    })
}

/// The evaluation of one residual, step by step (no allocation per step).
#[derive(Debug, Clone)]
pub struct Evaluator {
    kind: Evaluation,
    /// ‖r‖² of the last N samples (rms).
    ring: Vec<f64>,
    at: usize,
    filled: usize,
    sum: f64,
    /// J² (forgetting).
    state: f64,
    /// Whitening (chi2).
    w: Mat,
    white: Vec<f64>,
}

impl Evaluator {
    /// For a residual of covariance `cov` (used by chi2 only).
    pub fn new(kind: Evaluation, cov: Option<&Mat>) -> Self {
        let w = match (kind, cov) {
            (Evaluation::Chi2, Some(c)) => whitening(c),
            _ => Mat::zeros(0, 0),
        };
        let window = if let Evaluation::Rms { window } = kind {
            window.max(1)
        } else {
            0
        };
        Evaluator {
            kind,
            ring: vec![0.0; window],
            at: 0,
            filled: 0,
            sum: 0.0,
            state: 0.0,
            white: vec![0.0; w.nrows()],
            w,
        }
    }

    /// J_k of r_k.
    pub fn push(&mut self, r: &[f64]) -> f64 {
        let sq: f64 = r.iter().map(|v| v * v).sum();
        match self.kind {
            Evaluation::Norm => sq.sqrt(),
            Evaluation::Rms { .. } => {
                let n = self.ring.len();
                self.sum += sq - self.ring[self.at];
                self.ring[self.at] = sq;
                self.at = (self.at + 1) % n;
                self.filled = (self.filled + 1).min(n);
                // The running sum is re-added from the window once per lap, so rounding cannot
                // accumulate over a long run.
                if self.at == 0 {
                    self.sum = self.ring.iter().sum();
                }
                (self.sum.max(0.0) / self.filled as f64).sqrt()
            }
            Evaluation::Forgetting { lambda } => {
                self.state = lambda * self.state + (1.0 - lambda) * sq;
                self.state.sqrt()
            }
            Evaluation::Chi2 => {
                lti::kernel::mul_into(&mut self.white, &self.w, r);
                self.white.iter().map(|v| v * v).sum()
            }
        }
    }
}
