//! Process and measurement noise from a seeded generator.
//!
//! ```text
//! x_{k+1} = Φ x_k + … + w_k,   w_k ~ N(0, Q_d),      y_k = C x_k + … + ν_k,   ν_k ~ N(0, R),
//! ```
//!
//! Q_d is the exact discrete covariance of the continuous process noise over a step (Van Loan,
//! [`lti::process_noise_covariance`]), or the scenario's discrete one; the scenario computes it
//! and the Kalman design uses the same matrix. Each noise is drawn as S ξ with S Sᵀ = the
//! covariance (S = V·√Λ from its symmetric eigendecomposition: a semi-definite covariance is
//! allowed) and ξ standard normal from ChaCha8 — one stream per purpose (process, measurement,
//! each sensor-noise fault), so one stream's draws never shift another's, and a seed gives the
//! same realisation in every run mode and process.

use lti::MatData;
use nalgebra::{DMatrix, DVector};
use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// The noise of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Noise {
    /// The generator's seed.
    pub seed: u64,
    /// Q_d, n×n: covariance of w_k (all zeros: no process noise).
    pub qd: MatData,
    /// R, p×p: covariance of ν_k (all zeros: no measurement noise).
    pub r: MatData,
}

/// The stream of the process noise; measurement is 2, sensor-noise fault i is 16 + i.
pub(crate) const PROCESS: u64 = 1;
pub(crate) const MEASUREMENT: u64 = 2;
pub(crate) const FAULT_BASE: u64 = 16;

/// A standard-normal stream.
#[derive(Debug, Clone)]
pub(crate) struct Stream(ChaCha8Rng);

impl Stream {
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        Stream(rng)
    }

    pub fn normal(&mut self) -> f64 {
        let rng: &mut dyn RngCore = &mut self.0;
        StandardNormal.sample(rng)
    }
}

/// A Gaussian vector source N(0, Σ).
#[derive(Debug, Clone)]
pub(crate) struct Gaussian {
    s: DMatrix<f64>,
    xi: DVector<f64>,
    stream: Stream,
}

impl Gaussian {
    /// None when Σ is zero (nothing to draw).
    pub fn new(sigma: &MatData, seed: u64, stream: u64) -> Option<Self> {
        let m: DMatrix<f64> = sigma.into();
        if m.iter().all(|&v| v == 0.0) {
            return None;
        }
        let e = m.symmetric_eigen();
        let root = e.eigenvalues.map(|l| l.max(0.0).sqrt());
        let s = &e.eigenvectors * DMatrix::from_diagonal(&root);
        Some(Gaussian {
            xi: DVector::zeros(s.ncols()),
            s,
            stream: Stream::new(seed, stream),
        })
    }

    /// Adds one draw to `out`.
    pub fn add_to(&mut self, out: &mut [f64]) {
        for v in self.xi.iter_mut() {
            *v = self.stream.normal();
        }
        lti::kernel::mul_acc(out, &self.s, self.xi.as_slice());
    }
}
