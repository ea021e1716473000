//! The controller component: state feedback on an observer's estimate, u_k = r_k − G x̂_k
//! (seed 000 eq. 24), its design, and the process shell that runs it in lockstep.

pub mod design;
pub mod shell;

use lti::kernel::mul_into;
use lti::signal::Signal;
use lti::MatData;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// What the launcher tells the controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControllerConfig {
    /// Feedback gain G (l×n).
    pub g: MatData,
    /// Reference signals r, one per input.
    pub references: Vec<Signal>,
    /// Sample period, s.
    pub dt: f64,
    /// Number of steps.
    pub steps: u64,
    /// The observer whose estimate is fed back.
    pub observer: String,
}

/// State feedback as a step function.
#[derive(Debug, Clone)]
pub struct Controller {
    g: DMatrix<f64>,
    references: Vec<Signal>,
    dt: f64,
    gx: DVector<f64>,
    u: DVector<f64>,
}

impl Controller {
    /// From the configuration; fails if G and the references do not conform.
    pub fn new(cfg: &ControllerConfig) -> Result<Self, String> {
        let g: DMatrix<f64> = (&cfg.g).into();
        if g.nrows() != cfg.references.len() {
            return Err(format!("G has {} rows but there are {} references", g.nrows(), cfg.references.len()));
        }
        Ok(Self { gx: DVector::zeros(g.nrows()), u: DVector::zeros(g.nrows()), g, references: cfg.references.clone(), dt: cfg.dt })
    }

    /// u_k = r(t_k) − G x̂_k.
    pub fn step(&mut self, k: u64, xhat: &[f64]) -> &[f64] {
        let t = k as f64 * self.dt;
        for (u, r) in self.u.iter_mut().zip(&self.references) {
            *u = r.sample(t, self.dt);
        }
        mul_into(self.gx.as_mut_slice(), &self.g, xhat);
        for (u, gx) in self.u.iter_mut().zip(self.gx.iter()) {
            *u -= gx;
        }
        self.u.as_slice()
    }
}
