//! `uio-fmu-plant --linearize`: the sampled linear model of an FMU at an operating point, made
//! from the FMU itself (the machinery behind `uio-launcher linearize`).
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
mod one_sample;
mod trim;
mod wire;

use crate::check::resolve;
use crate::slave::Archive;
use one_sample::OneSample;
use wire::{Answer, Request};

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
    let mut f = OneSample::new(params, &map, archive, req.dt);
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

/// `uio-fmu-plant --linearize`: the request on stdin, the answer (JSON) on stdout; exit 2 with one
/// line for a request the FMU cannot answer.
pub fn main() -> std::process::ExitCode {
    let answer = crate::request::read::<Request>("request").and_then(|r| run(&r));
    crate::request::answer(
        answer.map(|a| Some(serde_json::to_string(&a).expect("numbers serialise"))),
    )
}
