//! The checked scenario the launcher runs, and the one-line error a scenario that is not one
//! gets (file, line:column, field, reason).

use std::fmt;
use std::path::PathBuf;

use controller::design::FeedbackSpec;
use lti::signal::Signal;
use lti::{Mat, Model};
use observer::Spec;

use crate::locate;
use crate::{NoiseSpec, RawExpect, Remote};

/// A scenario that passed every check.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Components that run on other hosts (`[hosts]`, `host = …`), by component name.
    pub remote: std::collections::BTreeMap<String, Remote>,
    /// The file it came from.
    pub path: PathBuf,
    /// Its name (also the recording's file name).
    pub name: String,
    /// One line.
    pub description: String,
    /// Sample period, s.
    pub dt: f64,
    /// Length, s.
    pub duration: f64,
    /// Number of steps, round(duration / dt).
    pub steps: u64,
    /// The plant: continuous (A, B, C, E, D), or with `discrete` its per-step (Φ, Γ_B, C, Γ_E, D).
    pub model: Model,
    /// `[plant] time = "discrete"`: `model`'s A, B and E are Φ, Γ_B and Γ_E of one step of dt.
    pub discrete: bool,
    /// Initial state (absolute, like every signal of the plant).
    pub x0: Vec<f64>,
    /// `[plant.operating_point]`: the model is the linearisation there, in deviations; the
    /// observers and the controller add its offsets and exchange absolute signals.
    pub operating_point: Option<lti::OperatingPoint>,
    /// |x_i| beyond this stops the run.
    pub state_bound: f64,
    /// Names and units of every signal, for labels, titles and CSV headers.
    pub names: SignalNames,
    /// One per column of E.
    pub disturbances: Vec<Signal>,
    /// One per column of D.
    pub measurement_disturbances: Vec<Signal>,
    /// One per column of B.
    pub inputs: Vec<Signal>,
    /// The observers, in file order.
    pub observers: Vec<ObserverEntry>,
    /// The state feedback, if any.
    pub controller: Option<ControllerEntry>,
    /// Who simulates the true plant, when not the built-in exact linear plant.
    pub plant_process: Option<ProcessSpec>,
    /// `[plant.fmu]`: the FMU that simulates the true plant (absolute path); `plant_process` is
    /// then the component that runs it ([`FMU_PLANT_PROGRAM`]).
    pub plant_fmu: Option<PathBuf>,
    /// `[plant.replay]`: the recorded data replayed as the true plant (absolute path);
    /// `plant_process` is then the component that replays it ([`REPLAY_PLANT_PROGRAM`]).
    pub plant_replay: Option<PathBuf>,
    /// What the run must achieve.
    pub expect: RawExpect,
    /// The file's text (to locate fields in later messages).
    pub source: String,
    /// The noise generator's seed.
    pub seed: u64,
    /// Process and measurement noise, if any.
    pub noise: Option<NoiseSpec>,
    /// Fault distribution F_f, n×m (m may be 0).
    pub ff: Mat,
    /// Injected faults.
    pub faults: Vec<plant::Fault>,
    /// The share of a fault's active time it must be isolated correctly for to count as
    /// isolated (`isolated_fraction`, default 0.9).
    pub isolated_fraction: f64,
    /// How long a component that is running or runnable may publish nothing before the run is
    /// stopped, s (`stall_timeout`, default [`limits::STALL_TIMEOUT`]; `--stall-timeout`).
    pub stall_timeout: f64,
    /// `tail`: the length of the stretch at the run's end over which the tail figures are taken,
    /// s (`None`: the last quarter of the steps; [`Scenario::tail_steps`]).
    pub tail: Option<f64>,
    /// `time_unit`: what a bare time meant in the file ("h"), and the unit its plots use.
    pub time_unit: Option<String>,
    /// Banks of residual generators.
    pub diagnosers: Vec<diagnosis::DiagnoserSpec>,
}

/// A name and a unit ("" when unknown) per component of each signal, in order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SignalNames {
    /// States x (default x1, x2, …).
    pub state: Vec<Named>,
    /// Outputs y (default y1, …).
    pub output: Vec<Named>,
    /// Known inputs r, columns of B (default r1, …).
    pub input: Vec<Named>,
    /// Unknown inputs w, columns of E (default w1, …).
    pub disturbance: Vec<Named>,
    /// Measurement disturbances v, columns of D (default v1, …).
    pub measurement_disturbance: Vec<Named>,
}

/// A signal component's name and unit.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Named {
    /// E.g. "eta", or the default "x3".
    pub name: String,
    /// E.g. "rad"; "" when not given.
    pub unit: String,
}

impl Named {
    /// "eta [rad]", or "eta" without a unit.
    pub fn with_unit(&self) -> String {
        if self.unit.is_empty() {
            self.name.clone()
        } else {
            format!("{} [{}]", self.name, self.unit)
        }
    }
}

/// An external component (PROTOCOL.md §7): a command run in the scenario file's folder, and
/// the parameters it receives as JSON.
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessSpec {
    /// Program and arguments.
    pub command: Vec<String>,
    /// The scenario's `params` table, as JSON (an empty object when there is none).
    pub params: serde_json::Value,
}

/// One `[[observer]]`.
#[derive(Debug, Clone)]
pub struct ObserverEntry {
    /// Unique name.
    pub name: String,
    /// The design (`None` for an external observer).
    pub spec: Option<Spec>,
    /// The external observer, for `kind = "process"`.
    pub process: Option<ProcessSpec>,
    /// (diagnoser, member), both 0-based, for a member of a `[[diagnoser]]` bank (designed with
    /// the bank; neither spec nor process).
    pub member: Option<(usize, usize)>,
    /// The initial estimate x̂₀ (`xhat0`, n values); `None`: the design's own start.
    pub xhat0: Option<Vec<f64>>,
}

impl ObserverEntry {
    /// Its kind as the scenario writes it ("bank-member" for a diagnoser's member).
    pub fn kind(&self) -> &'static str {
        match (&self.spec, self.member) {
            (Some(s), _) => s.kind(),
            (None, Some(_)) => "bank-member",
            (None, None) => "process",
        }
    }
}

/// The `[controller]`.
#[derive(Debug, Clone)]
pub struct ControllerEntry {
    /// Whose estimate it feeds back.
    pub observer: String,
    /// How G is obtained (`None` for an external controller).
    pub spec: Option<FeedbackSpec>,
    /// Tracked outputs z = C_t x (l×n): the prefilter (or the integrators) make them follow r.
    pub track: Option<Mat>,
    /// Integral action on the tracked outputs.
    pub integral: bool,
    /// Cancel the matched unknown input with the observer's ŵ (`feedforward = "what"`).
    pub feedforward: bool,
    /// The measured disturbances: inputs (0-based, ascending) it does not command; they keep
    /// their `[[input]]` signal (`controller::design::measured`).
    pub measured: Vec<usize>,
    /// The external controller, for `kind = "process"`.
    pub process: Option<ProcessSpec>,
}

/// A problem with a scenario file.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioError {
    /// The file.
    pub file: PathBuf,
    /// 1-based line and column, where known.
    pub at: Option<(usize, usize)>,
    /// The field, e.g. "plant.A".
    pub field: String,
    /// What is wrong.
    pub reason: String,
}

impl fmt::Display for ScenarioError {
    /// One line: the file name, the field path (which may hold a key from the file) and the
    /// reason (which may quote the file's text) have their control characters escaped.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use crate::untrusted::one_line;
        write!(f, "{}", one_line(&self.file.display().to_string()))?;
        if let Some((l, c)) = self.at {
            write!(f, ":{l}:{c}")?;
        }
        if self.field.is_empty() {
            write!(f, ": {}", one_line(&self.reason))
        } else {
            write!(f, ": {}: {}", one_line(&self.field), one_line(&self.reason))
        }
    }
}

impl std::error::Error for ScenarioError {}

/// A [`ScenarioError`] for `field` of a validated scenario, located in its text.
pub fn locate_error(s: &Scenario, field: &str, reason: String) -> ScenarioError {
    let at = locate::offset(&s.source, &locate::parse_path(field))
        .map(|o| locate::line_col(&s.source, o));
    ScenarioError {
        file: s.path.clone(),
        at,
        field: field.to_string(),
        reason,
    }
}
