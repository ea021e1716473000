//! What acts on a plant from outside its dynamics, the same for every plant that applies the
//! scenario's faults and noise (the built-in plant, an FMU plant): actuator faults change the
//! commanded u before it reaches the plant, sensor faults and measurement noise change y after
//! it leaves, and every fault's (active, value) pair is written into the sample (PROTOCOL.md §4).
//! How additive actuator faults enter is the plant's own: the built-in plant integrates them
//! exactly through B (crate::fault), an FMU plant adds φ(t_k) to its input, held over the step.

use crate::config::PlantConfig;
use crate::fault::{Kind, Scheduled, Target};
use crate::noise::{FAULT_BASE, Gaussian, MEASUREMENT, Stream};

/// Faults and measurement noise of one run.
#[derive(Debug, Clone)]
pub struct Sensing {
    dt: f64,
    pub(crate) faults: Vec<Scheduled>,
    /// Per fault: its noise stream (sensor noise bursts only).
    bursts: Vec<Option<Stream>>,
    measurement_noise: Option<Gaussian>,
}

impl Sensing {
    /// From the plant's configuration (its faults, and R of its noise).
    pub fn new(cfg: &PlantConfig) -> Result<Self, String> {
        let p = cfg.c.rows;
        let seed = cfg.noise.as_ref().map_or(0, |z| z.seed);
        let bursts = cfg
            .faults
            .iter()
            .enumerate()
            .map(|(i, f)| (f.kind == Kind::Noise).then(|| Stream::new(seed, FAULT_BASE + i as u64)))
            .collect();
        let measurement_noise = match &cfg.noise {
            Some(z) if (z.r.rows, z.r.cols) != (p, p) => {
                return Err("plant configuration: the noise covariances do not conform".into());
            }
            Some(z) => Gaussian::new(&z.r, z.seed, MEASUREMENT),
            None => None,
        };
        Ok(Sensing {
            dt: cfg.dt,
            faults: cfg
                .faults
                .iter()
                .map(|f| Scheduled::new(f, cfg.dt))
                .collect(),
            bursts,
            measurement_noise,
        })
    }

    /// The input acting over step k: the commanded `u` with stuck actuators held and lost gain
    /// taken off; with `additive`, an additive actuator fault's φ(t_k) added too.
    pub fn actuate(&self, k: u64, u: &[f64], applied: &mut [f64], additive: bool) {
        lti::kernel::copy(applied, u);
        for f in self.faults.iter().filter(|f| f.active(k)) {
            match (f.fault.target, f.fault.kind) {
                (Target::Actuator(i), Kind::Stuck) => applied[i] = f.fault.value,
                (Target::Actuator(i), Kind::Gain) => applied[i] *= 1.0 - f.fault.value,
                (Target::Actuator(i), Kind::Additive) if additive => {
                    applied[i] += f.magnitude(k, self.dt).0
                }
                _ => {}
            }
        }
    }

    /// y_k as measured: measurement noise, then the sensor faults active at step k; and each
    /// fault's (active, value) pair written to `slots` ([`Sensing::record`]).
    pub fn sense(&mut self, k: u64, y: &mut [f64], slots: &mut [f64]) {
        if let Some(g) = &mut self.measurement_noise {
            g.add_to(y);
        }
        for (i, f) in self.faults.iter().enumerate() {
            if let (Target::Sensor(j), true) = (f.fault.target, f.active(k)) {
                match f.fault.kind {
                    Kind::Stuck => y[j] = f.fault.value,
                    Kind::Noise => {
                        y[j] += f.fault.value * self.bursts[i].as_mut().map_or(0.0, Stream::normal)
                    }
                    _ => y[j] += f.magnitude(k, self.dt).0,
                }
            }
        }
        self.record(k, slots);
    }

    /// Each fault's (active, value) pair at step k, written to `slots` (2 per fault, in order):
    /// the magnitude for additive, bias and drift faults, the value while active for the others.
    pub fn record(&self, k: u64, slots: &mut [f64]) {
        for (i, f) in self.faults.iter().enumerate() {
            let active = f.active(k);
            slots[2 * i] = if active { 1.0 } else { 0.0 };
            slots[2 * i + 1] = match f.fault.kind {
                Kind::Additive | Kind::Bias | Kind::Drift => f.magnitude(k, self.dt).0,
                _ if active => f.fault.value,
                _ => 0.0,
            };
        }
    }
}
