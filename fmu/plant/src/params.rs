//! What the launcher gives the FMU plant as `params` (made from `[plant.fmu]` by the scenario
//! crate, `scenario/src/fmu_plant.rs`).

use serde::Deserialize;

/// The FMU and the scenario's map of its variables.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// The `.fmu` file (absolute).
    pub path: String,
    /// FMU inputs receiving u (one per column of B).
    pub inputs: Vec<String>,
    /// FMU inputs receiving w (one per column of E).
    pub disturbances: Vec<String>,
    /// FMU outputs read as y (one per row of C).
    pub outputs: Vec<String>,
    /// FMU variables read as the true x.
    pub states: Vec<String>,
    /// Start values of parameters, by name (numbers or booleans).
    #[serde(default)]
    pub parameters: serde_json::Map<String, serde_json::Value>,
    /// doStep calls per sample.
    pub substeps: u32,
    /// `[plant] x0`: start values of the `states` variables (none: the FMU's own).
    #[serde(default)]
    pub x0: Option<Vec<f64>>,
}
