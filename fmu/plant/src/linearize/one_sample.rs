//! The FMU's one-sample map F(x, u, w) = (x⁺, y₀), each evaluation on a fresh instance.

use crate::check::{Map, Start};
use crate::params::Params;
use crate::slave::Archive;

/// One FMU, extracted once; a fresh instance per evaluation of F.
pub struct OneSample<'a> {
    p: &'a Params,
    map: &'a Map,
    archive: Archive,
    dt: f64,
    pub instances: usize,
}

impl<'a> OneSample<'a> {
    /// The FMU of `archive` stepped over one sample of `dt`, with the scenario's `p`.
    pub fn new(p: &'a Params, map: &'a Map, archive: Archive, dt: f64) -> Self {
        OneSample {
            p,
            map,
            archive,
            dt,
            instances: 0,
        }
    }

    /// F(z) = (x⁺, y₀) for z = (x, u, w), from a fresh instance.
    pub fn eval(&mut self, z: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let (n, l) = (self.map.states.len(), self.map.inputs.len());
        let starts: Vec<(u32, Start)> = self
            .map
            .parameters
            .iter()
            .cloned()
            .chain(
                self.map
                    .inputs
                    .iter()
                    .zip(&z[n..n + l])
                    .map(|(&vr, &v)| (vr, Start::Real(v))),
            )
            .chain(
                self.map
                    .disturbances
                    .iter()
                    .zip(&z[n + l..])
                    .map(|(&vr, &v)| (vr, Start::Real(v))),
            )
            .collect();
        let x0: Vec<(u32, f64)> = self
            .map
            .states
            .iter()
            .zip(&z[..n])
            .map(|(&vr, &v)| (vr, v))
            .collect();
        self.instances += 1;
        let mut s = self.archive.start("linearize", &starts, &x0)?;
        let (mut x, mut y) = (vec![0.0; n], vec![0.0; self.map.outputs.len()]);
        s.get(&self.map.outputs, &mut y, 0.0)?;
        s.get(&self.map.states, &mut x, 0.0)?;
        if let Some(i) = (0..n).find(|&i| x[i] != z[i]) {
            return Err(format!(
                "the state '{}' reads {} after initialisation where its start value was {}: the FMU does not start where it is set",
                self.p.states[i], x[i], z[i]
            ));
        }
        let h = self.dt / self.p.substeps.max(1) as f64;
        for j in 0..self.p.substeps.max(1) {
            s.step(j as f64 * h, h)?;
        }
        s.get(&self.map.states, &mut x, self.dt)?;
        Ok((x, y))
    }
}
