//! Errors of the math library: each names the condition that failed.

use thiserror::Error;

/// Why a computation in this crate could not produce a result.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LtiError {
    /// Two operands do not conform.
    #[error("dimension mismatch: {0}")]
    Dimension(String),
    /// An iterative decomposition did not converge.
    #[error("{0} did not converge")]
    NoConvergence(&'static str),
    /// A matrix that must be invertible is (numerically) singular.
    #[error("{0} is singular")]
    Singular(&'static str),
    /// An argument is out of its domain (non-finite, not symmetric, not definite).
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// A Riccati equation has no stabilising solution; the message names the cause.
    #[error("no stabilising solution: {0}")]
    NoStabilisingSolution(String),
    /// The requested pole set is not valid for this problem.
    #[error("invalid poles: {0}")]
    InvalidPoles(String),
    /// The pair is not controllable (or, for observers, not observable).
    #[error("{what} is not {property}: uncontrollable/unobservable modes {modes}")]
    NotAssignable {
        /// The pair, e.g. "(A, B)" or "(TA, C)".
        what: String,
        /// "controllable" or "observable".
        property: &'static str,
        /// The fixed modes, formatted.
        modes: String,
    },
    /// The placement finished but the achieved eigenvalues are off.
    #[error(
        "placement missed: requested {requested}, achieved {achieved} (max error {error:.3e}; {how})"
    )]
    PlacementMissed {
        /// Requested eigenvalues, formatted.
        requested: String,
        /// Achieved eigenvalues, formatted.
        achieved: String,
        /// Largest relative distance between matched pairs.
        error: f64,
        /// How ill-conditioned the placement was: the gain's size, κ of the eigenvectors.
        how: String,
    },
}

/// Result alias for this crate.
pub type Result<T> = std::result::Result<T, LtiError>;
