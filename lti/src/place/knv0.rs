//! Kautsky–Nichols–Van Dooren method 0 (KNV 1985, §5; scipy's `place_poles(method="KNV0")`).
//!
//! One sweep visits the poles in order. For pole j it takes the unit vector yⱼ orthogonal to all
//! other columns of X (the last column of the full QR factor of X with column j removed) and
//! replaces xⱼ by the normalised projection of yⱼ onto 𝒮ⱼ:
//!
//! ```text
//! xⱼ ← 𝒮ⱼ 𝒮ⱼᴴ yⱼ / ‖𝒮ⱼ 𝒮ⱼᴴ yⱼ‖.
//! ```
//!
//! Each update makes xⱼ as orthogonal as 𝒮ⱼ allows to the others, which raises |det X| for unit
//! columns and so lowers the condition of the eigenvector matrix. A complex pole's partner column
//! is kept equal to its conjugate, so that X Λ X⁻¹ stays real.

use nalgebra::DMatrix;

use super::eigenstructure::{Eigenstructure, abs_det};
use crate::eig::C64;
use crate::householder::full_qr;

/// How many sweeps to run.
#[derive(Debug, Clone, Copy)]
pub enum Sweeps {
    /// Exactly this many (MATLAB's `place` runs 5).
    Exactly(usize),
    /// Until |det X| changes by less than `rtol` relatively, at most `max` sweeps.
    UntilConverged {
        /// Relative change of |det X| under which the iteration stops.
        rtol: f64,
        /// Upper bound on the number of sweeps.
        max: usize,
    },
}

/// Runs method 0 from the initial X; returns the final X and the number of sweeps done.
pub fn knv0(es: &Eigenstructure, mut x: DMatrix<C64>, sweeps: Sweeps) -> (DMatrix<C64>, usize) {
    let n = x.nrows();
    if n <= 1 {
        return (x, 0);
    }
    let (limit, rtol) = match sweeps {
        Sweeps::Exactly(k) => (k, None),
        Sweeps::UntilConverged { rtol, max } => (max, Some(rtol)),
    };
    let mut done = 0;
    while done < limit {
        let before = abs_det(&x);
        for j in 0..n {
            if es.poles[j].im < 0.0 {
                continue; // set together with its partner
            }
            let others = x.clone().remove_column(j);
            let y = full_qr(&others).q.column(n - 1).into_owned();
            if let Some(v) = es.project(j, &y) {
                es.set(&mut x, j, &v);
            }
        }
        done += 1;
        if rtol.is_some_and(|rtol| converged(before, abs_det(&x), rtol)) {
            break;
        }
    }
    (x, done)
}

/// scipy's stopping rule: with d₁ = max(√ε, |det X| after the sweep), stop when
/// |d₁ − d₀| / d₁ < rtol and d₁ > √ε (X far enough from singular).
pub fn converged(before: f64, after: f64, rtol: f64) -> bool {
    let sqrt_eps = f64::EPSILON.sqrt();
    let d1 = after.max(sqrt_eps);
    (d1 - before).abs() / d1 < rtol && d1 > sqrt_eps
}
