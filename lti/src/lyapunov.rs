//! Lyapunov equations, solved through their Kronecker form (n²×n², fine for the n ≤ 20 of the
//! textbook observers):
//!
//! * continuous: AᵀP + PA = −Q  ⇔  (I ⊗ Aᵀ + Aᵀ ⊗ I) vec P = −vec Q;
//! * discrete:   AᵀPA − P = −Q  ⇔  (Aᵀ ⊗ Aᵀ − I) vec P = −vec Q.
//!
//! Above [`KRONECKER_MAX`] states the discrete (Stein) equation is solved by Smith's doubling
//! (Smith, "Matrix equation XA + BX = C", SIAM J. Appl. Math. 16(1), 1968): P = Σₖ (Aᵀ)ᵏQAᵏ,
//! summed as P_{j+1} = P_j + A_jᵀP_jA_j, A_{j+1} = A_j², i.e. 2ʲ terms after j steps — O(n³) per
//! step and ~log₂(36/(1 − ρ(A))) steps for a Schur-stable A, where the Kronecker form would need
//! O(n⁶) (a 52-state model's LU alone is 10¹⁰ flops).
//!
//! For a Hurwitz (resp. Schur) A and Q ≻ 0 the solution P is symmetric positive definite, and
//! V(e) = eᵀPe certifies the decay of ė = Ae (resp. e⁺ = Ae). Shifting A by αI before solving
//! certifies the decay rate α: every trajectory satisfies ‖e(t)‖ ≤ κ e^{−αt} ‖e(0)‖.

use nalgebra::DMatrix;

use crate::error::{LtiError, Result};

/// P with AᵀP + PA = −Q.
pub fn continuous(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let n = a.nrows();
    let i = DMatrix::<f64>::identity(n, n);
    let at = a.transpose();
    let k = i.kronecker(&at) + at.kronecker(&i);
    solve(k, q, n)
}

/// The largest order solved through the Kronecker form; larger discrete equations use Smith's
/// doubling.
pub const KRONECKER_MAX: usize = 24;

/// P with AᵀPA − P = −Q.
pub fn discrete(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let n = a.nrows();
    if n > KRONECKER_MAX {
        return smith(a, q);
    }
    let at = a.transpose();
    let k = at.kronecker(&at) - DMatrix::<f64>::identity(n * n, n * n);
    solve(k, q, n)
}

fn solve(k: DMatrix<f64>, q: &DMatrix<f64>, n: usize) -> Result<DMatrix<f64>> {
    if q.shape() != (n, n) {
        return Err(LtiError::Dimension(format!(
            "Q is {}×{}, expected {n}×{n}",
            q.nrows(),
            q.ncols()
        )));
    }
    let rhs = -DMatrix::from_column_slice(n * n, 1, q.as_slice());
    let v = k
        .lu()
        .solve(&rhs)
        .ok_or(LtiError::Singular("the Lyapunov operator"))?;
    let p = DMatrix::from_column_slice(n, n, v.as_slice());
    Ok((&p + p.transpose()) * 0.5)
}

/// Smith's doubling for AᵀPA − P = −Q (A Schur-stable): stops when a step changes P by less than
/// its rounding; refuses when the sum does not settle (ρ(A) ≥ 1, so there is no such P ⪰ 0).
fn smith(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    use crate::linalg::product::{mul, mul_symmetric};
    let n = a.nrows();
    if q.shape() != (n, n) {
        return Err(LtiError::Dimension(format!(
            "Q is {}×{}, expected {n}×{n}",
            q.nrows(),
            q.ncols()
        )));
    }
    let norm = |m: &DMatrix<f64>| {
        m.column_iter()
            .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let (mut p, mut ak) = (q.clone(), a.clone());
    for _ in 0..64 {
        // faer's blocked products from 96 rows on (the Newton steps of a 1000-state DARE spent
        // most of their time here in nalgebra's), nalgebra's below: the same bits as before there.
        let step = mul_symmetric(&mul(&ak.transpose(), &p), &ak);
        let (change, size) = (norm(&step), norm(&p));
        p += step;
        if !(change.is_finite() && p.iter().all(|v| v.is_finite())) {
            break;
        }
        if change <= f64::EPSILON * size {
            return Ok((&p + p.transpose()) * 0.5);
        }
        ak = mul(&ak, &ak);
    }
    Err(LtiError::Singular(
        "the Stein operator (A is not Schur-stable)",
    ))
}

/// Smallest eigenvalue of a symmetric matrix.
pub fn min_eigenvalue(p: &DMatrix<f64>) -> f64 {
    p.clone().symmetric_eigen().eigenvalues.min()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_cases() {
        let a = DMatrix::from_element(1, 1, -2.0);
        let q = DMatrix::from_element(1, 1, 1.0);
        assert!((continuous(&a, &q).unwrap()[(0, 0)] - 0.25).abs() < 1e-15);
        let ad = DMatrix::from_element(1, 1, 0.5);
        assert!((discrete(&ad, &q).unwrap()[(0, 0)] - 4.0 / 3.0).abs() < 1e-14);
    }

    /// Smith's doubling against the Kronecker form on the same Schur-stable A, and refusing an
    /// unstable one.
    #[test]
    fn smith_matches_kronecker() {
        let n = 12;
        let a = DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                0.9 - 0.05 * i as f64
            } else {
                0.02 * ((i * 7 + j * 3) % 5) as f64 - 0.04
            }
        });
        let q = DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                2.0
            } else {
                0.1 / (1.0 + (i + j) as f64)
            }
        });
        let exact = discrete(&a, &q).unwrap();
        let doubled = smith(&a, &q).unwrap();
        assert!(
            (&exact - &doubled).amax() <= 1e-12 * exact.amax(),
            "{}",
            (&exact - &doubled).amax()
        );
        assert!(smith(&(a * 1.5), &q).is_err());
    }
}
