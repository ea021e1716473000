//! The Hui–Żak LMI (seed 004): its solution, always; the solver (Clarabel, [`solver`]) only in a
//! build with the feature `lmi`.

use lti::Mat;

#[cfg(feature = "lmi")]
mod solver;
#[cfg(feature = "lmi")]
pub use solver::solve;

/// The LMI's solution.
#[derive(Debug, Clone)]
pub struct LmiSolution {
    /// P = Pᵀ ⪰ 0.01 I.
    pub p: Mat,
    /// Y with YD = 0.
    pub y: Mat,
}
