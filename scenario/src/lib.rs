//! Scenario files: parsing, validation, and the validated [`Scenario`] the launcher runs.
//!
//! Every problem is reported as one [`ScenarioError`]: file, line:column where known, the field
//! (as a path such as `plant.A` or `observer[1].poles`), and the reason.

mod check;
mod checked;
mod fault_diagnosis;
mod fmu_plant;
mod glr;
mod hosts;
pub mod limits;
pub mod linearized;
mod plant_file;
pub use observer_processes::{ObserverProcess, observer_processes};
mod locate;
pub mod matrix_file;
mod observer_processes;
mod operating_point;
mod raw;
mod replay_plant;
pub mod suggest;
pub mod untrusted;
mod validate;

use std::path::Path;

pub use checked::{
    ControllerEntry, Named, ObserverEntry, ProcessSpec, Scenario, ScenarioError, SignalNames,
    locate_error,
};
pub use fault_diagnosis::NoiseSpec;
pub use fmu_plant::FMU_PLANT_PROGRAM;
pub use hosts::Remote;
pub use raw::RawExpect;
pub use replay_plant::{REPLAY_PLANT_PROGRAM, replay_has_states};
pub use untrusted::{MAX_SCENARIO_BYTES, quoted};
impl Scenario {
    /// The observer on the lockstep ring across processes, the one the plant waits for each
    /// step: the controller's, in open loop the first. Every other trails the plant in batches
    /// (a follower, PROTOCOL.md §5).
    pub fn ring_observer(&self) -> Option<&str> {
        match &self.controller {
            Some(c) => Some(c.observer.as_str()),
            None => self.observers.first().map(|o| o.name.as_str()),
        }
    }

    /// The tail's length in steps, where `tail` is set: round(tail / duration · steps), at least
    /// one (so a run whose dt a sweep changed keeps the tail's seconds). `None`: the default,
    /// the last quarter of the steps completed.
    pub fn tail_steps(&self) -> Option<u64> {
        let t = self.tail?;
        let share = if self.duration > 0.0 {
            t / self.duration
        } else {
            1.0
        };
        Some(((share * self.steps as f64).round() as u64).clamp(1, self.steps.max(1)))
    }

    /// The observer processes of a run across processes: each the indices of the observers it
    /// steps ([`observer_processes`]).
    pub fn observer_processes(&self) -> Vec<ObserverProcess> {
        observer_processes(&self.observers, &self.remote)
    }

    /// The plant over one step of dt: the exact zero-order-hold sampling of a continuous plant,
    /// or a discrete plant's own Φ, Γ_B, Γ_E.
    pub fn sampled_model(&self) -> lti::Discrete {
        if self.discrete {
            let m = &self.model;
            lti::Discrete {
                a: m.a.clone(),
                b: m.b.clone(),
                c: m.c.clone(),
                e: m.e.clone(),
                d: m.d.clone(),
                dt: self.dt,
            }
        } else {
            self.model.discretize(self.dt)
        }
    }

    /// Reads and validates a scenario file: a regular file of at most [`MAX_SCENARIO_BYTES`].
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let text =
            untrusted::read_bounded(path, MAX_SCENARIO_BYTES).map_err(|reason| ScenarioError {
                file: path.to_path_buf(),
                at: None,
                field: String::new(),
                reason,
            })?;
        Self::parse(path, &text)
    }

    /// Validates scenario text (`path` is used in messages).
    pub fn parse(path: &Path, text: &str) -> Result<Scenario, ScenarioError> {
        validate::parse(path, text, true)
    }

    /// Validates the scenario text a recording holds, away from its folder: the files of
    /// `[plant.fmu]` and `[plant.replay]` are named, not read (the run read them), so that a
    /// recording's names and units survive its scenario's files.
    pub fn parse_recorded(text: &str) -> Result<Scenario, ScenarioError> {
        validate::parse(Path::new("<recording>"), text, false)
    }

    /// Names of the observers, in order.
    pub fn observer_names(&self) -> Vec<&str> {
        self.observers.iter().map(|o| o.name.as_str()).collect()
    }
}
