//! What a design gives: the observer with its report of conditions, or the refusal naming the
//! condition that failed; and the domain (continuous or sampled) a condition is checked in.

use lti::{C64, Mat};

use super::unknown_input::InputEstimator;
use crate::runtime::LinearObserver;

/// One existence condition, evaluated.
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// What is checked, as the paper writes it, e.g. "rank(CE) = rank(E)".
    pub name: String,
    /// Whether it holds.
    pub ok: bool,
    /// The values behind the verdict, e.g. "1 = 1".
    pub detail: String,
}

/// What a design computed: conditions, the paper's matrices, eigenvalues.
#[derive(Debug, Clone)]
pub struct Report {
    /// Scenario kind.
    pub kind: &'static str,
    /// Every condition evaluated, in order.
    pub conditions: Vec<Condition>,
    /// The continuous-time design matrices under the papers' names.
    pub matrices: Vec<(String, Mat)>,
    /// Continuous-time error-dynamics eigenvalues, sorted.
    pub poles: Vec<C64>,
    /// Eigenvalues of the sampled observer's F, sorted.
    pub discrete_poles: Vec<C64>,
    /// Modes no admissible gain can move (invariant zeros, unobservable modes).
    pub fixed_modes: Vec<C64>,
    /// Further facts worth showing (certificates, choices made).
    pub notes: Vec<String>,
    /// True when there is no continuous design (an LQE gain, a Kalman filter, a discrete-time
    /// plant): `poles` are then ln(z)/dt of the sampled ones, a deadbeat mode z = 0 left out.
    pub sampled_only: bool,
}

/// A finished design: its report and the sampled observer to run.
#[derive(Debug, Clone)]
pub struct Designed {
    /// The design report.
    pub report: Report,
    /// The sampled-data observer.
    pub runtime: LinearObserver,
    /// How the unknown inputs are reconstructed from its estimate (UIOs whose Γ_E the outputs
    /// see whole).
    pub what: Option<InputEstimator>,
}

impl Designed {
    /// The same design run on the plant's absolute signals at the operating point `op` (its
    /// model is the linearisation there, in deviations): the observer's offsets c_z, c_x
    /// ([`crate::runtime`]) and the input estimate's ([`InputEstimator::at_operating_point`]).
    pub fn at_operating_point(&mut self, op: &lti::OperatingPoint) {
        self.runtime.at_operating_point(op);
        if let Some(w) = &mut self.what {
            w.at_operating_point(op);
        }
    }
}

/// A condition that fails, with everything evaluated up to it.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{kind}: {condition} does not hold: {detail}")]
pub struct DesignError {
    /// Scenario kind.
    pub kind: &'static str,
    /// The failing condition's name.
    pub condition: String,
    /// Why.
    pub detail: String,
    /// All conditions evaluated, the failing one last.
    pub conditions: Vec<Condition>,
    /// The plant states (0-based) that carry a mode no sensor sees, when that is the cause and
    /// the pair's state is the plant's: the largest entries of its eigenvector, largest first.
    /// The detail names them x1, x2, …; the launcher adds the scenario's `state_names`.
    pub unseen_states: Vec<usize>,
}

/// Continuous or sampled: decides what "stable" means and how poles map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Domain {
    /// s-plane: stable means Re s < 0.
    Continuous,
    /// z-plane with period dt: stable means |z| < 1.
    Discrete(f64),
}

impl Domain {
    /// Whether an eigenvalue is asymptotically stable here, with a margin for rounding: a mode
    /// computed as −1e−17 is marginal (an integrator), not stable.
    pub fn stable(self, z: C64) -> bool {
        match self {
            Domain::Continuous => z.re < -1e-10 * z.norm().max(1.0),
            Domain::Discrete(_) => z.norm() < 1.0 - 1e-13,
        }
    }
}
