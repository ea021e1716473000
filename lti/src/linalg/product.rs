//! Matrix products and LU solves for large matrices (faer's blocked, vectorised kernels).
//!
//! Below [`LARGE`] rows nalgebra's own product is as fast and keeps the exact bits the small
//! reference designs were checked against; above it faer's blocked product runs ≈ 20× faster
//! (n = 1000 here), which is what the Riccati doubling on 500 … 1000-state models spends its
//! time on.

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::solvers::Solve;
use faer::{Accum, Par};
use nalgebra::DMatrix;

use super::{view, view_mut};

/// Products with an inner or outer dimension at or above this go to faer.
pub const LARGE: usize = 96;

/// A·B.
pub fn mul(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    assert_eq!(a.ncols(), b.nrows(), "product of non-conforming matrices");
    if a.nrows().max(a.ncols()).max(b.ncols()) < LARGE {
        return a * b;
    }
    // Written straight into nalgebra's column-major buffer (no faer matrix to copy back).
    let mut out = DMatrix::<f64>::zeros(a.nrows(), b.ncols());
    faer::linalg::matmul::matmul(
        view_mut(&mut out),
        Accum::Replace,
        view(a),
        view(b),
        1.0,
        Par::Seq,
    );
    out
}

/// A·B for a product known to be symmetric (AᵀXA, AXAᵀ with X symmetric): from [`LARGE`] rows
/// on only its lower triangle is formed (faer's triangular product, half the flops) and
/// mirrored, so the result is exactly symmetric; below, the full product (the same bits as
/// [`mul`]).
pub fn mul_symmetric(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    assert_eq!(a.ncols(), b.nrows(), "product of non-conforming matrices");
    assert_eq!(a.nrows(), b.ncols(), "a symmetric product is square");
    let n = a.nrows();
    if n.max(a.ncols()) < LARGE {
        return a * b;
    }
    let mut m = DMatrix::<f64>::zeros(n, n);
    triangular::matmul(
        view_mut(&mut m),
        BlockStructure::TriangularLower,
        Accum::Replace,
        view(a),
        BlockStructure::Rectangular,
        view(b),
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
    for j in 0..n {
        for i in 0..j {
            m[(i, j)] = m[(j, i)];
        }
    }
    m
}

/// X with A·X = B by LU with partial pivoting; `None` if A is singular to working precision
/// (a zero pivot, or a non-finite result).
pub fn solve(a: &DMatrix<f64>, b: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    assert_eq!(a.nrows(), a.ncols(), "solve with a non-square matrix");
    if a.nrows() < LARGE {
        return a.clone().lu().solve(b);
    }
    let lu = view(a).partial_piv_lu();
    let mut x = b.clone();
    lu.solve_in_place(view_mut(&mut x));
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// (X₁, X₂) with A·X₁ = B₁ and A·X₂ = B₂, one LU of A for both (as [`solve`] of [B₁ B₂], whose
/// bits it keeps below [`LARGE`] rows; above, no joined copy of the right-hand sides).
pub fn solve_pair(
    a: &DMatrix<f64>,
    b1: &DMatrix<f64>,
    b2: &DMatrix<f64>,
) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    assert_eq!(a.nrows(), a.ncols(), "solve with a non-square matrix");
    let (k1, k2) = (b1.ncols(), b2.ncols());
    if a.nrows() < LARGE {
        let mut rhs = DMatrix::zeros(a.nrows(), k1 + k2);
        rhs.columns_mut(0, k1).copy_from(b1);
        rhs.columns_mut(k1, k2).copy_from(b2);
        let x = solve(a, &rhs)?;
        return Some((
            x.columns(0, k1).into_owned(),
            x.columns(k1, k2).into_owned(),
        ));
    }
    let lu = view(a).partial_piv_lu();
    let (mut x1, mut x2) = (b1.clone(), b2.clone());
    lu.solve_in_place(view_mut(&mut x1));
    lu.solve_in_place(view_mut(&mut x2));
    let finite = |x: &DMatrix<f64>| x.iter().all(|v| v.is_finite());
    (finite(&x1) && finite(&x2)).then_some((x1, x2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_products_and_solves_agree_with_nalgebra() {
        let n = LARGE + 5;
        let a = DMatrix::from_fn(n, n, |i, j| {
            ((i * 7 + j * 3) % 11) as f64 - 5.0 + if i == j { 40.0 } else { 0.0 }
        });
        let b = DMatrix::from_fn(n, 3, |i, j| (i + j) as f64 / 10.0);
        assert!((mul(&a, &b) - &a * &b).amax() < 1e-12);
        let x = solve(&a, &b).unwrap();
        assert!((&a * &x - &b).amax() < 1e-12);
        let b2 = DMatrix::from_fn(n, 2, |i, j| (i * j) as f64 / 50.0 - 1.0);
        let (x1, x2) = solve_pair(&a, &b, &b2).unwrap();
        assert_eq!(x1, x);
        assert!((&a * x2 - &b2).amax() < 1e-12);
    }

    #[test]
    fn symmetric_products_are_the_full_product_mirrored() {
        let n = LARGE + 7;
        let a = DMatrix::from_fn(n, n, |i, j| ((i * 5 + j * 11) % 13) as f64 / 7.0 - 0.9);
        let x = DMatrix::from_fn(n, n, |i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let full = &a.transpose() * &x * &a;
        let half = mul_symmetric(&mul(&a.transpose(), &x), &a);
        assert_eq!(half, half.transpose());
        assert!((&half - &full).amax() <= 1e-13 * full.amax());
    }
}
