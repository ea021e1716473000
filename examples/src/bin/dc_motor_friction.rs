//! A nonlinear plant for `scenarios/dc-motor-friction.toml`: the DC motor of
//! `dc-motor-load-torque` with Coulomb friction on the shaft,
//!
//! ```text
//! ẋ = A x + B u + E (w + τ_f(ω)),   τ_f(ω) = τ_c · tanh(ω / ω_s),   y = C x,
//! ```
//!
//! x = [i, ω, θ], integrated with classical Runge–Kutta (`substeps` per sample, u held over the
//! step; w's piecewise-constant part held at its value of the step's sample — switching on the
//! samples as the published w does — and its sine part evaluated at each stage). Its linearisation about rest without friction is the
//! scenario's `[plant]`. The friction torque enters exactly where the unknown load torque does
//! (the column E), so an unknown-input observer designed on the linear model rejects it as it
//! rejects the load, while a Luenberger observer sees a model error.
//!
//! `params`: `coulomb` (τ_c, in the units of w, default 0.02), `stribeck_speed` (ω_s, rad/s,
//! default 0.05), `substeps` (default 10).

use lockstep::PlantLayout;
use lockstep::component::{self, Component, ComponentConfig, Inputs, StepError};
use lti::Mat;
use plant::PlantConfig;
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    coulomb: f64,
    stribeck_speed: f64,
    substeps: u32,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            coulomb: 0.02,
            stribeck_speed: 0.05,
            substeps: 10,
        }
    }
}

/// The design model's matrices, read through the protocol (`PlantConfig::from_protocol`).
struct Mats {
    a: Mat,
    b: Mat,
    c: Mat,
    d: Mat,
    e: Mat,
}

struct FrictionMotor {
    m: Mats,
    /// The scenario's signals and state bound (its matrices are in `m`).
    s: PlantConfig,
    p: Params,
    lay: PlantLayout,
    dt: f64,
    controller: Option<usize>,
    x: Vec<f64>,
    u: Vec<f64>,
    /// Scratch for the Runge–Kutta stages (no allocation per step).
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
    /// The piecewise-constant part of each w over the current step.
    held: Vec<f64>,
}

impl FrictionMotor {
    /// ẋ at (t, x) with u held: A x + B u + E (w(t) + τ_f(ω)) — ω is x[1]; `held` is the
    /// piecewise-constant part of each w over this step.
    #[allow(clippy::too_many_arguments)]
    fn f(
        m: &Mats,
        s: &PlantConfig,
        p: &Params,
        t: f64,
        x: &[f64],
        u: &[f64],
        held: &[f64],
        out: &mut [f64],
    ) {
        let friction = p.coulomb * (x[1] / p.stribeck_speed).tanh();
        for (i, o) in out.iter_mut().enumerate() {
            let mut v = 0.0;
            for (j, xj) in x.iter().enumerate() {
                v += m.a[(i, j)] * xj;
            }
            for (j, uj) in u.iter().enumerate() {
                v += m.b[(i, j)] * uj;
            }
            for (j, w) in s.disturbances.iter().enumerate() {
                let sine = w.sine().map_or(0.0, |(a, om, ph)| a * (om * t + ph).sin());
                v += m.e[(i, j)] * (held[j] + sine + if j == 0 { friction } else { 0.0 });
            }
            *o = v;
        }
    }

    /// x(t + h) by one Runge–Kutta step.
    fn rk4(&mut self, t: f64, h: f64) {
        let n = self.x.len();
        let (m, s, p, u, held) = (&self.m, &self.s, &self.p, &self.u, &self.held);
        let [k1, k2, k3, k4] = &mut self.k;
        // tmp = x + c·k, the point each next stage is evaluated at.
        let stage = |tmp: &mut [f64], x: &[f64], c: f64, k: &[f64]| {
            for ((t, xi), ki) in tmp.iter_mut().zip(x).zip(k) {
                *t = xi + c * ki;
            }
        };
        Self::f(m, s, p, t, &self.x, u, held, k1);
        stage(&mut self.tmp, &self.x, 0.5 * h, k1);
        Self::f(m, s, p, t + 0.5 * h, &self.tmp, u, held, k2);
        stage(&mut self.tmp, &self.x, 0.5 * h, k2);
        Self::f(m, s, p, t + 0.5 * h, &self.tmp, u, held, k3);
        stage(&mut self.tmp, &self.x, h, k3);
        Self::f(m, s, p, t + h, &self.tmp, u, held, k4);
        for i in 0..n {
            self.x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
}

fn mul(m: &Mat, x: &[f64], i: usize) -> f64 {
    x.iter().enumerate().map(|(j, v)| m[(i, j)] * v).sum()
}

impl Component for FrictionMotor {
    fn new(cfg: &ComponentConfig) -> Result<Self, String> {
        let s = PlantConfig::from_protocol(cfg)?;
        let m = Mats {
            a: (&s.a).into(),
            b: (&s.b).into(),
            c: (&s.c).into(),
            d: (&s.d).into(),
            e: (&s.e).into(),
        };
        let p: Params = cfg.params()?;
        let lay = PlantLayout {
            n: m.a.nrows(),
            p: m.c.nrows(),
            q: m.e.ncols(),
            r: m.d.ncols(),
            l: m.b.ncols(),
            f: 0,
        };
        if lay.n != 3 || lay.q < 1 {
            return Err(format!(
                "this plant is x = [i, ω, θ] with the load torque as the first unknown input; the scenario has n = {}, q = {}",
                lay.n, lay.q
            ));
        }
        if !(p.stribeck_speed > 0.0 && p.substeps > 0 && p.coulomb.is_finite()) {
            return Err("params: stribeck_speed must be > 0, substeps ≥ 1, coulomb finite".into());
        }
        let x = s.x0.clone();
        let held = vec![0.0; lay.q];
        Ok(FrictionMotor {
            held,
            lay,
            dt: cfg.dt,
            controller: cfg.read_index("controller"),
            u: vec![0.0; lay.l],
            k: std::array::from_fn(|_| vec![0.0; 3]),
            tmp: vec![0.0; 3],
            x,
            m,
            s,
            p,
        })
    }

    fn step(&mut self, k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
        if k > 0 {
            match self.controller {
                Some(i) => self.u.copy_from_slice(inputs.get(i)),
                None => {
                    for (u, r) in self.u.iter_mut().zip(&self.s.inputs) {
                        *u = r.sample_step(k - 1, self.dt);
                    }
                }
            }
            for (c, w) in self.held.iter_mut().zip(&self.s.disturbances) {
                let sine = w.sine().map_or(0.0, |(a, om, ph)| {
                    a * (om * (k - 1) as f64 * self.dt + ph).sin()
                });
                *c = w.sample_step(k - 1, self.dt) - sine;
            }
            let h = self.dt / self.p.substeps as f64;
            for j in 0..self.p.substeps {
                self.rk4((k - 1) as f64 * self.dt + j as f64 * h, h);
            }
            if let Some(i) = self
                .x
                .iter()
                .position(|v| !v.is_finite() || v.abs() > self.s.state_bound)
            {
                return Err(StepError {
                    code: plant::shell::EXIT_DIVERGED,
                    message: format!("diverged: x{} = {} at step {k}", i + 1, self.x[i]),
                });
            }
        }
        let (lay, dt) = (self.lay, self.dt);
        out[lay.x()].copy_from_slice(&self.x);
        for (j, y) in out[lay.y()].iter_mut().enumerate() {
            let noise: f64 = self
                .s
                .measurement_disturbances
                .iter()
                .enumerate()
                .map(|(c, s)| self.m.d[(j, c)] * s.sample_step(k, dt))
                .sum();
            *y = mul(&self.m.c, &self.x, j) + noise;
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
        Ok(())
    }
}

fn main() -> std::process::ExitCode {
    component::main::<FrictionMotor>("dc_motor_friction")
}
