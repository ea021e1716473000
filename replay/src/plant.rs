//! The replayed plant as a kit component. Sample k is row k of the data on the run's grid
//! ([`replay::Table`]), published as it is: x, y, w, v, r and u_{k−1} as recorded. Nothing is
//! applied to it: the data holds its own faults and noise, which the scenario's `[[fault]]`
//! and `[noise]` only describe, for the design and the scoring. Each fault's (active, value)
//! slots are computed from `[[fault]]` as the built-in plant computes them (plant::Sensing),
//! so that detection delays are measured against the fault the data is said to hold.

use lockstep::PlantLayout;
use lockstep::component::{Component, ComponentConfig, Inputs, StepError};
use plant::{PlantConfig, Sensing};
use replay::{Params, Table};

pub struct ReplayPlant {
    table: Table,
    /// Only to write the fault slots ([`Sensing::record`]): nothing acts on the data.
    sensing: Sensing,
    lay: PlantLayout,
}

impl Component for ReplayPlant {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        let p: Params = cfg.params()?;
        let s = PlantConfig::from_protocol(cfg)?;
        let lay = PlantLayout {
            n: s.a.rows,
            p: s.c.rows,
            q: s.e.cols,
            r: s.d.cols,
            l: s.b.cols,
            f: s.faults.len(),
        };
        if (p.n, p.p, p.q, p.r, p.l) != (lay.n, lay.p, lay.q, lay.r, lay.l) || p.steps != cfg.steps
        {
            return Err(format!(
                "{}: the parameters are for n = {}, p = {}, l = {}, q = {}, r = {}, {} steps; the run has n = {}, p = {}, l = {}, q = {}, r = {}, {} steps",
                p.file(),
                p.n,
                p.p,
                p.l,
                p.q,
                p.r,
                p.steps,
                lay.n,
                lay.p,
                lay.l,
                lay.q,
                lay.r,
                cfg.steps
            ));
        }
        let table = replay::load(&p)?;
        Ok(ReplayPlant {
            table,
            sensing: Sensing::new(&s)?,
            lay,
        })
    }

    fn step(&mut self, k: u64, _inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        let end = self.lay.faults().start;
        out[..end].copy_from_slice(self.table.row(k));
        self.sensing.record(k, &mut out[end..]);
        Ok(())
    }
}
