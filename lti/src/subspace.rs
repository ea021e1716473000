//! Orthonormal bases of the subspaces of a matrix: null space, range, and complements.

use nalgebra::DMatrix;

use crate::householder::full_qr;
use crate::pinv::rank_tolerance;

/// Orthonormal basis (as columns) of the right null space {v : A v = 0}, from the full SVD.
///
/// A wide A is padded with zero rows so that the SVD returns the whole of V.
pub fn null_space(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    if n == 0 {
        return DMatrix::zeros(0, 0);
    }
    if m == 0 {
        return DMatrix::identity(n, n);
    }
    let tol = rank_tolerance(a);
    let padded = if m < n { a.clone().resize_vertically(n, 0.0) } else { a.clone() };
    let svd = padded.svd(false, true);
    let vt = svd.v_t.expect("requested Vᵀ");
    let mut cols = Vec::new();
    for (i, &s) in svd.singular_values.iter().enumerate() {
        if s <= tol {
            cols.push(vt.row(i).transpose());
        }
    }
    if cols.is_empty() {
        return DMatrix::zeros(n, 0);
    }
    DMatrix::from_columns(&cols)
}

/// Orthonormal basis (as columns) of the range of A.
pub fn range(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    if m == 0 || n == 0 {
        return DMatrix::zeros(m, 0);
    }
    let tol = rank_tolerance(a);
    let svd = a.clone().svd(true, false);
    let u = svd.u.expect("requested U");
    let cols: Vec<_> = svd
        .singular_values
        .iter()
        .enumerate()
        .filter(|(_, s)| **s > tol)
        .map(|(i, _)| u.column(i).into_owned())
        .collect();
    if cols.is_empty() {
        return DMatrix::zeros(m, 0);
    }
    DMatrix::from_columns(&cols)
}

/// Completes orthonormal columns `u` (m×r) to an orthogonal m×m matrix [u  u⊥]; returns u⊥.
pub fn orthogonal_complement(u: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, r) = u.shape();
    if r == 0 {
        return DMatrix::identity(m, m);
    }
    let q = full_qr(u).q;
    q.columns(r, m - r).into_owned()
}

/// Rows spanning the left null space {l : l A = 0}, as an orthonormal (m − rank)×m matrix.
pub fn left_null_space(a: &DMatrix<f64>) -> DMatrix<f64> {
    null_space(&a.transpose()).transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn null_space_of_wide_matrix() {
        let a = DMatrix::from_row_slice(1, 3, &[1.0, 2.0, -1.0]);
        let n = null_space(&a);
        assert_eq!(n.shape(), (3, 2));
        assert!((&a * &n).norm() < 1e-14);
        assert!((n.transpose() * &n - DMatrix::identity(2, 2)).norm() < 1e-14);
    }

    #[test]
    fn complement_is_orthogonal() {
        let u = range(&DMatrix::from_row_slice(3, 1, &[1.0, 1.0, 0.0]));
        let c = orthogonal_complement(&u);
        assert_eq!(c.shape(), (3, 2));
        assert!((u.transpose() * &c).norm() < 1e-15);
    }

    #[test]
    fn left_null_of_d() {
        // Seed 004: D = [1, 2]ᵀ, so l D = 0 for l ∝ [2, −1].
        let d = DMatrix::from_row_slice(2, 1, &[1.0, 2.0]);
        let l = left_null_space(&d);
        assert_eq!(l.shape(), (1, 2));
        assert!((l[(0, 0)] / l[(0, 1)] + 2.0).abs() < 1e-14);
    }
}
