//! The controller component: state feedback on an observer's estimate, u_k = N r_k − G x̂_k
//! (seed 000 eq. 24, with the reference prefilter N of [`design`]), its design, and the process
//! shell that runs it in lockstep.

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
    /// Reference prefilter N (l×l).
    pub n: MatData,
    /// Reference signals r, one per input.
    pub references: Vec<Signal>,
    /// Sample period, s.
    pub dt: f64,
    /// The observer whose estimate is fed back.
    pub observer: String,
}

/// State feedback as a step function.
#[derive(Debug, Clone)]
pub struct Controller {
    g: DMatrix<f64>,
    n: DMatrix<f64>,
    r: DVector<f64>,
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
        let n: DMatrix<f64> = (&cfg.n).into();
        if n.shape() != (g.nrows(), g.nrows()) {
            return Err(format!("N is {}×{}, must be {}×{}", n.nrows(), n.ncols(), g.nrows(), g.nrows()));
        }
        let l = g.nrows();
        Ok(Self { gx: DVector::zeros(l), u: DVector::zeros(l), r: DVector::zeros(l), g, n, references: cfg.references.clone(), dt: cfg.dt })
    }

    /// u_k = N r(t_k) − G x̂_k.
    pub fn step(&mut self, k: u64, xhat: &[f64]) -> &[f64] {
        for (r, s) in self.r.iter_mut().zip(&self.references) {
            *r = s.sample_step(k, self.dt);
        }
        mul_into(self.u.as_mut_slice(), &self.n, self.r.as_slice());
        mul_into(self.gx.as_mut_slice(), &self.g, xhat);
        for (u, gx) in self.u.iter_mut().zip(self.gx.iter()) {
            *u -= gx;
        }
        self.u.as_slice()
    }
}
