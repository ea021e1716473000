//! Lyapunov equations, solved through their Kronecker form (fine for the n ≤ 20 of observers).
//!
//! * continuous: AᵀP + PA = −Q  ⇔  (I ⊗ Aᵀ + Aᵀ ⊗ I) vec P = −vec Q;
//! * discrete:   AᵀPA − P = −Q  ⇔  (Aᵀ ⊗ Aᵀ − I) vec P = −vec Q.
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

/// P with AᵀPA − P = −Q.
pub fn discrete(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let n = a.nrows();
    let at = a.transpose();
    let k = at.kronecker(&at) - DMatrix::<f64>::identity(n * n, n * n);
    solve(k, q, n)
}

fn solve(k: DMatrix<f64>, q: &DMatrix<f64>, n: usize) -> Result<DMatrix<f64>> {
    if q.shape() != (n, n) {
        return Err(LtiError::Dimension(format!("Q is {}×{}, expected {n}×{n}", q.nrows(), q.ncols())));
    }
    let rhs = -DMatrix::from_column_slice(n * n, 1, q.as_slice());
    let v = k.lu().solve(&rhs).ok_or(LtiError::Singular("the Lyapunov operator"))?;
    let p = DMatrix::from_column_slice(n, n, v.as_slice());
    Ok((&p + p.transpose()) * 0.5)
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
}
