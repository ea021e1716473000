//! What `uio-fmu-plant --linearize` reads (the request, JSON on stdin) and writes (the answer).

use serde::{Deserialize, Serialize};

use crate::params::Params;

/// What the launcher asks for, on stdin.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Request {
    /// The plant's map (`[plant.fmu]`); its `x0` is x_op (or the trim's first guess).
    pub params: Params,
    pub u: Vec<f64>,
    pub w: Vec<f64>,
    pub dt: f64,
    #[serde(default)]
    pub trim: bool,
}

/// A Jacobian block and its estimated error (max |D(h/2) − D(h)| / 3 over the block).
#[derive(Debug, Serialize)]
pub struct Block {
    pub rows: Vec<Vec<f64>>,
    pub error: f64,
}

/// The trim's outcome.
#[derive(Debug, Serialize)]
pub struct Trim {
    pub iterations: usize,
    /// max |x⁺ − x| at the end, over all states.
    pub residual: f64,
    /// x⁺ − x at the end.
    pub step_residual: Vec<f64>,
    /// States (0-based) in a direction along which Φ − I is singular.
    pub free: Vec<usize>,
}

/// The answer, on stdout.
#[derive(Debug, Serialize)]
pub struct Answer {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    #[serde(rename = "Phi")]
    pub phi: Block,
    #[serde(rename = "Gamma_B")]
    pub gamma_b: Block,
    #[serde(rename = "Gamma_E")]
    pub gamma_e: Block,
    #[serde(rename = "C")]
    pub c: Block,
    /// ∂y₀/∂u and ∂y₀/∂w: a direct feedthrough the sampled model has no place for.
    pub d_u: Block,
    pub d_w: Block,
    /// The steps h_j of x, u, w.
    pub steps: Vec<f64>,
    pub trim: Option<Trim>,
    /// FMU instances made.
    pub instances: usize,
}
