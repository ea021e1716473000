//! The plant process: reads its configuration, joins the run's bus, and steps in lockstep.

use lockstep::{now_ns, ready_then_wait_for_go, Bus, Inlet, Launch, LockstepError, Outlet, FOLLOWER_LAG};

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

/// The plant's side of the lockstep: its ports and the step function, one step at a time.
pub struct PlantLoop {
    plant: Plant,
    outlet: Outlet,
    observers: Vec<Inlet>,
    followers: Vec<bool>,
    controller: Option<Inlet>,
    /// Steps each observer has completed; a follower may trail by up to FOLLOWER_LAG.
    done: Vec<u64>,
    xhat: Vec<f64>,
    u: Vec<f64>,
    taken_ns: u64,
    steps: u64,
}

impl PlantLoop {
    /// Creates the plant and its ports on `bus`.
    pub fn new(cfg: &PlantRun, bus: &Bus) -> Result<Self, ShellError> {
        let plant = Plant::new(&cfg.plant).map_err(ShellError::Config)?;
        let outlet = bus.outlet("plant")?;
        let observers = cfg.observers.iter().map(|o| bus.inlet(&format!("observer/{o}"))).collect::<Result<Vec<_>, _>>()?;
        let controller = if cfg.controller { Some(bus.inlet("controller")?) } else { None };
        let lay = plant.layout();
        Ok(Self {
            plant,
            outlet,
            done: vec![0; observers.len()],
            observers,
            followers: cfg.followers.clone(),
            controller,
            xhat: vec![0.0; lay.n],
            u: vec![0.0; lay.l],
            taken_ns: 0,
            steps: cfg.plant.steps,
        })
    }

    /// Publishes the sample of step k.
    pub fn publish(&mut self, k: u64) -> Result<(), ShellError> {
        let t = self.plant.time(k);
        self.outlet.send(k, t, self.taken_ns, self.plant.sample(k))?;
        Ok(())
    }

    /// Waits for what step k needs (the ring's estimate and u_k; followers within their lag),
    /// then advances the state to step k + 1.
    pub fn complete(&mut self, k: u64) -> Result<(), ShellError> {
        for (i, inlet) in self.observers.iter().enumerate() {
            if self.followers[i] {
                while inlet.try_step(self.done[i], &mut self.xhat)?.is_some() {
                    self.done[i] += 1;
                }
                while self.done[i] + FOLLOWER_LAG <= k {
                    inlet.wait_step(self.done[i], &mut self.xhat)?;
                    self.done[i] += 1;
                }
            } else {
                self.taken_ns = inlet.wait_step(k, &mut self.xhat)?.received_ns;
                self.done[i] = k + 1;
            }
        }
        match &self.controller {
            Some(inlet) => self.taken_ns = inlet.wait_step(k, &mut self.u)?.received_ns,
            None => {
                self.u.copy_from_slice(self.plant.reference());
                if self.observers.is_empty() {
                    self.taken_ns = now_ns();
                }
            }
        }
        self.plant.advance(k, &self.u).map_err(ShellError::Diverged)
    }

    /// Waits until the followers have taken the last step too.
    pub fn finish(&mut self) -> Result<(), ShellError> {
        for (i, inlet) in self.observers.iter().enumerate() {
            while self.done[i] < self.steps {
                inlet.wait_step(self.done[i], &mut self.xhat)?;
                self.done[i] += 1;
            }
        }
        Ok(())
    }
}

/// Runs the plant for a launched run.
pub fn run(launch: &Launch) -> Result<(), ShellError> {
    let cfg: PlantRun = serde_json::from_str(&launch.run.read_config("plant")?).map_err(|e| ShellError::Config(e.to_string()))?;
    let bus = Bus::join(&launch.run, "plant", launch.wait)?;
    let mut lp = PlantLoop::new(&cfg, &bus)?;
    ready_then_wait_for_go()?;
    for k in 0..cfg.plant.steps {
        lp.publish(k)?;
        lp.complete(k)?;
    }
    lp.finish()?;
    // The end sample: x_K, and when the plant had u_{K−1} — the last step's latency. Sent once
    // every follower has taken step K − 1, so it never crowds a trailing subscriber's buffer.
    lp.publish(cfg.plant.steps)
}
