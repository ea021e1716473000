//! `fmu_plant --linearize`: the sampled linear model of an FMU at an operating point, made
//! from the FMU itself (the machinery behind `launcher linearize`).
//!
//! The FMU's one-sample map, from the state x at t = 0 with u and w held over one sample
//! (`substeps` doStep calls of dt / substeps, as the FMU plant steps it), is
//!
//! ```text
//! F(x, u, w) = (x⁺, y₀):   x⁺ = x(dt),   y₀ = the outputs at t = 0
//! ```
//!
//! and its Jacobian at (x_op, u_op, w_op) is the sampled model in deviations:
//!
//! ```text
//! ∂x⁺/∂(x, u, w) = [Φ  Γ_B  Γ_E],     ∂y₀/∂(x, u, w) = [C  D_u  D_w]
//! ```
//!
//! Each column comes from central differences over fresh instances started at the perturbed
//! point (the states' start values set: they must be initial exact or approx), at a step
//! h_j = 6.06e-6 · max(|z_j|, 1) (∛ε, the step that balances the O(h²) truncation of a central
//! difference against rounding) and at h_j / 2; Richardson's extrapolation of the two is the
//! result, O(h⁴), and |D(h/2) − D(h)| / 3 its error estimate, reported per matrix.
//!
//! With `trim`, x_op is first found for the given u_op, w_op: Newton on x⁺(x) − x = 0, each
//! step the minimum-norm solution of (Φ − I) δ = −(x⁺ − x) over the singular values above
//! 1e-8 σ₁; singular directions are a non-unique equilibrium (a free integrator), reported
//! with the states involved, and what residual stays in them.

mod difference;
mod trim;

use serde::{Deserialize, Serialize};

use crate::check::{Map, Start, resolve};
use crate::params::Params;
use crate::slave::Archive;

/// What the launcher asks for, on stdin.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Request {
    /// The plant's map (`[plant.fmu]`); its `x0` is x_op (or the trim's first guess).
    pub params: Params,
    pub u: Vec<f64>,
    pub w: Vec<f64>,
    pub dt: f64,
    #[serde(default)]
    pub trim: bool,
}

/// A Jacobian block and its estimated error (max |D(h/2) − D(h)| / 3 over the block).
#[derive(Debug, Serialize)]
pub struct Block {
    pub rows: Vec<Vec<f64>>,
    pub error: f64,
}

/// The trim's outcome.
#[derive(Debug, Serialize)]
pub struct Trim {
    pub iterations: usize,
    /// max |x⁺ − x| at the end, over all states.
    pub residual: f64,
    /// x⁺ − x at the end.
    pub step_residual: Vec<f64>,
    /// States (0-based) in a direction along which Φ − I is singular.
    pub free: Vec<usize>,
}

/// The answer, on stdout.
#[derive(Debug, Serialize)]
pub struct Answer {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    #[serde(rename = "Phi")]
    pub phi: Block,
    #[serde(rename = "Gamma_B")]
    pub gamma_b: Block,
    #[serde(rename = "Gamma_E")]
    pub gamma_e: Block,
    #[serde(rename = "C")]
    pub c: Block,
    /// ∂y₀/∂u and ∂y₀/∂w: a direct feedthrough the sampled model has no place for.
    pub d_u: Block,
    pub d_w: Block,
    /// The steps h_j of x, u, w.
    pub steps: Vec<f64>,
    pub trim: Option<Trim>,
    /// FMU instances made.
    pub instances: usize,
}

/// One FMU, extracted once; a fresh instance per evaluation of F.
pub struct OneSample<'a> {
    p: &'a Params,
    map: &'a Map,
    archive: Archive,
    dt: f64,
    pub instances: usize,
}

impl OneSample<'_> {
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

fn run(req: &Request) -> Result<Answer, String> {
    let (n, l, q) = (
        req.params.states.len(),
        req.params.inputs.len(),
        req.params.disturbances.len(),
    );
    if req.u.len() != l || req.w.len() != q {
        return Err(format!(
            "operating point: {} u and {} w given for {l} inputs and {q} disturbances",
            req.u.len(),
            req.w.len()
        ));
    }
    if !(req.dt > 0.0 && req.dt.is_finite()) {
        return Err(format!("dt = {}: must be finite and > 0", req.dt));
    }
    let params = &req.params;
    let Some(x_start) = params.x0.clone() else {
        return Err(
            "x_op: the launcher gives the operating point's x (or the trim's first guess)".into(),
        );
    };
    let (fmu, map) = resolve(params)?;
    let archive = Archive::open(&params.path, fmu.version, map.python.as_ref())?;
    let mut f = OneSample {
        p: params,
        map: &map,
        archive,
        dt: req.dt,
        instances: 0,
    };
    let (x, trim) = if req.trim {
        let t = trim::newton(&mut f, &x_start, &req.u, &req.w)?;
        (t.0, Some(t.1))
    } else {
        (x_start, None)
    };
    let z: Vec<f64> = x.iter().chain(&req.u).chain(&req.w).copied().collect();
    let (_, y) = f.eval(&z)?;
    let d = difference::jacobian(&mut f, &z)?;
    let block = |r: std::ops::Range<usize>, c: std::ops::Range<usize>| difference::block(&d, r, c);
    let (xs, ys) = (0..n, n..n + map.outputs.len());
    let (cx, cu, cw) = (0..n, n..n + l, n + l..n + l + q);
    Ok(Answer {
        phi: block(xs.clone(), cx.clone()),
        gamma_b: block(xs.clone(), cu.clone()),
        gamma_e: block(xs, cw.clone()),
        c: block(ys.clone(), cx),
        d_u: block(ys.clone(), cu),
        d_w: block(ys, cw),
        steps: d.steps.clone(),
        x,
        y,
        trim,
        instances: f.instances,
    })
}

/// `fmu_plant --linearize`: the request on stdin, the answer (JSON) on stdout; exit 2 with one
/// line for a request the FMU cannot answer.
pub fn main() -> std::process::ExitCode {
    let answer = crate::request::read::<Request>("request").and_then(|r| run(&r));
    crate::request::answer(
        answer.map(|a| Some(serde_json::to_string(&a).expect("numbers serialise"))),
    )
}
