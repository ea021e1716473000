//! The observer component: designs (pure math), the sampled-data step function, and the thin
//! process shell that runs it in lockstep with the plant.

pub mod design;
mod lmi;
pub mod runtime;
pub mod shell;

pub use design::{DesignError, Designed, Report, Spec, design};
pub use runtime::{LinearObserver, ObserverState};
