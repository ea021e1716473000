//! The observer process: waits for the plant's sample, publishes x̂_k.

use lockstep::{ready_then_wait_for_go, Bus, Inlet, Launch, LockstepError, Outlet, PlantLayout};
use serde::{Deserialize, Serialize};

use crate::{LinearObserver, ObserverState};

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
    /// Off the critical path: poll with this sleep (µs) instead of the run's wait strategy.
    pub follower_sleep_us: Option<u32>,
}

/// An observer's side of the lockstep, one step at a time.
pub struct ObserverLoop {
    obs: ObserverState,
    outlet: Outlet,
    inlet: Inlet,
    layout: PlantLayout,
    sample: Vec<f64>,
}

impl ObserverLoop {
    /// Creates the observer `name` and its ports on `bus`.
    pub fn new(cfg: &ObserverRun, name: &str, bus: &Bus) -> Result<Self, LockstepError> {
        cfg.observer.check().map_err(LockstepError::Io)?;
        let mut inlet = bus.inlet("plant")?;
        if let Some(us) = cfg.follower_sleep_us {
            inlet.sleep_between_polls(us);
        }
        Ok(Self {
            obs: cfg.observer.instantiate(),
            outlet: bus.outlet(&format!("observer/{name}"))?,
            inlet,
            layout: cfg.layout,
            sample: vec![0.0; cfg.layout.len()],
        })
    }

    /// Takes the plant's sample of step k, publishes x̂_k.
    pub fn step(&mut self, k: u64) -> Result<(), LockstepError> {
        let h = self.inlet.wait_step(k, &mut self.sample)?;
        let lay = self.layout;
        let xhat = self.obs.step(&self.sample[lay.y()], &self.sample[lay.u_prev()]);
        self.outlet.send(k, h.sim_time, h.received_ns, xhat)?;
        Ok(())
    }
}

/// Runs the observer named in `launch`.
pub fn run(launch: &Launch) -> Result<(), LockstepError> {
    let component = format!("observer-{}", launch.name);
    let cfg: ObserverRun =
        serde_json::from_str(&launch.run.read_config(&component)?).map_err(|e| LockstepError::Io(format!("configuration: {e}")))?;
    let bus = Bus::join(&launch.run, &component, launch.wait)?;
    let mut lp = ObserverLoop::new(&cfg, &launch.name, &bus)?;
    ready_then_wait_for_go()?;
    for k in 0..cfg.steps {
        lp.step(k)?;
    }
    Ok(())
}
