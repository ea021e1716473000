//! The FMU plant as a kit component. Sample k is what the FMU's variables hold at t_k after
//! k communication steps of dt (each `substeps` doStep calls):
//!
//! ```text
//! step k−1 → k:  inputs ← u_{k−1} (actuator faults applied, an additive one as φ(t_{k−1}) held),
//!                         w(t_{k−1}) held over the step;   doStep(t_{k−1}, dt)
//! sample k:      x_k ← the `states` variables,  y_k ← the `outputs` + D v(t_k),
//!                then measurement noise and sensor faults (plant::Sensing)
//! ```
//!
//! as for the built-in plant, u and w are zero-order held over the step: an FMU sees its
//! inputs piecewise constant (a sine w enters as its samples).

use lockstep::PlantLayout;
use lockstep::component::{Component, ComponentConfig, Inputs, StepError};
use lti::Mat;
use lti::kernel::mul_acc;
use plant::shell::EXIT_DIVERGED;
use plant::{PlantConfig, Sensing};

use crate::check::{Map, resolve};
use crate::params::Params;
use crate::slave::{Archive, Slave};

pub struct FmuPlant {
    slave: Slave,
    map: Map,
    /// The scenario's signals, bound, faults and noise.
    s: PlantConfig,
    d: Mat,
    sensing: Sensing,
    lay: PlantLayout,
    dt: f64,
    substeps: u32,
    controller: Option<usize>,
    u: Vec<f64>,
    u_applied: Vec<f64>,
    /// w(t_k) and r(t_k) of the last sample: held over the step that follows it.
    w: Vec<f64>,
    r: Vec<f64>,
    /// The FMU's file name, for messages.
    file: String,
}

impl FmuPlant {
    fn fail(&self, e: String) -> StepError {
        StepError::failed(format!("{}: {e}", self.file))
    }
}

impl Component for FmuPlant {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        let p: Params = cfg.params()?;
        // The archive is extracted into the run's directory, which the launcher removes with the
        // run however it ends (an FMU that crashes leaves nothing behind).
        if let Ok(runs) = std::env::var(lockstep::RUNS_DIR_ENV) {
            let dir = std::path::Path::new(&runs).join(&cfg.run);
            if dir.is_dir() {
                // SAFETY: set before this process starts any thread (the kit builds the
                // component before it joins the run).
                unsafe { std::env::set_var("TMPDIR", dir) };
            }
        }
        let (fmu, map) = resolve(&p)?;
        let s = PlantConfig::from_protocol(cfg)?;
        let d: Mat = (&s.d).into();
        let lay = PlantLayout {
            n: s.a.rows,
            p: s.c.rows,
            q: s.e.cols,
            r: s.d.cols,
            l: s.b.cols,
            f: s.faults.len(),
        };
        if (
            map.states.len(),
            map.outputs.len(),
            map.inputs.len(),
            map.disturbances.len(),
        ) != (lay.n, lay.p, lay.l, lay.q)
        {
            return Err(format!(
                "the map has {} states, {} outputs, {} inputs, {} disturbances; the model n = {}, p = {}, l = {}, q = {}",
                map.states.len(),
                map.outputs.len(),
                map.inputs.len(),
                map.disturbances.len(),
                lay.n,
                lay.p,
                lay.l,
                lay.q
            ));
        }
        let file = std::path::Path::new(&p.path)
            .file_name()
            .map_or(p.path.clone(), |f| f.to_string_lossy().into_owned());
        let slave = Archive::open(&p.path, fmu.version, map.python.as_ref())
            .and_then(|a| a.start(&cfg.name, &map.parameters, &map.x0))
            .map_err(|e| format!("{file}: {e}"))?;
        Ok(FmuPlant {
            slave,
            map,
            sensing: Sensing::new(&s)?,
            d,
            lay,
            dt: cfg.dt,
            substeps: p.substeps.max(1),
            controller: cfg.read_index("controller"),
            u: vec![0.0; lay.l],
            u_applied: vec![0.0; lay.l],
            w: vec![0.0; lay.q],
            r: vec![0.0; lay.l],
            s,
            file,
        })
    }

    fn step(&mut self, k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        let dt = self.dt;
        if k > 0 {
            let t = (k - 1) as f64 * dt;
            self.u.copy_from_slice(match self.controller {
                Some(i) => inputs.get(i),
                None => &self.r,
            });
            self.sensing
                .actuate(k - 1, &self.u, &mut self.u_applied, true);
            let r = self
                .slave
                .set(&self.map.inputs, &self.u_applied, t)
                .and_then(|_| self.slave.set(&self.map.disturbances, &self.w, t));
            r.map_err(|e| self.fail(e))?;
            let h = dt / self.substeps as f64;
            for j in 0..self.substeps {
                let r = self.slave.step(t + j as f64 * h, h);
                r.map_err(|e| self.fail(e))?;
            }
        }
        let (lay, t) = (self.lay, k as f64 * dt);
        let r = self
            .slave
            .get(&self.map.states, &mut out[lay.x()], t)
            .and_then(|_| self.slave.get(&self.map.outputs, &mut out[lay.y()], t));
        r.map_err(|e| self.fail(e))?;
        if k > 0
            && let Some(i) = out[lay.x()]
                .iter()
                .position(|v| !v.is_finite() || v.abs() > self.s.state_bound)
        {
            return Err(StepError {
                code: EXIT_DIVERGED,
                message: format!("diverged: x{} = {} at step {k}", i + 1, out[i]),
            });
        }
        for (o, s) in out[lay.w()].iter_mut().zip(&self.s.disturbances) {
            *o = s.sample_step(k, dt);
        }
        for (o, s) in out[lay.v()]
            .iter_mut()
            .zip(&self.s.measurement_disturbances)
        {
            *o = s.sample_step(k, dt);
        }
        for (o, s) in out[lay.r()].iter_mut().zip(&self.s.inputs) {
            *o = s.sample_step(k, dt);
        }
        out[lay.u_prev()].copy_from_slice(&self.u);
        self.w.copy_from_slice(&out[lay.w()]);
        self.r.copy_from_slice(&out[lay.r()]);
        // y = (the FMU's y) + D v, then noise and sensor faults, as the built-in plant measures.
        let (head, tail) = out.split_at_mut(lay.w().start);
        let y = &mut head[lay.y()];
        mul_acc(
            y,
            &self.d,
            &tail[lay.v().start - lay.w().start..lay.v().end - lay.w().start],
        );
        let slots = lay.faults().start - lay.w().start;
        self.sensing.sense(k, y, &mut tail[slots..]);
        Ok(())
    }
}
