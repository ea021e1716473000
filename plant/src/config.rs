//! What the launcher tells the plant.

use lti::signal::Signal;
use lti::MatData;
use serde::{Deserialize, Serialize};

/// The plant's model, signals and run length.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlantConfig {
    /// State matrix A.
    pub a: MatData,
    /// Known-input matrix B.
    pub b: MatData,
    /// Output matrix C.
    pub c: MatData,
    /// Unknown-input distribution E (may have no columns).
    pub e: MatData,
    /// Measurement-disturbance distribution D (may have no columns).
    pub d: MatData,
    /// Initial state.
    pub x0: Vec<f64>,
    /// Unknown inputs w, one per column of E.
    pub disturbances: Vec<Signal>,
    /// Measurement disturbances v, one per column of D.
    pub measurement_disturbances: Vec<Signal>,
    /// Known inputs (open loop) or references (closed loop), one per column of B.
    pub inputs: Vec<Signal>,
    /// Sample period, s.
    pub dt: f64,
    /// Number of steps.
    pub steps: u64,
    /// A state whose magnitude exceeds this stops the run.
    pub state_bound: f64,
}

/// The plant of a run as the launcher plans it: its configuration (the built-in plant's
/// `params`) and the shape of the ring around it, which places the processes on CPUs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlantRun {
    /// The plant itself.
    pub plant: PlantConfig,
    /// Per observer, whether it may trail the plant (a follower, see [`lockstep::FOLLOWER_LAG`]).
    pub followers: Vec<bool>,
    /// Whether a controller provides u (else u = the input signals).
    pub controller: bool,
}
