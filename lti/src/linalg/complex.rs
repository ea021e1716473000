//! Complex decompositions for frequency responses ([`crate::freq`]): the solve with zI − A that
//! G(z) = C(zI − A)⁻¹B + D needs, and the singular values of G(z) — faer's LU with partial
//! pivoting and SVD on complex doubles (`faer::c64` is nalgebra's `Complex<f64>`, so the views
//! are borrowed, not copied).
//!
//! Preconditions: finite entries (a non-finite matrix gives `None` or NaN values, never a
//! silent 0).

use faer::MatRef;
use faer::prelude::Solve;
use nalgebra::DMatrix;

use crate::eig::C64;

/// A complex matrix, as the rest of the code base's matrices, column-major.
pub type CMat = DMatrix<C64>;

fn view(a: &CMat) -> MatRef<'_, C64> {
    MatRef::from_column_major_slice(a.as_slice(), a.nrows(), a.ncols())
}

/// X with A·X = B (A square) by LU with partial pivoting; `None` when A is singular to working
/// precision (a non-finite result).
pub fn solve(a: &CMat, b: &CMat) -> Option<CMat> {
    assert_eq!(a.nrows(), a.ncols(), "solve with a non-square matrix");
    assert_eq!(a.nrows(), b.nrows(), "solve: the right-hand side's rows");
    if a.nrows() == 0 {
        return Some(b.clone());
    }
    let x = view(a).partial_piv_lu().solve(view(b));
    let out = CMat::from_fn(b.nrows(), b.ncols(), |i, j| x[(i, j)]);
    out.iter()
        .all(|v| v.re.is_finite() && v.im.is_finite())
        .then_some(out)
}

/// Singular values of A, largest first (empty for an empty matrix, NaN for a non-finite one).
pub fn singular_values(a: &CMat) -> Vec<f64> {
    let k = a.nrows().min(a.ncols());
    if k == 0 {
        return Vec::new();
    }
    if a.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
        return vec![f64::NAN; k];
    }
    view(a)
        .singular_values()
        .unwrap_or_else(|_| vec![f64::NAN; k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_complex_solve_and_singular_values_match_their_definitions() {
        // A = [[1 + i, 2], [0, 3 − i]]: A·X = B checked by the product; σ of a unitary-scaled
        // matrix 2·[[1, i], [i, 1]]/√2 are 2 and 2.
        let a = CMat::from_row_slice(
            2,
            2,
            &[
                C64::new(1.0, 1.0),
                C64::new(2.0, 0.0),
                C64::new(0.0, 0.0),
                C64::new(3.0, -1.0),
            ],
        );
        let b = CMat::from_row_slice(2, 1, &[C64::new(1.0, 0.0), C64::new(0.0, 2.0)]);
        let x = solve(&a, &b).unwrap();
        assert!((&a * &x - &b).norm() < 1e-15, "{x}");
        let h = 2f64.sqrt();
        let u = CMat::from_row_slice(
            2,
            2,
            &[
                C64::new(h, 0.0),
                C64::new(0.0, h),
                C64::new(0.0, h),
                C64::new(h, 0.0),
            ],
        );
        let s = singular_values(&u);
        assert!(
            (s[0] - 2.0).abs() < 1e-15 && (s[1] - 2.0).abs() < 1e-15,
            "{s:?}"
        );
        let singular = CMat::from_element(2, 2, C64::new(1.0, 0.0));
        assert!(solve(&singular, &b).is_none());
    }
}
