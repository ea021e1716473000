//! Rank and Moore–Penrose pseudo-inverse from the SVD, with numpy's relative tolerances.
//!
//! With A = U Σ Vᵀ and singular values σ₁ ≥ … ≥ σ_k:
//! * `rank(A)` counts σᵢ > σ₁ · max(m, n) · ε (numpy `matrix_rank`);
//! * `pinv(A)` = V Σ⁺ Uᵀ, inverting σᵢ > 10⁻¹⁵ · σ₁ (numpy `pinv`'s default `rcond`).
//!
//! The pseudo-inverse is the papers' "g-inverse" Aᵍ: the unique X with AXA = A, XAX = X and
//! AX, XA symmetric (Penrose's four conditions, eqs. 1–4 of seeds 000 and 001).

use nalgebra::DMatrix;

/// numpy's default `rcond` for `pinv`.
pub const PINV_RCOND: f64 = 1e-15;

/// Singular values, largest first (empty for an empty matrix).
pub fn singular_values(a: &DMatrix<f64>) -> Vec<f64> {
    if a.is_empty() {
        return Vec::new();
    }
    let mut s: Vec<f64> = a.clone().svd(false, false).singular_values.iter().copied().collect();
    s.sort_by(|x, y| y.total_cmp(x));
    s
}

/// Tolerance under which a singular value counts as zero for `rank` (numpy `matrix_rank`).
pub fn rank_tolerance(a: &DMatrix<f64>) -> f64 {
    let smax = singular_values(a).first().copied().unwrap_or(0.0);
    smax * a.nrows().max(a.ncols()) as f64 * f64::EPSILON
}

/// Numerical rank with numpy's rule.
pub fn rank(a: &DMatrix<f64>) -> usize {
    let s = singular_values(a);
    let Some(&smax) = s.first() else { return 0 };
    let tol = smax * a.nrows().max(a.ncols()) as f64 * f64::EPSILON;
    s.iter().filter(|&&x| x > tol).count()
}

/// Moore–Penrose pseudo-inverse (n×m for an m×n matrix) with numpy's default cut-off.
pub fn pinv(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    if a.is_empty() {
        return DMatrix::zeros(n, m);
    }
    let svd = a.clone().svd(true, true);
    let u = svd.u.expect("requested U");
    let vt = svd.v_t.expect("requested Vᵀ");
    let smax = svd.singular_values.max();
    let mut out = DMatrix::zeros(n, m);
    for (i, &s) in svd.singular_values.iter().enumerate() {
        if s > PINV_RCOND * smax {
            out += vt.row(i).transpose() * u.column(i).transpose() / s;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn penrose_conditions_hold() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 2.0, 2.0, 4.0, 3.0, 6.0]);
        let x = pinv(&a);
        assert_eq!(rank(&a), 1);
        assert!((&a * &x * &a - &a).norm() < 1e-13);
        assert!((&x * &a * &x - &x).norm() < 1e-13);
        let ax = &a * &x;
        let xa = &x * &a;
        assert!((&ax - ax.transpose()).norm() < 1e-13);
        assert!((&xa - xa.transpose()).norm() < 1e-13);
    }

    #[test]
    fn tiny_singular_value_is_cut() {
        let a = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 1e-20, 0.0]);
        assert_eq!(rank(&a), 1);
        assert_eq!(pinv(&a)[(1, 1)], 0.0);
    }
}
