//! The controller process: waits for its observer's estimate, publishes u_k.

use lockstep::{ready_then_wait_for_go, Bus, Launch, LockstepError};

use crate::{Controller, ControllerConfig};

/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = 3;

/// Runs the controller for a launched run.
pub fn run(launch: &Launch) -> Result<(), LockstepError> {
    let cfg: ControllerConfig =
        serde_json::from_str(&launch.run.read_config("controller")?).map_err(|e| LockstepError::Io(format!("configuration: {e}")))?;
    let mut ctrl = Controller::new(&cfg).map_err(LockstepError::Io)?;
    let bus = Bus::join(&launch.run, "controller", launch.wait)?;
    let outlet = bus.outlet("controller")?;
    let inlet = bus.inlet(&format!("observer/{}", cfg.observer))?;
    let mut xhat = vec![0.0; cfg.g.cols];
    ready_then_wait_for_go()?;
    for k in 0..cfg.steps {
        let h = inlet.wait_step(k, &mut xhat)?;
        let u = ctrl.step(k, &xhat);
        outlet.send(k, h.sim_time, h.received_ns, u)?;
    }
    Ok(())
}
