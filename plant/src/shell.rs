//! The built-in plant as a component of the kit (`lockstep::component`): the exact linear plant
//! of [`crate::Plant`], built from the protocol's public fields alone
//! ([`PlantConfig::from_protocol`]), as an external plant would be.

use lockstep::component::{Component, ComponentConfig, Inputs, StepError};

use crate::{Plant, PlantConfig};

/// Exit code when a state diverged.
pub const EXIT_DIVERGED: i32 = 4;
/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = lockstep::component::EXIT_FAILED;

/// The plant: u_{k−1} from the controller's input (or the reference signals without one)
/// advances x_{k−1} to x_k, and sample k is published.
pub struct PlantComponent {
    plant: Plant,
    controller: Option<usize>,
    u: Vec<f64>,
}

impl Component for PlantComponent {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        let pc = PlantConfig::from_protocol(cfg)?;
        let plant = Plant::new(&pc)?;
        let l = plant.layout().l;
        Ok(PlantComponent {
            plant,
            controller: cfg.read_index("controller"),
            u: vec![0.0; l],
        })
    }

    fn step(&mut self, k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        if k > 0 {
            match self.controller {
                Some(i) => self.u.copy_from_slice(inputs.get(i)),
                None => self.u.copy_from_slice(self.plant.reference()),
            }
            self.plant.advance(k - 1, &self.u).map_err(|d| StepError {
                code: EXIT_DIVERGED,
                message: format!("diverged: {d}"),
            })?;
        }
        out.copy_from_slice(self.plant.sample(k));
        Ok(())
    }
}
