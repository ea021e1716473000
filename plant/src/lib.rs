//! The plant component: an exact sampled-data integrator of ẋ = Ax + Bu + Ew, y = Cx + Dv
//! ([`Plant`], a pure step function) and the process shell that runs it in lockstep.

mod config;
pub mod fault;
pub mod noise;
mod plant;
pub mod sensing;
pub mod shell;

pub use config::PlantConfig;
pub use fault::Fault;
pub use noise::Noise;
pub use plant::{Divergence, Plant};
pub use sensing::Sensing;
