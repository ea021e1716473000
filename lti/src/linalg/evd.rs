//! Eigenvalues and eigenvectors of a real square matrix: Parlett–Reinsch balancing
//! ([`crate::eig::balance`]), then faer's real Schur form (Hessenberg reduction and the
//! multishift Francis QR with aggressive early deflation, LAPACK `xHSEQR`'s method).
//!
//! Preconditions: square, finite. The iteration can in principle fail to converge; faer's
//! multishift QR converged on every model tried here, among them the ANDES power systems of
//! 52 … 569 states on which nalgebra's Schur iteration failed.

use faer::Mat as FMat;
use nalgebra::{Complex, DMatrix};

use super::view;
use crate::error::{LtiError, Result};
use crate::linalg::balance::balance;

/// Eigenvalues of A (unsorted; conjugate pairs exact, the standardized 2×2 Schur blocks').
pub fn eigenvalues(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>> {
    let n = a.nrows();
    if n != a.ncols() {
        return Err(LtiError::Dimension(format!(
            "eigenvalues of a {}×{} matrix",
            n,
            a.ncols()
        )));
    }
    if n == 0 {
        return Ok(Vec::new());
    }
    if a.iter().any(|x| !x.is_finite()) {
        return Err(LtiError::NoConvergence(
            "eigenvalues of a non-finite matrix",
        ));
    }
    let b = balance(a);
    view(&b)
        .eigenvalues()
        .map_err(|_| LtiError::NoConvergence("the real Schur iteration (faer)"))
}

/// Eigenvalues and, for each, its right eigenvector.
pub type Eigen = (Vec<Complex<f64>>, Vec<Vec<Complex<f64>>>);

/// Eigenvalues and right eigenvectors (columns, unit 2-norm) of A, unbalanced.
pub fn eigen(a: &DMatrix<f64>) -> Result<Eigen> {
    let n = a.nrows();
    if n != a.ncols() {
        return Err(LtiError::Dimension(format!(
            "eigenvectors of a {}×{} matrix",
            n,
            a.ncols()
        )));
    }
    if a.iter().any(|x| !x.is_finite()) {
        return Err(LtiError::NoConvergence(
            "eigenvectors of a non-finite matrix",
        ));
    }
    if n == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    let evd = view(a)
        .eigen()
        .map_err(|_| LtiError::NoConvergence("the real Schur iteration (faer)"))?;
    let s = evd.S();
    let u: FMat<Complex<f64>> = evd.U().to_owned();
    let values = (0..n).map(|i| s[i]).collect();
    let vectors = (0..n)
        .map(|j| {
            let col: Vec<Complex<f64>> = (0..n).map(|i| u[(i, j)]).collect();
            let norm = col.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
            if norm > 0.0 {
                col.iter().map(|z| z / norm).collect()
            } else {
                col
            }
        })
        .collect();
    Ok((values, vectors))
}

/// An eigenvector of A for the computed eigenvalue λ by inverse iteration: three solves with the
/// LU of A − λI (faer's partial-pivoting LU, complex), from a fixed start. For a simple λ computed
/// to rounding, A − λI is singular to rounding and each solve multiplies the eigenvector's
/// share by ~1/ε: the result is the eigenvector to rounding. For a multiple λ it is some vector
/// of the eigenspace (or a principal vector). Returned scaled to max |xᵢ| = 1, with the
/// relative residual ‖(A − λI)x‖∞ / (‖A‖∞ + |λ|); `None` if the solve broke down.
pub fn inverse_iteration(
    a: &DMatrix<f64>,
    lambda: Complex<f64>,
) -> Option<(Vec<Complex<f64>>, f64)> {
    use faer::c64;
    use faer::linalg::solvers::Solve;
    let n = a.nrows();
    if n == 0 || n != a.ncols() || a.iter().any(|x| !x.is_finite()) {
        return None;
    }
    // An exact eigenvalue (a triangular A) makes A − λI exactly singular and the LU divide by
    // zero: shifting λ by a few ulps keeps it nonsingular and changes nothing else.
    let lambda = lambda * (1.0 + 4.0 * f64::EPSILON) + Complex::new(4.0 * f64::EPSILON, 0.0);
    let shifted = FMat::<c64>::from_fn(n, n, |i, j| {
        let d = if i == j {
            lambda
        } else {
            Complex::new(0.0, 0.0)
        };
        c64::new(a[(i, j)] - d.re, -d.im)
    });
    let lu = shifted.partial_piv_lu();
    // A start with no special direction: 1 + frac(i·φ).
    let mut x = FMat::<c64>::from_fn(n, 1, |i, _| {
        c64::new(1.0 + (i as f64 * 0.618_033_988_749_895).fract(), 0.0)
    });
    for _ in 0..3 {
        x = lu.solve(&x);
        let top = (0..n).map(|i| x[(i, 0)].norm()).fold(0.0, f64::max);
        if !(top.is_finite() && top > 0.0) {
            return None;
        }
        x = FMat::from_fn(n, 1, |i, _| x[(i, 0)] / top);
    }
    let r = &shifted * &x;
    let residual = (0..n).map(|i| r[(i, 0)].norm()).fold(0.0, f64::max);
    let norm_a = (0..n)
        .map(|i| (0..n).map(|j| a[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let v = (0..n)
        .map(|i| Complex::new(x[(i, 0)].re, x[(i, 0)].im))
        .collect();
    Some((
        v,
        residual / (norm_a + lambda.norm()).max(f64::MIN_POSITIVE),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rotation_has_a_conjugate_pair() {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, -2.0, 2.0, 0.0]);
        let mut ev = eigenvalues(&a).unwrap();
        ev.sort_by(|x, y| x.im.total_cmp(&y.im));
        assert_eq!(ev[0], ev[1].conj());
        assert!((ev[1] - Complex::new(0.0, 2.0)).norm() < 1e-15);
    }

    #[test]
    fn eigenvectors_satisfy_the_eigen_equation() {
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -6.0, -11.0, -6.0]);
        let (values, vectors) = eigen(&a).unwrap();
        for (l, v) in values.iter().zip(&vectors) {
            for i in 0..3 {
                let av: Complex<f64> = (0..3).map(|j| v[j] * a[(i, j)]).sum();
                assert!((av - v[i] * l).norm() < 1e-13);
            }
        }
    }
}
