//! The observer process: waits for the plant's sample, publishes x̂_k.

use lockstep::{ready_then_wait_for_go, Bus, Launch, LockstepError, PlantLayout};
use serde::{Deserialize, Serialize};

use crate::LinearObserver;

/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = 3;

/// What the launcher tells an observer process.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObserverRun {
    /// The sampled observer.
    pub observer: LinearObserver,
    /// Where y and u_{k−1} sit in the plant's samples.
    pub layout: PlantLayout,
    /// Number of steps.
    pub steps: u64,
}

/// Runs the observer named in `launch`.
pub fn run(launch: &Launch) -> Result<(), LockstepError> {
    let component = format!("observer-{}", launch.name);
    let cfg: ObserverRun =
        serde_json::from_str(&launch.run.read_config(&component)?).map_err(|e| LockstepError::Io(format!("configuration: {e}")))?;
    cfg.observer.check().map_err(LockstepError::Io)?;
    let mut obs = cfg.observer.instantiate();
    let bus = Bus::join(&launch.run, &component, launch.wait)?;
    let outlet = bus.outlet(&format!("observer/{}", launch.name))?;
    let inlet = bus.inlet("plant")?;
    let lay = cfg.layout;
    let mut sample = vec![0.0; lay.len()];
    ready_then_wait_for_go()?;
    for k in 0..cfg.steps {
        let h = inlet.wait_step(k, &mut sample)?;
        let xhat = obs.step(&sample[lay.y()], &sample[lay.u_prev()]);
        outlet.send(k, h.sim_time, h.received_ns, xhat)?;
    }
    Ok(())
}
