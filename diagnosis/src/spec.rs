//! A `[[diagnoser]]` as validated from the scenario.

use lti::Poles;
use lti::place::Method;

/// Which channels the bank watches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channels {
    /// The known inputs u_i (columns of B).
    Actuator,
    /// The outputs y_j.
    Sensor,
    /// The columns of the plant's fault distribution F_f.
    Component,
}

impl Channels {
    /// The scenario's word.
    pub fn name(self) -> &'static str {
        match self {
            Channels::Actuator => "actuator",
            Channels::Sensor => "sensor",
            Channels::Component => "component",
        }
    }
}

/// How members share the channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// Member i is blind to every channel but i (dedicated observer scheme, Clark 1978):
    /// residual i reacts to channel i alone.
    Dedicated,
    /// Member i is blind to channel i alone (generalized observer scheme, Frank 1987):
    /// residual i reacts to every channel but i.
    Generalized,
}

impl Scheme {
    /// The scenario's word.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Dedicated => "dedicated",
            Scheme::Generalized => "generalized",
        }
    }
}

/// The design every member of a bank uses.
#[derive(Debug, Clone, PartialEq)]
pub enum MemberKind {
    /// Chen & Patton's UIO with the member's unknown inputs (its blind channels and E).
    ChenPatton { poles: Poles, placement: Method },
    /// A Luenberger observer on the member's outputs (sensor banks).
    Luenberger { poles: Poles, placement: Method },
    /// The steady-state Kalman filter on the member's outputs (sensor banks, with noise).
    Kalman,
}

/// How a residual is turned into one number per step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Evaluation {
    /// ‖r_k‖₂.
    Norm,
    /// √(mean of ‖r‖² over the last `window` samples).
    Rms { window: usize },
    /// J_k = √(λ J²_{k−1} + (1 − λ)‖r_k‖²).
    Forgetting { lambda: f64 },
    /// r_kᵀ Σ_r⁻¹ r_k, χ²(p_i) for a fault-free stationary residual.
    Chi2,
}

/// The evaluation's threshold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Threshold {
    /// A given value.
    Fixed(f64),
    /// The χ²(p_i) quantile 1 − α: a fault-free sample exceeds it with probability α.
    FalseAlarm(f64),
    /// `margin` × the largest evaluation of `runs` fault-free realisations (set by the launcher
    /// before the run; see `launcher/src/calibrate.rs`).
    Calibrated { runs: usize, margin: f64 },
}

/// One `[[diagnoser]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoserSpec {
    /// Unique name.
    pub name: String,
    /// Dedicated or generalized.
    pub scheme: Scheme,
    /// What it watches.
    pub channels: Channels,
    /// The channels of its class it watches (0-based, ascending), when not all of them.
    pub subset: Option<Vec<usize>>,
    /// The members' design.
    pub member: MemberKind,
    /// The structure matrix asked for (rows: residuals, columns: channels), if given.
    pub structure: Option<Vec<Vec<u8>>>,
    /// Residual evaluation.
    pub evaluation: Evaluation,
    /// Threshold.
    pub threshold: Threshold,
    /// Consecutive exceedances before an alarm.
    pub persistence: u32,
    /// No decision before this time, s (the observers' start-up transient).
    pub ignore_before: f64,
    /// A windowed GLR test beside the evaluation ([`crate::glr`]), if asked for.
    pub glr: Option<GlrSpec>,
}

/// What a `glr = { window, false_alarm }` asks for ([`crate::glr`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlrSpec {
    /// How long an onset is tried for, s (N = round(window/dt) samples).
    pub window: f64,
    /// The bound on the false-alarm probability per sample, α.
    pub false_alarm: f64,
}
