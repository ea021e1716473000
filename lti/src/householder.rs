//! Householder QR with LAPACK's conventions (`xGEQRF` + `xUNGQR`), returning the full Q.
//!
//! A = Q R with Q = H₁ H₂ ⋯ H_k, Hᵢ = I − τᵢ vᵢ vᵢᴴ, vᵢ(i) = 1. Each reflector is chosen as
//! LAPACK's `xLARFG` chooses it: β = −sign(Re α)·‖(α, x)‖, τ = (β − α)/β, and H = I when the
//! column below the diagonal is already zero and α is real. Matching these conventions matters:
//! MATLAB's `place` takes "the first vector of a null-space basis" from such a Q, and the gain it
//! returns depends on which vector that is.

use nalgebra::{ComplexField, DMatrix};

/// Full QR factorisation: `q` is m×m unitary, `r` is m×n upper triangular, `a = q r`.
#[derive(Debug, Clone)]
pub struct FullQr<T: ComplexField> {
    /// Unitary factor, m×m.
    pub q: DMatrix<T>,
    /// Upper-triangular factor, m×n.
    pub r: DMatrix<T>,
}

/// Householder QR of `a` (m×n) with the full m×m Q.
pub fn full_qr<T: ComplexField<RealField = f64>>(a: &DMatrix<T>) -> FullQr<T> {
    let m = a.nrows();
    let (r, vs) = reflectors(a);
    FullQr {
        q: q_columns(&vs, m, 0..m),
        r,
    }
}

/// Columns `cols` of the Q of `a`'s Householder QR (the same bits as [`full_qr`]'s Q there:
/// each column of Q is transformed by the reflectors on its own), at O(m·k) per column
/// instead of the O(m²·k) of the whole Q — for a basis of the complement of `a`'s columns.
pub fn qr_q_columns<T: ComplexField<RealField = f64>>(
    a: &DMatrix<T>,
    cols: std::ops::Range<usize>,
) -> DMatrix<T> {
    let m = a.nrows();
    let (_, vs) = reflectors(a);
    q_columns(&vs, m, cols)
}

/// R and the reflectors (v, τ) of `a` (`xGEQRF`). The loops walk the column-major storage
/// directly (column j of an m-row matrix is `[j·m, (j + 1)·m)`); each element sees the same operations in the same order as the textbook loops.
fn reflectors<T: ComplexField<RealField = f64>>(a: &DMatrix<T>) -> (DMatrix<T>, Vec<(Vec<T>, T)>) {
    let (m, n) = a.shape();
    let k = m.min(n);
    let mut r = a.clone();
    let mut vs: Vec<(Vec<T>, T)> = Vec::with_capacity(k);
    for i in 0..k {
        let (v, tau, beta) = reflector(&r.as_slice()[i * m + i..(i + 1) * m]);
        // Apply Hᴴ = I − conj(τ) v vᴴ to the trailing columns (xLARF with conj(tau), as xGEQRF).
        let tau_c = tau.clone().conjugate();
        for j in i + 1..n {
            let col = &mut r.as_mut_slice()[j * m + i..(j + 1) * m];
            let mut w = T::zero();
            for (vp, x) in v.iter().zip(col.iter()) {
                w += vp.clone().conjugate() * x.clone();
            }
            let s = tau_c.clone() * w;
            for (vp, x) in v.iter().zip(col.iter_mut()) {
                *x -= vp.clone() * s.clone();
            }
        }
        let col = &mut r.as_mut_slice()[i * m + i..(i + 1) * m];
        col[0] = beta;
        for x in col.iter_mut().skip(1) {
            *x = T::zero();
        }
        vs.push((v, tau));
    }
    (r, vs)
}

/// Columns `cols` of Q = H₁ ⋯ H_k, each accumulated backwards from the identity's as xUNGQR does.
fn q_columns<T: ComplexField<RealField = f64>>(
    vs: &[(Vec<T>, T)],
    m: usize,
    cols: std::ops::Range<usize>,
) -> DMatrix<T> {
    let mut q = DMatrix::<T>::zeros(m, cols.len());
    for (c, j) in cols.enumerate() {
        let col = &mut q.as_mut_slice()[c * m..(c + 1) * m];
        col[j] = T::one();
        for (i, (v, tau)) in vs.iter().enumerate().rev() {
            let part = &mut col[i..m];
            let mut w = T::zero();
            for (vp, x) in v.iter().zip(part.iter()) {
                w += vp.clone().conjugate() * x.clone();
            }
            let s = tau.clone() * w;
            for (vp, x) in v.iter().zip(part.iter_mut()) {
                *x -= vp.clone() * s.clone();
            }
        }
    }
    q
}

/// `xLARFG`: the reflector that maps `col = (α, x)` to (β, 0). Returns (v with v₀ = 1, τ, β).
fn reflector<T: ComplexField<RealField = f64>>(col: &[T]) -> (Vec<T>, T, T) {
    let alpha = col[0].clone();
    let xnorm = col[1..]
        .iter()
        .map(|c| c.clone().modulus_squared())
        .sum::<f64>()
        .sqrt();
    let mut v = vec![T::one(); col.len()];
    if xnorm == 0.0 && alpha.clone().imaginary() == 0.0 {
        for e in v.iter_mut().skip(1) {
            *e = T::zero();
        }
        return (v, T::zero(), alpha);
    }
    let (ar, ai) = (alpha.clone().real(), alpha.clone().imaginary());
    let norm = (ar * ar + ai * ai + xnorm * xnorm).sqrt();
    let beta = if ar >= 0.0 { -norm } else { norm };
    let tau = T::from_real((beta - ar) / beta) - T::from_real(ai / beta) * imaginary_unit::<T>();
    let scale = T::one() / (alpha - T::from_real(beta));
    for (e, c) in v.iter_mut().zip(col).skip(1) {
        *e = c.clone() * scale.clone();
    }
    (v, tau, T::from_real(beta))
}

/// i for complex scalars, 0 for real ones (where the imaginary part is always zero anyway).
fn imaginary_unit<T: ComplexField<RealField = f64>>() -> T {
    // For real T, `ai` is 0, so the value returned here is multiplied by zero.
    let minus_one = T::from_real(-1.0);
    let s = minus_one.sqrt();
    if s.clone().imaginary() == 1.0 {
        s
    } else {
        T::zero()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Complex;

    #[test]
    fn reconstructs_and_is_orthogonal() {
        let a = DMatrix::from_row_slice(
            4,
            3,
            &[1.0, 2.0, 3.0, 4.0, 5.0, 6.5, 7.0, 8.0, 10.0, -1.0, 0.5, 2.0],
        );
        let FullQr { q, r } = full_qr(&a);
        assert!((&q * &r - &a).norm() < 1e-13);
        assert!((q.transpose() * &q - DMatrix::identity(4, 4)).norm() < 1e-14);
        for i in 0..4 {
            for j in 0..i.min(3) {
                assert_eq!(r[(i, j)], 0.0);
            }
        }
    }

    #[test]
    fn lapack_sign_convention() {
        // dgeqrf on [[3],[4]]: beta = -5, so R = [[-5]] and Q's first column is -[0.6, 0.8].
        let a = DMatrix::from_row_slice(2, 1, &[3.0, 4.0]);
        let FullQr { q, r } = full_qr(&a);
        assert!((r[(0, 0)] + 5.0).abs() < 1e-15);
        assert!((q[(0, 0)] + 0.6).abs() < 1e-15 && (q[(1, 0)] + 0.8).abs() < 1e-15);
        // An already-triangular column with a negative pivot is left alone (tau = 0).
        let b = DMatrix::from_row_slice(2, 1, &[-2.0, 0.0]);
        let f = full_qr(&b);
        assert_eq!(f.r[(0, 0)], -2.0);
        assert_eq!(f.q, DMatrix::identity(2, 2));
    }

    #[test]
    fn complex_reconstructs() {
        let a = DMatrix::from_fn(3, 2, |i, j| {
            Complex::new(i as f64 + 1.0, j as f64 - 0.5 * i as f64)
        });
        let FullQr { q, r } = full_qr(&a);
        assert!((&q * &r - &a).norm() < 1e-13);
        assert!((q.adjoint() * &q - DMatrix::identity(3, 3)).norm() < 1e-14);
    }
}
