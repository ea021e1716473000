//! Fault diagnosis with banks of observers (Chen & Patton, "Robust Model-Based Fault Diagnosis
//! for Dynamic Systems", 1999, ch. 3; Frank 1990): pure math, no I/O.
//!
//! * [`spec`] — what a `[[diagnoser]]` asks for: scheme, channels, member design, evaluation,
//!   threshold, decision;
//! * [`bank`] — the members' models and designs (each one a [`observer::LinearObserver`]), and
//!   the bank's structure matrix computed from them ([`structure`]);
//! * [`residual`] — a member's residual in terms of its observer's state and the measurement;
//! * [`covariance`] — the stationary covariance of a member's residual under the noise;
//! * [`evaluate`] — residual evaluation signals and thresholds;
//! * [`glr`] — a windowed GLR test on the residual whitened in time, for faults that persist;
//! * [`decide`] — alarms and isolation per step ([`Monitor`]);
//! * [`figures`] — detection times, isolation, false alarms of a run.

pub mod bank;
pub mod covariance;
pub mod decide;
pub mod evaluate;
pub mod figures;
pub mod freq;
pub mod glr;
pub mod residual;
pub mod spec;
pub mod structure;

pub use bank::BankError;
pub use bank::{Bank, Member, design_bank};
pub use decide::{DecidedBy, Isolation, Monitor};
pub use figures::{Diagnosis, FaultFigure, FaultInfo, IsolatedBy, Judge, ResidualFigure};
pub use spec::{Channels, DiagnoserSpec, Evaluation, GlrSpec, MemberKind, Scheme, Threshold};
