//! Linear time-invariant system math for observer design: no I/O, no allocation-sensitive
//! code paths — the design-time half of the toolkit.
//!
//! * [`pinv`], [`subspace`], [`householder`], [`eig`] — the numerical core;
//! * [`staircase`] — controllable / observable splits, controllability and observability matrices;
//! * [`zeros`] — invariant zeros that decide whether an unknown-input observer exists;
//! * [`unseen`] — the modes no sensor sees (PBH at the eigenvalues that matter), and the states
//!   that carry them;
//! * [`lyapunov`] — continuous and discrete Lyapunov equations (decay-rate certificates);
//! * [`dare`] — the discrete algebraic Riccati equation (structure-preserving doubling) and the
//!   steady-state Kalman filter;
//! * [`place`] — eigenvalue assignment (Tits–Yang, KNV0, MATLAB-compatible, Ackermann);
//! * [`model`], [`discretize`], [`expm`] — the plant model, its exact zero-order-hold sampling and
//!   the matrix exponential behind it;
//! * [`van_loan`] — the discrete covariance of continuous white process noise over a step;
//! * [`signal`] — the known-input and disturbance signals of a scenario;
//! * [`input_estimate`] — the unknown input ŵ, one sample late, from an observer's estimate.

pub mod dare;
pub(crate) mod dd;
pub mod discretize;
pub mod eig;
pub mod error;
pub mod expm;
pub mod freq;
pub mod householder;
pub mod input_estimate;
pub mod kernel;
pub mod linalg;
pub mod lyapunov;
pub mod model;
pub mod operating_point;
pub mod pinv;
pub mod place;
pub mod poles;
pub mod sampled;
pub mod signal;
pub mod staircase;
pub mod subspace;
pub mod units;
pub mod unseen;
pub mod van_loan;
pub mod zeros;

pub use dare::{Dare, Kalman, solve_dare, steady_state_kalman};
pub use eig::C64;
pub use error::{LtiError, Result};
pub use model::{Discrete, MatData, Model};
pub use nalgebra::DMatrix;
pub use operating_point::OperatingPoint;
pub use poles::{PoleSpec, Poles, re_im};
pub use van_loan::{discrete_noise_covariance, process_noise_covariance};

/// A real matrix.
pub type Mat = nalgebra::DMatrix<f64>;
