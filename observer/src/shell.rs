//! The built-in observer as a component of the kit (`lockstep::component`): the sampled
//! [`LinearObserver`] of its design, arriving as the component's `params` ([`ObserverRun`]).

use lockstep::component::{Component, ComponentConfig, Inputs, StepError};
use lockstep::PlantLayout;
use serde::{Deserialize, Serialize};

use crate::{LinearObserver, ObserverState};

/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = lockstep::component::EXIT_FAILED;

/// What the launcher gives an observer as `params`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObserverRun {
    /// The sampled observer.
    pub observer: LinearObserver,
    /// Where y and u_{k−1} sit in the plant's samples.
    pub layout: PlantLayout,
}

/// An observer: x̂_k from y_k and u_{k−1} of the plant's sample k.
pub struct ObserverComponent {
    obs: ObserverState,
    layout: PlantLayout,
}

impl Component for ObserverComponent {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        let run: ObserverRun = cfg.params()?;
        run.observer.check()?;
        Ok(ObserverComponent { obs: run.observer.instantiate(), layout: run.layout })
    }

    fn step(&mut self, _k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        let (s, lay) = (inputs.get(0), self.layout);
        out.copy_from_slice(self.obs.step(&s[lay.y()], &s[lay.u_prev()]));
        Ok(())
    }
}
