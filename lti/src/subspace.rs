//! Orthonormal bases of the subspaces of a matrix — null space, range, left null space, a
//! canonical basis of ker C, complements — all from the SVD ([`crate::linalg::svd`]) or a
//! pivoted QR; no greedy column picking.

use nalgebra::DMatrix;

use crate::householder::full_qr;
use crate::linalg::qr::pivot_order;
use crate::linalg::svd::Svd;

/// Orthonormal basis (as columns) of the right null space {v : A v = 0}: the right singular
/// vectors of the singular values under [the rank rule](crate::linalg::svd).
pub fn null_space(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    if n == 0 {
        return DMatrix::zeros(0, 0);
    }
    if m == 0 {
        return DMatrix::identity(n, n);
    }
    match Svd::new(a) {
        Some(svd) => svd.null(),
        None => DMatrix::from_element(n, n, f64::NAN),
    }
}

/// Orthonormal basis (as columns) of the range of A.
pub fn range(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    if m == 0 || n == 0 {
        return DMatrix::zeros(m, 0);
    }
    match Svd::new(a) {
        Some(svd) => svd.range(),
        None => DMatrix::from_element(m, m, f64::NAN),
    }
}

/// An orthonormal basis L (n×(n − rank C)) of ker C with L Lᵀ = I − CᵍC, chosen to be the
/// coordinate vectors e_j where ker C is spanned by them (C = [I 0] gives L = [0; I], the
/// papers' choice, seeds 000 and 003).
///
/// The dimension comes from the SVD of C ([the rank rule](crate::linalg::svd)), never from a
/// greedy rank test. The columns of the projector I − CᵍC (Cᵍ from the same SVD: I − VᵣVᵣᵀ)
/// picked by a rank-revealing QR are well conditioned; they are taken in their original order
/// and orthonormalised (Householder QR, signs so that R has a positive diagonal), which leaves
/// a set of coordinate vectors as it is.
pub fn kernel_basis(c: &DMatrix<f64>) -> DMatrix<f64> {
    let n = c.ncols();
    if c.nrows() == 0 {
        return DMatrix::identity(n, n);
    }
    let Some(svd) = Svd::new(c) else {
        return DMatrix::from_element(n, n, f64::NAN);
    };
    let null = svd.null();
    let r = null.ncols();
    if r == 0 {
        return DMatrix::zeros(n, 0);
    }
    let projector = &null * null.transpose();
    let mut picked: Vec<usize> = pivot_order(&projector).into_iter().take(r).collect();
    picked.sort_unstable();
    let cols: Vec<_> = picked
        .iter()
        .map(|&j| projector.column(j).into_owned())
        .collect();
    let chosen = DMatrix::from_columns(&cols);
    let qr = chosen.qr();
    let (mut q, rr) = (qr.q(), qr.r());
    for j in 0..r {
        if rr[(j, j)] < 0.0 {
            q.column_mut(j).neg_mut();
        }
    }
    // Snap rounding of a coordinate basis (entries within 4ε of 0 or ±1) so that C = [I 0]
    // gives exactly [0; I]; any other basis keeps its computed entries.
    if q.iter()
        .all(|&x| x.abs() <= 4.0 * f64::EPSILON || (x.abs() - 1.0).abs() <= 4.0 * f64::EPSILON)
    {
        q.apply(|x| *x = if x.abs() <= 0.5 { 0.0 } else { x.signum() });
    }
    q
}

/// Completes orthonormal columns `u` (m×r) to an orthogonal m×m matrix [u  u⊥]; returns u⊥.
pub fn orthogonal_complement(u: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, r) = u.shape();
    if r == 0 {
        return DMatrix::identity(m, m);
    }
    if m < crate::linalg::product::LARGE {
        let q = full_qr(u).q;
        return q.columns(r, m - r).into_owned();
    }
    // From 96 rows on, faer's blocked Householder QR: the staircase of a 1000-state model
    // completes ten such bases of up to 1000 rows, where the unblocked one took ~0.4 s.
    let q = crate::linalg::view(u).qr().compute_Q();
    crate::linalg::to_nalgebra(q.as_ref().subcols(r, m - r))
}

/// Rows spanning the left null space {l : l A = 0}, as an orthonormal (m − rank)×m matrix.
pub fn left_null_space(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    if m == 0 {
        return DMatrix::zeros(0, 0);
    }
    if n == 0 {
        return DMatrix::identity(m, m);
    }
    match Svd::new(a) {
        Some(svd) => svd.left_null().transpose(),
        None => DMatrix::from_element(m, m, f64::NAN),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_complements_are_orthonormal_and_orthogonal_to_the_basis() {
        // 150 rows (faer's QR) and 40 (ours): [u u⊥] orthogonal to rounding either way.
        for (m, r) in [(150, 17), (40, 6)] {
            let a = DMatrix::from_fn(m, r, |i, j| {
                ((i * 13 + j * 7) as f64 * 0.31).sin() + if i == j { 2.0 } else { 0.0 }
            });
            let u = range(&a);
            assert_eq!(u.ncols(), r);
            let c = orthogonal_complement(&u);
            assert_eq!(c.shape(), (m, m - r));
            assert!((u.transpose() * &c).amax() < 1e-14);
            assert!((c.transpose() * &c - DMatrix::identity(m - r, m - r)).amax() < 1e-14);
        }
    }

    #[test]
    fn null_space_of_wide_matrix() {
        let a = DMatrix::from_row_slice(1, 3, &[1.0, 2.0, -1.0]);
        let n = null_space(&a);
        assert_eq!(n.shape(), (3, 2));
        assert!((&a * &n).norm() < 1e-14);
        assert!((n.transpose() * &n - DMatrix::identity(2, 2)).norm() < 1e-14);
    }

    #[test]
    fn the_kernel_basis_of_a_coordinate_c_is_the_remaining_coordinates() {
        let c = DMatrix::from_row_slice(2, 4, &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let l = kernel_basis(&c);
        let want = DMatrix::from_row_slice(4, 2, &[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(l, want);
    }

    /// The smallest general C on which the greedy column picking gave 2 columns.
    #[test]
    fn the_kernel_basis_of_a_general_c_has_n_minus_p_orthonormal_columns() {
        let c = DMatrix::from_row_slice(2, 3, &[0.45, -1.8, 1.0, 1.05, -2.2, 1.0]);
        let l = kernel_basis(&c);
        assert_eq!(l.shape(), (3, 1));
        assert!((&c * &l).amax() < 1e-15);
        assert!((l.transpose() * &l - DMatrix::identity(1, 1)).amax() < 1e-15);
        let projector = DMatrix::identity(3, 3) - crate::pinv::pinv(&c) * &c;
        assert!((&l * l.transpose() - projector).amax() < 1e-14);
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
