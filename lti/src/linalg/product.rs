//! Matrix products and LU solves for large matrices (faer's blocked, vectorised kernels).
//!
//! Below [`LARGE`] rows nalgebra's own product is as fast and keeps the exact bits the small
//! reference designs were checked against; above it faer's blocked product runs ≈ 20× faster
//! (n = 1000 here), which is what the Riccati doubling on 500 … 1000-state models spends its
//! time on.

use faer::linalg::solvers::Solve;
use faer::{Accum, Mat as FMat, Par};
use nalgebra::DMatrix;

use super::{from_faer, view};

/// Products with an inner or outer dimension at or above this go to faer.
pub const LARGE: usize = 96;

/// A·B.
pub fn mul(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    assert_eq!(a.ncols(), b.nrows(), "product of non-conforming matrices");
    if a.nrows().max(a.ncols()).max(b.ncols()) < LARGE {
        return a * b;
    }
    let mut out = FMat::<f64>::zeros(a.nrows(), b.ncols());
    faer::linalg::matmul::matmul(
        out.as_mut(),
        Accum::Replace,
        view(a),
        view(b),
        1.0,
        Par::Seq,
    );
    from_faer(&out)
}

/// X with A·X = B by LU with partial pivoting; `None` if A is singular to working precision
/// (a zero pivot, or a non-finite result).
pub fn solve(a: &DMatrix<f64>, b: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    assert_eq!(a.nrows(), a.ncols(), "solve with a non-square matrix");
    if a.nrows() < LARGE {
        return a.clone().lu().solve(b);
    }
    let lu = view(a).partial_piv_lu();
    let x = lu.solve(view(b));
    let x = from_faer(&x);
    x.iter().all(|v| v.is_finite()).then_some(x)
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
        assert!((&a * x - &b).amax() < 1e-12);
    }
}
