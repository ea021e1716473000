//! What the scenario's `[plant.replay]` becomes (scenario/src/replay_plant.rs): the file, its
//! column map, the options, and the run's grid and sizes, so that the check and the component
//! read the same thing from one JSON object.

use serde::Deserialize;

#[derive(Debug, Clone, Deserialize)]
pub struct Params {
    /// The data file, absolute.
    pub path: String,
    /// "csv", "mcap" or "rrd".
    pub format: String,
    /// MCAP: the JSON channels (topics) whose messages are the rows, joined by message index.
    #[serde(default)]
    pub channels: Vec<String>,
    /// CSV: the time column; MCAP: the time field (none: the rows are uniform at dt; MCAP:
    /// the messages' log_time).
    pub time: Option<String>,
    /// CSV columns (MCAP fields) of u (l), y (p), and optionally w (q) and x (n).
    #[serde(default)]
    pub inputs: Vec<String>,
    #[serde(default)]
    pub outputs: Vec<String>,
    pub disturbances: Option<Vec<String>>,
    pub states: Option<Vec<String>>,
    /// Without `inputs` (a log of a plant whose known inputs held still): the constant u
    /// (l values: the operating point's u_op, or 0).
    #[serde(default)]
    pub input_values: Option<Vec<f64>>,
    /// "none" or "zoh".
    pub resample: String,
    /// "error" or "hold".
    pub missing: String,
    /// The run's sample period and steps.
    pub dt: f64,
    pub steps: u64,
    /// The design model's sizes: states, outputs, known inputs, unknown inputs, columns of D.
    pub n: usize,
    pub p: usize,
    pub l: usize,
    pub q: usize,
    pub r: usize,
}

impl Params {
    /// The file's name, for messages.
    pub fn file(&self) -> String {
        std::path::Path::new(&self.path)
            .file_name()
            .map_or(self.path.clone(), |f| f.to_string_lossy().into_owned())
    }
}
