//! The scenario file as written: every table rejects unknown keys.

use std::collections::BTreeMap;

use lti::signal::Signal;
use serde::Deserialize;

/// A matrix: rows of numbers, or the path of a `.npy` file beside the scenario
/// ([`crate::matrix_file`]), which validation replaces by its rows before anything reads them.
#[derive(Debug, Clone)]
pub enum Rows {
    /// `A = [[…], […]]`.
    Inline(Vec<Vec<f64>>),
    /// `A = "model/A.npy"`, relative to the scenario's folder.
    File(String),
}

impl<'de> Deserialize<'de> for Rows {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Rows;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("rows of numbers, or the path of a .npy file")
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<Rows, E> {
                Ok(Rows::File(s.to_string()))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Rows, A::Error> {
                let mut rows = Vec::new();
                while let Some(r) = seq.next_element::<Vec<f64>>()? {
                    rows.push(r);
                }
                Ok(Rows::Inline(rows))
            }
        }
        d.deserialize_any(Visit)
    }
}

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// Sample period: seconds, or a time with its unit ("1 min", [`lti::units`]).
    #[serde(deserialize_with = "lti::units::de::seconds")]
    pub dt: f64,
    /// Length: seconds, or "48 h".
    #[serde(deserialize_with = "lti::units::de::seconds")]
    pub duration: f64,
    pub plant: RawPlant,
    #[serde(default)]
    pub disturbance: Vec<Signal>,
    #[serde(default)]
    pub measurement_disturbance: Vec<Signal>,
    #[serde(default)]
    pub input: Vec<Signal>,
    #[serde(default)]
    pub observer: Vec<RawObserver>,
    pub controller: Option<RawController>,
    pub expect: Option<RawExpect>,
    /// The noise generator's seed (default 0; `--seed` overrides it).
    pub seed: Option<u64>,
    pub noise: Option<RawNoise>,
    #[serde(default)]
    pub fault: Vec<RawFault>,
    #[serde(default)]
    pub diagnoser: Vec<RawDiagnoser>,
    /// The share of a fault's active time it must be isolated correctly for to count as
    /// isolated (default 0.9).
    pub isolated_fraction: Option<f64>,
    /// How long a component that is running (or waiting for a core) may publish nothing before
    /// the run is stopped, s (default 60; `--stall-timeout` overrides it).
    #[serde(default, deserialize_with = "lti::units::de::wall_seconds_opt")]
    pub stall_timeout: Option<f64>,
    /// The unit of a bare number of a simulated time ("h": `dt = 1` is an hour; read before
    /// the rest, [`lti::units::with_bare_unit`]); also the plots' time unit.
    pub time_unit: Option<String>,
    /// The stretch at the run's end its tail figures are taken over: seconds, or "12 h"
    /// (default: the last quarter of the steps).
    #[serde(default, deserialize_with = "lti::units::de::seconds_opt")]
    pub tail: Option<f64>,
    /// Host name → its agent's Zenoh endpoint.
    pub hosts: Option<BTreeMap<String, String>>,
}

/// `[noise]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawNoise {
    /// Q_c: intensity of the continuous process noise ν in ẋ = … + Gν (k×k).
    pub process: Option<Rows>,
    /// G, n×k (default I).
    #[serde(rename = "G")]
    pub g: Option<Rows>,
    /// Q_d: covariance of the process noise per step, n×n (instead of `process`).
    pub process_discrete: Option<Rows>,
    /// R: covariance of the measurement noise per sample, p×p.
    pub measurement: Option<Rows>,
}

/// `[[fault]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFault {
    pub name: String,
    pub target: String,
    pub channel: i64,
    pub kind: String,
    pub value: f64,
    pub profile: Option<String>,
    #[serde(default, deserialize_with = "lti::units::de::seconds_opt")]
    pub start: Option<f64>,
    #[serde(default, deserialize_with = "lti::units::de::seconds_opt")]
    pub end: Option<f64>,
    /// `[[on, off], …]`: seconds, or times with their units (`[["6 h", "7 h"]]`).
    #[serde(default, deserialize_with = "lti::units::de::seconds_pairs_opt")]
    pub intervals: Option<Vec<Vec<f64>>>,
}

/// `calibrate = { runs, margin }` of a `[[diagnoser]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCalibrate {
    pub runs: i64,
    pub margin: Option<f64>,
}

/// `[[diagnoser]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDiagnoser {
    pub name: String,
    pub scheme: String,
    pub faults: String,
    /// The channels of the class it watches (1-based), when not all.
    pub channels: Option<Vec<i64>>,
    pub observer: Option<String>,
    pub poles: Option<Vec<RawPole>>,
    pub placement: Option<String>,
    pub structure: Option<Vec<Vec<i64>>>,
    pub evaluation: Option<String>,
    pub window: Option<i64>,
    pub forgetting: Option<f64>,
    pub threshold: Option<f64>,
    pub false_alarm: Option<f64>,
    pub calibrate: Option<RawCalibrate>,
    pub persistence: Option<i64>,
    #[serde(default, deserialize_with = "lti::units::de::seconds_opt")]
    pub ignore_before: Option<f64>,
    /// `glr = { window, false_alarm }`: a windowed GLR test beside the evaluation.
    pub glr: Option<RawGlr>,
}

/// `glr = { window, false_alarm }` of a `[[diagnoser]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGlr {
    /// How long an onset is tried for, s.
    #[serde(deserialize_with = "lti::units::de::seconds")]
    pub window: f64,
    /// The bound on the false-alarm probability per sample.
    pub false_alarm: f64,
}

/// `[plant]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPlant {
    /// "continuous" (default: A, B, E) or "discrete" (Phi, Gamma_B, Gamma_E per step of dt).
    pub time: Option<String>,
    #[serde(rename = "A")]
    pub a: Option<Rows>,
    #[serde(rename = "B")]
    pub b: Option<Rows>,
    /// Φ of a discrete-time plant.
    #[serde(rename = "Phi")]
    pub phi: Option<Rows>,
    /// Γ_B of a discrete-time plant.
    #[serde(rename = "Gamma_B")]
    pub gamma_b: Option<Rows>,
    /// Γ_E of a discrete-time plant.
    #[serde(rename = "Gamma_E")]
    pub gamma_e: Option<Rows>,
    #[serde(rename = "C")]
    pub c: Rows,
    #[serde(rename = "E")]
    pub e: Option<Rows>,
    #[serde(rename = "D")]
    pub d: Option<Rows>,
    /// x(0); an FMU plant may leave it out (then its own start values).
    pub x0: Option<Vec<f64>>,
    /// |x_i| beyond this stops the run (default 1e9).
    pub state_bound: Option<f64>,
    /// Names of the states for plots and exports (default x1, x2, …).
    pub state_names: Option<Vec<String>>,
    /// Units of the states.
    pub state_units: Option<Vec<String>>,
    /// Names of the outputs, rows of C (default y1, y2, …).
    pub output_names: Option<Vec<String>>,
    /// Units of the outputs.
    pub output_units: Option<Vec<String>>,
    /// Names of the known inputs, columns of B (default r1, r2, …).
    pub input_names: Option<Vec<String>>,
    /// Units of the known inputs.
    pub input_units: Option<Vec<String>>,
    /// Names of the unknown inputs, columns of E (default w1, w2, …).
    pub disturbance_names: Option<Vec<String>>,
    /// Units of the unknown inputs.
    pub disturbance_units: Option<Vec<String>>,
    /// Names of the measurement disturbances, columns of D (default v1, v2, …).
    pub measurement_disturbance_names: Option<Vec<String>>,
    /// Units of the measurement disturbances.
    pub measurement_disturbance_units: Option<Vec<String>>,
    /// Who simulates the true plant, when not the built-in exact linear plant.
    pub process: Option<RawProcess>,
    /// An FMU (FMI 2.0/3.0 co-simulation) simulates the true plant.
    pub fmu: Option<RawFmu>,
    /// Recorded data (a CSV log or a run's `.rrd`) is replayed as the true plant.
    pub replay: Option<RawReplay>,
    /// Fault distribution F_f (n×m): component faults act through its columns.
    #[serde(rename = "Ff")]
    pub ff: Option<Rows>,
    /// The host it runs on (a name in `[hosts]`).
    pub host: Option<String>,
    /// `[plant.operating_point]`: where the model is linearised (it is in deviations there).
    pub operating_point: Option<RawOperatingPoint>,
}

/// `[plant.operating_point]`: x, u, w (default 0) and y (default C x).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawOperatingPoint {
    pub x: Option<Vec<f64>>,
    pub u: Option<Vec<f64>>,
    pub w: Option<Vec<f64>>,
    pub y: Option<Vec<f64>>,
}

/// An external component: its command and parameters (PROTOCOL.md §7).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProcess {
    pub command: Vec<String>,
    pub params: Option<toml::Table>,
}

/// `[plant.fmu]`: an FMU as the plant, its variables mapped by name.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFmu {
    /// The `.fmu` file, relative to the scenario's folder.
    pub path: String,
    /// FMU inputs receiving u, one per column of B.
    pub inputs: Option<Vec<String>>,
    /// FMU inputs receiving w, one per column of E.
    pub disturbances: Option<Vec<String>>,
    /// FMU outputs read as y, one per row of C.
    pub outputs: Vec<String>,
    /// FMU variables read as the true state x, one per state.
    pub states: Vec<String>,
    /// Start values of FMU parameters, by name.
    pub parameters: Option<toml::Table>,
    /// doStep calls per sample (default 1).
    pub substeps: Option<u32>,
}

/// `[plant.replay]`: recorded samples as the plant, a CSV's columns (an MCAP's JSON fields)
/// mapped by name.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawReplay {
    /// The `.csv`, `.mcap` or `.rrd` file, relative to the scenario's folder.
    pub path: String,
    /// MCAP: the JSON channel whose messages are the rows, or several joined message by message.
    pub channel: Option<RawChannels>,
    /// CSV: the time column; MCAP: the time field (absent: CSV rows uniform at dt, MCAP
    /// messages at their log_time).
    pub time: Option<String>,
    /// CSV columns read as u, one per column of B.
    pub inputs: Option<Vec<String>>,
    /// CSV columns read as y, one per row of C.
    pub outputs: Option<Vec<String>>,
    /// CSV columns read as w, one per column of E (absent: w = 0).
    pub disturbances: Option<Vec<String>>,
    /// CSV columns read as the true x, one per state (absent: no errors).
    pub states: Option<Vec<String>>,
    /// `"zoh"`: put non-uniform time stamps on the grid by zero-order hold.
    pub resample: Option<String>,
    /// `"hold"`: an empty or non-finite cell holds the column's previous value.
    pub missing: Option<String>,
}

/// `[plant.replay] channel`: one topic or a list of them.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum RawChannels {
    One(String),
    Many(Vec<String>),
}

/// One pole as written: a real number, or [re, im] for a complex pair.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum RawPole {
    Real(f64),
    Pair(Vec<f64>),
}

/// `[[observer]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawObserver {
    pub name: String,
    pub kind: String,
    pub poles: Option<Vec<RawPole>>,
    pub placement: Option<String>,
    #[serde(rename = "H")]
    pub h: Option<Rows>,
    pub decay: Option<f64>,
    pub path: Option<String>,
    /// `gain = "lqe"`: the free gain from the DARE of the sampled error pair, instead of poles.
    pub gain: Option<String>,
    /// LQE process weight (n×n, or the reduced order's size).
    #[serde(rename = "Q")]
    pub q: Option<Rows>,
    /// LQE measurement weight (p×p).
    #[serde(rename = "R")]
    pub r: Option<Rows>,
    /// The initial estimate x̂(0), n values.
    pub xhat0: Option<Vec<f64>>,
    /// `kind = "process"`: the command and its parameters.
    pub command: Option<Vec<String>>,
    pub params: Option<toml::Table>,
    /// The host it runs on (a name in `[hosts]`).
    pub host: Option<String>,
}

/// `[controller]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawController {
    pub kind: String,
    pub observer: String,
    pub poles: Option<Vec<RawPole>>,
    pub gain: Option<Rows>,
    pub placement: Option<String>,
    /// Where `poles` are placed: "sampled" (default) or "continuous".
    pub domain: Option<String>,
    /// `kind = "lqr"`: the state and input weights.
    #[serde(rename = "Q")]
    pub q: Option<Rows>,
    #[serde(rename = "R")]
    pub r: Option<Rows>,
    /// Rows of C_t: the state combinations that follow the reference.
    pub track: Option<Rows>,
    /// Integral action on the tracked outputs.
    pub integral: Option<bool>,
    /// "what": cancel the matched unknown input with the observer's ŵ.
    pub feedforward: Option<String>,
    /// Known inputs (by name) the controller does not command: they keep their `[[input]]`
    /// signal (the outdoor temperature of a building).
    pub measured_disturbances: Option<Vec<String>>,
    /// `kind = "process"`: the command and its parameters.
    pub command: Option<Vec<String>>,
    pub params: Option<toml::Table>,
    /// The host it runs on (a name in `[hosts]`).
    pub host: Option<String>,
}

/// `[expect]`: per-observer upper bounds on the run's figures.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawExpect {
    /// Max |x − x̂| over the tail (the last quarter of the steps completed), per observer.
    #[serde(default)]
    pub tail_max_abs_error: BTreeMap<String, f64>,
    /// Max |y − Cx̂| over the tail, per observer.
    #[serde(default)]
    pub tail_max_abs_residual: BTreeMap<String, f64>,
    /// Pairs of observers whose estimates must agree at every step: "a/b" = tolerance.
    #[serde(default)]
    pub max_abs_difference: BTreeMap<String, f64>,
    /// Upper bound on tail error(uio) / tail error(reference): "uio/luenberger" = 1e-4.
    #[serde(default)]
    pub tail_error_ratio: BTreeMap<String, f64>,
    /// Upper bound on each named fault's detection delay, s.
    #[serde(default)]
    pub detection_delay: BTreeMap<String, f64>,
    /// Every injected fault correctly isolated (for the scenario's `isolated_fraction` of its
    /// active time).
    pub correct_isolation: Option<bool>,
    /// Every injected fault's first isolation names its channel.
    pub first_isolation_correct: Option<bool>,
    /// Upper bound on the false-alarm episodes.
    pub false_alarms: Option<u64>,
}
