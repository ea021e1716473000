//! The plant process: reads its configuration, joins the run's bus, and steps in lockstep.

use lockstep::{now_ns, ready_then_wait_for_go, Bus, Launch, LockstepError};

use crate::{Plant, PlantRun};

/// Exit code when a state diverged.
pub const EXIT_DIVERGED: i32 = 4;
/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = 3;

/// Why the plant process stopped early.
#[derive(Debug, thiserror::Error)]
pub enum ShellError {
    /// Transport failure.
    #[error(transparent)]
    Bus(#[from] LockstepError),
    /// Bad configuration.
    #[error("configuration: {0}")]
    Config(String),
    /// A state diverged.
    #[error("diverged: {0}")]
    Diverged(crate::Divergence),
}

impl ShellError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            ShellError::Diverged(_) => EXIT_DIVERGED,
            _ => EXIT_FAILED,
        }
    }
}

/// Runs the plant for a launched run.
pub fn run(launch: &Launch) -> Result<(), ShellError> {
    let cfg: PlantRun = serde_json::from_str(&launch.run.read_config("plant")?).map_err(|e| ShellError::Config(e.to_string()))?;
    let mut plant = Plant::new(&cfg.plant).map_err(ShellError::Config)?;
    let bus = Bus::join(&launch.run, "plant", launch.wait)?;
    let outlet = bus.outlet("plant")?;
    let observers = cfg.observers.iter().map(|o| bus.inlet(&format!("observer/{o}"))).collect::<Result<Vec<_>, _>>()?;
    let controller = if cfg.controller { Some(bus.inlet("controller")?) } else { None };
    let lay = plant.layout();
    let mut xhat = vec![0.0; lay.n];
    let mut u = vec![0.0; lay.l];
    ready_then_wait_for_go()?;

    let mut taken_ns = 0;
    for k in 0..cfg.plant.steps {
        let t = plant.time(k);
        outlet.send(k, t, taken_ns, plant.sample(k))?;
        for inlet in &observers {
            taken_ns = inlet.wait_step(k, &mut xhat)?.received_ns;
        }
        match &controller {
            Some(inlet) => taken_ns = inlet.wait_step(k, &mut u)?.received_ns,
            None => {
                u.copy_from_slice(plant.reference());
                if observers.is_empty() {
                    taken_ns = now_ns();
                }
            }
        }
        plant.advance(k, &u).map_err(ShellError::Diverged)?;
    }
    Ok(())
}
