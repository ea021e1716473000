//! The trim: x_op with x⁺(x_op, u_op, w_op) = x_op, by Newton's method on the one-sample map
//! (module docs of [`super`]). Each iteration: g = x⁺(x) − x, J = Φ(x) − I from central
//! differences at step h_j, and the minimum-norm step δ = −Σ_{σ_i > 1e-8 σ₁} v_i (u_iᵀ g) / σ_i
//! (an SVD from `lti::linalg`, LAPACK-grade through faer). A singular direction of Φ − I is a
//! state the equilibrium does not fix (a free integrator such as a shaft angle): reported,
//! left where it was, and what residual stays there is said, not hidden.

use lti::DMatrix;
use lti::linalg::svd::Svd;

use super::difference::{column, step};
use super::one_sample::OneSample;
use super::wire::Trim;

/// Newton iterations at most.
pub const MAX_ITERATIONS: usize = 30;
/// Singular values of Φ − I at or below this fraction of the largest are a free direction.
pub const FREE: f64 = 1e-8;

pub fn newton(
    f: &mut OneSample,
    x_start: &[f64],
    u: &[f64],
    w: &[f64],
) -> Result<(Vec<f64>, Trim), String> {
    let n = x_start.len();
    let mut x = x_start.to_vec();
    let z = |x: &[f64]| x.iter().chain(u).chain(w).copied().collect::<Vec<f64>>();
    // States free at the first guess (in a null direction of Φ − I): held there, and their own
    // equations set aside — a shaft angle's x⁺ − x is the speed times dt, which no angle
    // removes; Newton on all equations would stop the motor to cancel it.
    let mut free: Option<Vec<usize>> = None;
    let mut last_norm = f64::INFINITY;
    for it in 1..=MAX_ITERATIONS {
        let zx = z(&x);
        let (xp, _) = f.eval(&zx)?;
        let g: Vec<f64> = xp.iter().zip(&x).map(|(a, b)| a - b).collect();
        let mut j = DMatrix::<f64>::zeros(n, n);
        for c in 0..n {
            let col = column(f, &zx, c, step(zx[c]))?;
            for r in 0..n {
                j[(r, c)] = col[r] - if r == c { 1.0 } else { 0.0 };
            }
        }
        let free =
            free.get_or_insert_with(|| null_states(&j, (0..n).collect()).unwrap_or_default());
        let active: Vec<usize> = (0..n).filter(|k| !free.contains(k)).collect();
        let m = active.len();
        let ja = DMatrix::from_fn(m, m, |r, c| j[(active[r], active[c])]);
        let ga: Vec<f64> = active.iter().map(|&k| g[k]).collect();
        // The minimum-norm Newton step on the active states' own equations.
        let mut delta = vec![0.0; m];
        let mut reducible = 0.0f64;
        if m > 0 {
            let svd = Svd::new(&ja).ok_or("trim: the Jacobian Φ − I is not finite")?;
            let s1 = svd.s.first().copied().unwrap_or(0.0);
            for i in (0..svd.s.len()).filter(|&i| svd.s[i] > FREE * s1) {
                let ug: f64 = (0..m).map(|r| svd.u[(r, i)] * ga[r]).sum();
                reducible = reducible.max(ug.abs());
                for (k, d) in delta.iter_mut().enumerate() {
                    *d -= svd.v[(k, i)] * ug / svd.s[i];
                }
            }
            // Still singular on the active states: more states the equilibrium does not fix.
            if let Some(more) = null_states(&ja, active.clone()) {
                free.extend(more);
                free.sort_unstable();
            }
        }
        let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        // Converged: what a step could still remove is at rounding level, or stopped shrinking.
        if reducible <= 1e-13 * scale || (it > 3 && reducible >= 0.5 * last_norm) {
            let residual = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            return Ok((
                x,
                Trim {
                    iterations: it,
                    residual,
                    step_residual: g,
                    free: free.clone(),
                },
            ));
        }
        last_norm = reducible;
        for (&k, d) in active.iter().zip(&delta) {
            x[k] += d;
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(format!(
                "trim: Newton's step left the finite numbers at iteration {it}"
            ));
        }
    }
    Err(format!(
        "trim: no equilibrium within {MAX_ITERATIONS} Newton iterations from x = {x_start:?}"
    ))
}

/// The states (of `index`, the rows and columns of `j`) in a null direction of `j`: entries
/// above 0.1 of a unit right singular vector whose singular value is at most FREE σ₁.
fn null_states(j: &DMatrix<f64>, index: Vec<usize>) -> Option<Vec<usize>> {
    let svd = Svd::new(j)?;
    let s1 = svd.s.first().copied().unwrap_or(0.0);
    let null: Vec<usize> = (0..svd.s.len())
        .filter(|&i| svd.s[i] <= FREE * s1)
        .collect();
    let states: Vec<usize> = (0..index.len())
        .filter(|&k| null.iter().any(|&i| svd.v[(k, i)].abs() > 0.1))
        .map(|k| index[k])
        .collect();
    (!states.is_empty()).then_some(states)
}
