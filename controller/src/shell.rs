//! The controller process: waits for its observer's estimate, publishes u_k.

use lockstep::{ready_then_wait_for_go, Bus, Inlet, Launch, LockstepError, Outlet};

use crate::{Controller, ControllerConfig};

/// Exit code for a transport or configuration failure.
pub const EXIT_FAILED: i32 = 3;

/// The controller's side of the lockstep, one step at a time.
pub struct ControllerLoop {
    ctrl: Controller,
    outlet: Outlet,
    inlet: Inlet,
    xhat: Vec<f64>,
}

impl ControllerLoop {
    /// Creates the controller and its ports on `bus`.
    pub fn new(cfg: &ControllerConfig, bus: &Bus) -> Result<Self, LockstepError> {
        Ok(Self {
            ctrl: Controller::new(cfg).map_err(LockstepError::Io)?,
            outlet: bus.outlet("controller")?,
            inlet: bus.inlet(&format!("observer/{}", cfg.observer))?,
            xhat: vec![0.0; cfg.g.cols],
        })
    }

    /// Takes x̂_k of its observer, publishes u_k.
    pub fn step(&mut self, k: u64) -> Result<(), LockstepError> {
        let h = self.inlet.wait_step(k, &mut self.xhat)?;
        let u = self.ctrl.step(k, &self.xhat);
        self.outlet.send(k, h.sim_time, h.received_ns, u)?;
        Ok(())
    }
}

/// Runs the controller for a launched run.
pub fn run(launch: &Launch) -> Result<(), LockstepError> {
    let cfg: ControllerConfig =
        serde_json::from_str(&launch.run.read_config("controller")?).map_err(|e| LockstepError::Io(format!("configuration: {e}")))?;
    let bus = Bus::join(&launch.run, "controller", launch.wait)?;
    let mut lp = ControllerLoop::new(&cfg, &bus)?;
    ready_then_wait_for_go()?;
    for k in 0..cfg.steps {
        lp.step(k)?;
    }
    Ok(())
}
