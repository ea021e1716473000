//! Observer designs, one file per family, each with the paper's continuous-time form (for the
//! design report and the printed numbers) and its sampled-data counterpart (what the observer
//! process runs).
//!
//! Every design is computed by one function of the model matrices, called twice: on (A, B, E)
//! with the requested poles p, and on the exact sampling (A_d, B_d, E_d) with poles e^{p·dt}.
//! Decoupling conditions such as TE = 0 then hold for the sampled plant exactly, so a
//! piecewise-constant unknown input leaves no error at the samples; a merely discretised
//! continuous observer would leave one of order dt.
//!
//! All sampled designs reduce to one runtime form ([`LinearObserver`]):
//! z_{k+1} = F z_k + G u_k + K y_k, x̂_k = P z_k + Q y_k.

mod checks;
mod chen_patton;
mod cumming;
mod das_ghosal;
mod gain;
mod gi_full_order;
mod hui_zak;
mod kalman;
mod luenberger;
mod report;
mod unknown_input;

use lti::place::Method;
use lti::{Discrete, Mat, Model};

pub use crate::lmi::LmiSolution;
pub(crate) use checks::{
    Checks, eig, eq_detail, place_detectable, refuse_unseen, require_stable, sampled_report,
};
pub use gain::{Gain, Weights};
pub(crate) use gain::{Pair, free_gain};
pub use hui_zak::{Path, lmi_available};
pub use report::{Condition, DesignError, Designed, Domain, Report};
pub use unknown_input::InputEstimator;

/// Which observer, with its free parameters.
#[derive(Debug, Clone, PartialEq)]
pub enum Spec {
    /// Full-order Luenberger observer: x̂˙ = Ax̂ + Bu + L(y − Cx̂).
    Luenberger { gain: Gain },
    /// Chen & Patton's unknown-input decoupling observer (seed 002).
    ChenPatton { gain: Gain },
    /// Das & Ghosal reduced-order observer (seed 003).
    DasGhosal { gain: Gain },
    /// Das & Ghosal reduced-order unknown-input observer (seed 000): either H given, or a gain
    /// for its free matrix.
    DasGhosalUio { h: Option<Mat>, gain: Option<Gain> },
    /// Full-order observer by the generalized inverse (seed 001).
    GiFullOrder { gain: Gain },
    /// Cumming's reduced-order observer (seed 003); H completes C to an invertible [C; H].
    Cumming { gain: Gain, h: Option<Mat> },
    /// Hui & Żak's projection unknown-input observer (seed 004). Without a gain the free poles
    /// default from the fixed modes and are placed with `placement`.
    HuiZak {
        decay: f64,
        gain: Option<Gain>,
        placement: Method,
        path: Path,
    },
    /// The steady-state Kalman filter of the sampled plant for process-noise covariance Q_d
    /// (per step, n×n) and measurement-noise covariance R (p×p).
    Kalman { qd: Mat, r: Mat },
}

impl Spec {
    /// The scenario name of this kind.
    pub fn kind(&self) -> &'static str {
        match self {
            Spec::Luenberger { .. } => "luenberger",
            Spec::ChenPatton { .. } => "chen-patton-uio",
            Spec::DasGhosal { .. } => "das-ghosal",
            Spec::DasGhosalUio { .. } => "das-ghosal-uio",
            Spec::GiFullOrder { .. } => "gi-full-order",
            Spec::Cumming { .. } => "cumming",
            Spec::HuiZak { .. } => "hui-zak-uio",
            Spec::Kalman { .. } => "kalman",
        }
    }

    /// True for designs that reject the unknown inputs.
    pub fn decouples(&self) -> bool {
        matches!(
            self,
            Spec::ChenPatton { .. } | Spec::DasGhosalUio { .. } | Spec::HuiZak { .. }
        )
    }
}

/// Designs the observer for the continuous-time `model`, sampled with period `dt`.
pub fn design(model: &Model, spec: &Spec, dt: f64) -> Result<Designed, DesignError> {
    design_on(Some(model), &model.discretize(dt), spec)
}

/// Designs the observer for a discrete-time plant x⁺ = Φx + Γ_Bu + Γ_Ew given per step (an
/// identified model): the sampled design alone, its poles mapped e^{p·dt} when placed.
pub fn design_discrete(dm: &Discrete, spec: &Spec) -> Result<Designed, DesignError> {
    design_on(None, dm, spec)
}

/// The family's design from the continuous model (if there is one) and the sampled one; an
/// unknown-input observer also gets its unknown-input estimator where the outputs see Γ_E whole.
fn design_on(model: Option<&Model>, dm: &Discrete, spec: &Spec) -> Result<Designed, DesignError> {
    let mut d = match spec {
        Spec::Luenberger { gain } => luenberger::design(model, dm, gain),
        Spec::ChenPatton { gain } => chen_patton::design(model, dm, gain),
        Spec::DasGhosal { gain } => {
            das_ghosal::design(model, dm, das_ghosal::Free::Gain(gain.clone()), false)
        }
        Spec::DasGhosalUio { h, gain } => {
            let free = match (h, gain) {
                (Some(h), _) => das_ghosal::Free::H(h.clone()),
                (None, Some(g)) => das_ghosal::Free::Gain(g.clone()),
                (None, None) => {
                    return Err(Checks::new("das-ghosal-uio").error(
                        "H or poles",
                        "give H = [[…]], poles = […] or gain = \"lqe\"",
                    ));
                }
            };
            das_ghosal::design(model, dm, free, true)
        }
        Spec::GiFullOrder { gain } => gi_full_order::design(model, dm, gain),
        Spec::Cumming { gain, h } => cumming::design(model, dm, gain, h.as_ref()),
        Spec::HuiZak {
            decay,
            gain,
            placement,
            path,
        } => hui_zak::design(model, dm, *decay, gain.as_ref(), *placement, *path),
        Spec::Kalman { qd, r } => kalman::design(dm, qd, r),
    }?;
    if spec.decouples() {
        d.what = unknown_input::estimator(dm, matches!(spec, Spec::HuiZak { .. }));
    }
    Ok(d)
}
