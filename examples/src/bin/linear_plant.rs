//! The built-in exact linear plant rebuilt from the protocol's configuration alone (`model` and
//! `signals`, not the launcher's private `params`): run in its place, it gives a recording equal
//! to the built-in plant's bit for bit — the proof that the protocol carries everything a plant
//! needs.

use examples::{DesignModel, Signals};
use lockstep::component::{self, Component, ComponentConfig, Inputs, StepError};
use plant::{Plant, PlantConfig};

struct LinearPlant {
    plant: Plant,
    controller: Option<usize>,
    u: Vec<f64>,
}

impl Component for LinearPlant {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        let (m, s) = (DesignModel::of(cfg)?, Signals::of(cfg)?);
        let pc = PlantConfig {
            a: (&m.a).into(),
            b: (&m.b).into(),
            c: (&m.c).into(),
            e: (&m.e).into(),
            d: (&m.d).into(),
            x0: m.x0.clone(),
            disturbances: s.disturbances,
            measurement_disturbances: s.measurement_disturbances,
            inputs: s.inputs,
            dt: cfg.dt,
            steps: cfg.steps,
            state_bound: s.state_bound,
        };
        let plant = Plant::new(&pc)?;
        Ok(LinearPlant { plant, controller: cfg.read_index("controller"), u: vec![0.0; m.b.ncols()] })
    }

    fn step(&mut self, k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        if k > 0 {
            match self.controller {
                Some(i) => self.u.copy_from_slice(inputs.get(i)),
                None => self.u.copy_from_slice(self.plant.reference()),
            }
            self.plant.advance(k - 1, &self.u).map_err(|d| StepError { code: plant::shell::EXIT_DIVERGED, message: format!("diverged: {d}") })?;
        }
        out.copy_from_slice(self.plant.sample(k));
        Ok(())
    }
}

fn main() -> std::process::ExitCode {
    component::main::<LinearPlant>("linear_plant")
}
