//! The built-in controller as a component of the kit (`lockstep::component`): state feedback
//! with its designed G and N, arriving as the component's `params` ([`ControllerConfig`]).

use lockstep::component::{Component, ComponentConfig, Inputs, StepError};

use crate::{Controller, ControllerConfig};

/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = lockstep::component::EXIT_FAILED;

/// The controller: u_k = N r_k − G x̂_k from its observer's x̂_k.
pub struct ControllerComponent {
    ctrl: Controller,
}

impl Component for ControllerComponent {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        Ok(ControllerComponent {
            ctrl: Controller::new(&cfg.params::<ControllerConfig>()?)?,
        })
    }

    fn step(&mut self, k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        // Its observer's x̂_k, and with feedforward the plant's sample k (the second read).
        let plant = if self.ctrl.reads_plant() {
            inputs.get(1)
        } else {
            &[]
        };
        out.copy_from_slice(self.ctrl.step(k, inputs.get(0), plant));
        Ok(())
    }
}
