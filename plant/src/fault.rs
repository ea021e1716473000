//! Injected faults: what they are (the scenario's `[[fault]]`, as the plant receives it) and how
//! they act on the plant.
//!
//! Faults switch on and off at samples (the scenario refuses a time between samples), so over
//! each step t_k … t_{k+1} a fault is either active throughout or not at all, and its
//! magnitude is φ(t_k + τ) = φ_k + s_k τ: constant (step, intermittent) or a ramp. Actuator and
//! component faults are inputs of the continuous plant, integrated exactly over the step:
//!
//! ```text
//! additive on u_i or through F_f,j (column f):  x_{k+1} += Γ₀ φ_k + Γ₁ s_k,
//! [Φ  Γ₀  Γ₁] = top rows of exp([[A, f, 0], [0, 0, 1], [0, 0, 0]]·dt)
//! stuck u_i:  u_i ← value over the step,      loss of gain on u_i:  u_i ← (1 − value)·u_i,
//! ```
//!
//! (the observers are still told the commanded u: the fault is theirs to find). Sensor faults act
//! at the sample: bias and drift add φ(t_k) to y_j, stuck sets y_j = value, a noise burst adds
//! value·N(0, 1) from its own seeded stream.

use serde::{Deserialize, Serialize};

/// Where a fault acts (0-based indices: messages and scenarios number from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// Known input u_i (column i of B).
    Actuator(usize),
    /// Output y_j.
    Sensor(usize),
    /// Column j of the plant's fault distribution matrix F_f.
    Component(usize),
}

/// What a fault does to its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// φ(t) added (actuator, component).
    Additive,
    /// The target held at `value` (actuator, sensor).
    Stuck,
    /// A fraction `value` of the actuator's gain lost.
    Gain,
    /// φ(t) added to a sensor.
    Bias,
    /// φ(t) = value·(t − start) added to a sensor (a bias with a ramp profile).
    Drift,
    /// Gaussian noise of standard deviation `value` added to a sensor.
    Noise,
}

/// When a fault acts and how its magnitude evolves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Profile {
    /// φ = value from `start` (until `end`, if given).
    Step { start: f64, end: Option<f64> },
    /// φ = value·(t − start) from `start` (until `end`).
    Ramp { start: f64, end: Option<f64> },
    /// φ = value during each [on, off) interval.
    Intermittent { intervals: Vec<[f64; 2]> },
}

impl Profile {
    /// When the fault first acts.
    pub fn start(&self) -> f64 {
        match self {
            Profile::Step { start, .. } | Profile::Ramp { start, .. } => *start,
            Profile::Intermittent { intervals } => {
                intervals.first().map_or(f64::INFINITY, |i| i[0])
            }
        }
    }

    /// Every [on, off) interval (off = +∞ for no end).
    pub fn intervals(&self) -> Vec<[f64; 2]> {
        match self {
            Profile::Step { start, end } | Profile::Ramp { start, end } => {
                vec![[*start, end.unwrap_or(f64::INFINITY)]]
            }
            Profile::Intermittent { intervals } => intervals.clone(),
        }
    }
}

/// One `[[fault]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fault {
    /// Unique name (recorded under `/fault/<name>`).
    pub name: String,
    /// Where it acts.
    pub target: Target,
    /// What it does.
    pub kind: Kind,
    /// Its magnitude (or slope for a ramp, stuck value, fraction of gain lost, noise σ).
    pub value: f64,
    /// When.
    pub profile: Profile,
}

impl Fault {
    /// Whether it acts through a state-equation column (integrated over the step).
    pub fn through_state(&self) -> bool {
        matches!(
            (self.target, self.kind),
            (Target::Actuator(_), Kind::Additive) | (Target::Component(_), _)
        )
    }
}

impl Fault {
    /// The [k_on, k_off) steps it acts in, on the grid of dt (k_off = u64::MAX for no end).
    pub fn active_steps(&self, dt: f64) -> Vec<(u64, u64)> {
        let sample_of = |t: f64| lti::signal::first_sample_from(t, dt);
        self.profile
            .intervals()
            .iter()
            .map(|i| (sample_of(i[0]), sample_of(i[1])))
            .collect()
    }
}

/// A fault on the sample grid: its active steps and magnitude per step.
#[derive(Debug, Clone)]
pub(crate) struct Scheduled {
    pub fault: Fault,
    /// [k_on, k_off) per interval.
    steps: Vec<(u64, u64)>,
    /// The first step of the ramp (for φ = value·(k − k₀)·dt).
    k0: u64,
    ramp: bool,
}

impl Scheduled {
    pub fn new(fault: &Fault, dt: f64) -> Self {
        // Validation puts every time on a sample (a time between would take effect at the next).
        let sample_of = |t: f64| lti::signal::first_sample_from(t, dt);
        let steps = fault.active_steps(dt);
        let ramp = matches!(fault.profile, Profile::Ramp { .. }) || fault.kind == Kind::Drift;
        Scheduled {
            fault: fault.clone(),
            steps,
            k0: sample_of(fault.profile.start()),
            ramp,
        }
    }

    /// Whether the fault acts over step k (from t_k on).
    pub fn active(&self, k: u64) -> bool {
        self.steps.iter().any(|&(on, off)| k >= on && k < off)
    }

    /// (φ_k, s_k): the magnitude at t_k and its slope over the step (zero when inactive).
    pub fn magnitude(&self, k: u64, dt: f64) -> (f64, f64) {
        if !self.active(k) {
            return (0.0, 0.0);
        }
        if self.ramp {
            (
                self.fault.value * ((k - self.k0) as f64 * dt),
                self.fault.value,
            )
        } else {
            (self.fault.value, 0.0)
        }
    }
}
