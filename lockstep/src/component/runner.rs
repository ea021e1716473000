//! The loop around a component's step function: ports, the step order of PROTOCOL.md §5, and
//! the end sample. Everything is allocated in [`Runner::new`]; a step allocates nothing.

use crate::clock::{now_ns, sleep_until_ns, tight_timers};
use crate::error::LockstepError;
use crate::port::{Bus, Inlet, Outlet};
use crate::sample::Header;

use super::config::{ComponentConfig, Role};
use super::{Component, StepError};

/// The latest samples of a component's inputs, in `reads` order.
#[derive(Debug, Clone)]
pub struct Inputs {
    values: Vec<Vec<f64>>,
    headers: Vec<Header>,
}

impl Inputs {
    /// Zeroed inputs of these lengths.
    pub fn new(lens: impl IntoIterator<Item = usize>) -> Self {
        let values: Vec<Vec<f64>> = lens.into_iter().map(|n| vec![0.0; n]).collect();
        Inputs {
            headers: vec![Header::default(); values.len()],
            values,
        }
    }

    /// The values of input `i`.
    pub fn get(&self, i: usize) -> &[f64] {
        &self.values[i]
    }

    /// Where input `i` is written (for callers that fill inputs themselves, e.g. one-process runs).
    pub fn get_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.values[i]
    }

    /// The header of input `i`'s latest sample.
    pub fn header(&self, i: usize) -> &Header {
        &self.headers[i]
    }

    /// How many inputs.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// True with no inputs.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

/// A component on the bus, stepping in lockstep.
pub struct Runner<C: Component> {
    comp: C,
    role: Role,
    dt: f64,
    steps: u64,
    outlet: Outlet,
    inlets: Vec<Inlet>,
    lags: Vec<u64>,
    /// Steps taken from each input.
    done: Vec<u64>,
    inputs: Inputs,
    out: Vec<f64>,
    /// The plant's pacing period, ns, and when its sample 0 went out.
    pace_ns: Option<u64>,
    t0: u64,
}

impl<C: Component> Runner<C> {
    /// Creates the ports of `cfg` on `bus` around `comp`.
    pub fn new(cfg: &ComponentConfig, bus: &Bus, comp: C) -> Result<Self, LockstepError> {
        let outlet = bus.outlet(&cfg.publishes.service, cfg.publishes.len)?;
        let mut inlets = Vec::with_capacity(cfg.reads.len());
        for r in &cfg.reads {
            let mut inlet = bus.inlet(&r.service)?;
            if let Some(us) = r.sleep_us {
                inlet.sleep_between_polls(us);
            }
            if let Some(t) = cfg.inlet_timeout_s.filter(|t| t.is_finite() && *t > 0.0) {
                inlet.set_timeout(std::time::Duration::from_secs_f64(t));
            }
            inlets.push(inlet);
        }
        Ok(Runner {
            comp,
            role: cfg.role,
            dt: cfg.dt,
            steps: cfg.steps,
            outlet,
            inlets,
            lags: cfg.reads.iter().map(|r| r.lag).collect(),
            done: vec![0; cfg.reads.len()],
            inputs: Inputs::new(cfg.reads.iter().map(|r| r.len)),
            out: vec![0.0; cfg.publishes.len],
            pace_ns: cfg
                .pace_s
                .filter(|p| cfg.role == Role::Plant && p.is_finite() && *p > 0.0)
                .map(|p| {
                    tight_timers();
                    (p * 1e9).round() as u64
                }),
            t0: 0,
        })
    }

    /// A paced plant waits for t₀ + k·pace before it publishes sample k (t₀: sample 0).
    fn pace(&mut self, k: u64) {
        if let Some(p) = self.pace_ns {
            if k == 0 {
                self.t0 = now_ns();
            } else {
                sleep_until_ns(self.t0 + k * p);
            }
        }
    }

    /// The component.
    pub fn component(&self) -> &C {
        &self.comp
    }

    /// Step k of the ring (PROTOCOL.md §5): the plant reads step k − 1 (nothing at k = 0) and
    /// publishes sample k; the others read step k and publish step k.
    pub fn step(&mut self, k: u64) -> Result<(), StepError> {
        let (taken_ns, sim_time) = match self.role {
            Role::Plant if k == 0 => (0, 0.0),
            Role::Plant => (self.take(k - 1, false)?, k as f64 * self.dt),
            _ => {
                let taken = self.take(k, false)?;
                // t_k as the first exact input carries it; k·dt with none.
                let t = self
                    .lags
                    .iter()
                    .position(|&l| l == 0)
                    .map_or(k as f64 * self.dt, |i| self.inputs.headers[i].sim_time);
                (taken, t)
            }
        };
        self.comp.step(k, &self.inputs, &mut self.out)?;
        self.pace(k);
        self.outlet
            .send(k, sim_time, taken_ns, &self.out)
            .map_err(StepError::transport)?;
        Ok(())
    }

    /// After step K − 1: the plant publishes its end sample K once every input, trailing ones
    /// included, has delivered step K − 1; nothing for the others.
    pub fn finish(&mut self) -> Result<(), StepError> {
        if self.role != Role::Plant {
            return Ok(());
        }
        let k = self.steps;
        let taken_ns = if k == 0 { 0 } else { self.take(k - 1, true)? };
        self.comp.step(k, &self.inputs, &mut self.out)?;
        self.pace(k);
        self.outlet
            .send(k, k as f64 * self.dt, taken_ns, &self.out)
            .map_err(StepError::transport)?;
        Ok(())
    }

    /// Reads step `j` of every input: exactly, or for a trailing input whatever has arrived and
    /// at least step j − lag (all of it when `all`). Returns when the step's last exact input
    /// was taken (now, with none).
    fn take(&mut self, j: u64, all: bool) -> Result<u64, StepError> {
        let mut taken: Option<u64> = None;
        for i in 0..self.inlets.len() {
            let (inlet, out) = (&self.inlets[i], &mut self.inputs.values[i]);
            if self.lags[i] == 0 {
                let h = inlet.wait_step(j, out).map_err(StepError::transport)?;
                self.inputs.headers[i] = h;
                self.done[i] = j + 1;
                taken = Some(taken.map_or(h.received_ns, |t: u64| t.max(h.received_ns)));
                continue;
            }
            while let Some(h) = inlet
                .try_step(self.done[i], out)
                .map_err(StepError::transport)?
            {
                self.inputs.headers[i] = h;
                self.done[i] += 1;
            }
            let need = if all {
                j + 1
            } else {
                (j + 1).saturating_sub(self.lags[i])
            };
            while self.done[i] < need {
                self.inputs.headers[i] = inlet
                    .wait_step(self.done[i], out)
                    .map_err(StepError::transport)?;
                self.done[i] += 1;
            }
        }
        Ok(taken.unwrap_or_else(now_ns))
    }
}
