//! The built-in observer as a component of the kit (`lockstep::component`): the sampled
//! [`LinearObserver`]s of its designs, arriving as the component's `params` ([`ObserverRun`]).
//!
//! One observer, or a whole diagnosis bank: a bank's members all read the same plant sample, so
//! one process steps them all and publishes their estimates side by side (member i's x̂ at
//! values i·n … (i+1)·n). A bank then costs one subscriber of the plant's samples and one
//! process, whatever its size, instead of one of each per member.

use lockstep::PlantLayout;
use lockstep::component::{Component, ComponentConfig, Inputs, StepError};
use serde::{Deserialize, Serialize};

use crate::{LinearObserver, ObserverState};

/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = lockstep::component::EXIT_FAILED;

/// What the launcher gives an observer process as `params`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObserverRun {
    /// The sampled observers it runs (one, or every member of a bank), in publishing order.
    pub observers: Vec<LinearObserver>,
    /// Where y and u_{k−1} sit in the plant's samples.
    pub layout: PlantLayout,
}

/// Observers: each x̂_k from y_k and u_{k−1} of the plant's sample k.
pub struct ObserverComponent {
    obs: Vec<ObserverState>,
    layout: PlantLayout,
}

impl Component for ObserverComponent {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        let run: ObserverRun = cfg.params()?;
        if run.observers.is_empty() {
            return Err("params: no observer to run".into());
        }
        for o in &run.observers {
            o.check()?;
            if o.states() != run.layout.n {
                return Err(format!(
                    "params: an observer estimates {} states, the plant has {}",
                    o.states(),
                    run.layout.n
                ));
            }
        }
        Ok(ObserverComponent {
            obs: run
                .observers
                .iter()
                .map(LinearObserver::instantiate)
                .collect(),
            layout: run.layout,
        })
    }

    fn step(&mut self, _k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        let (s, lay) = (inputs.get(0), self.layout);
        for (o, x) in self.obs.iter_mut().zip(out.chunks_exact_mut(lay.n)) {
            x.copy_from_slice(o.step(&s[lay.y()], &s[lay.u_prev()]));
        }
        Ok(())
    }
}
