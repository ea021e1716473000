//! The eigenstructure set-up shared by the KNV and Tits–Yang methods.
//!
//! With B = [U₀ U₁] [Z; 0] (QR, Z invertible for B of full column rank m), A − BK has the
//! eigenvalue λⱼ with eigenvector xⱼ exactly when U₁ᵀ(A − λⱼI) xⱼ = 0, i.e. xⱼ lies in
//! 𝒮ⱼ = ker U₁ᵀ(A − λⱼI), of dimension m for a controllable pair (KNV 1985, eq. 2.6). For any
//! invertible X = [x₁ … x_n] with xⱼ ∈ 𝒮ⱼ,
//!
//! ```text
//! K = Z⁻¹ U₀ᵀ (A − X Λ X⁻¹)        gives        A − BK = X Λ X⁻¹.
//! ```
//!
//! The methods differ only in how they choose X; a well-conditioned X gives eigenvalues that are
//! insensitive to perturbations (the "robust" in robust pole assignment).

use nalgebra::{DMatrix, DVector};

use crate::eig::C64;
use crate::error::{LtiError, Result};
use crate::householder::full_qr;

/// QR of B and the bases 𝒮ⱼ, one per pole (conjugate poles get conjugate bases).
pub struct Eigenstructure {
    /// Poles, conjugate pairs adjacent with the positive imaginary part first.
    pub poles: Vec<C64>,
    /// U₀: the first m columns of B's orthogonal factor.
    pub u0: DMatrix<f64>,
    /// Z: B = U₀ Z.
    pub z: DMatrix<f64>,
    /// Orthonormal basis of 𝒮ⱼ (n×m) for each pole.
    pub s: Vec<DMatrix<C64>>,
}

impl Eigenstructure {
    /// Sets up the problem for A (n×n), B (n×m, full column rank) and n poles.
    ///
    /// 𝒮ⱼ is taken, as MATLAB's `place` does, as the last m columns of the orthogonal factor of
    /// (U₁ᵀ(A − λⱼI))ᴴ: these span its orthogonal complement, which is ker U₁ᵀ(A − λⱼI).
    pub fn new(a: &DMatrix<f64>, b: &DMatrix<f64>, poles: &[C64]) -> Result<Self> {
        let (n, m) = b.shape();
        let qr = full_qr(b);
        let u0 = qr.q.columns(0, m).into_owned();
        let u1 = qr.q.columns(m, n - m).into_owned();
        let z = qr.r.rows(0, m).into_owned();
        let ac = a.map(|v| C64::new(v, 0.0));
        let u1t = u1.transpose().map(|v| C64::new(v, 0.0));
        let mut s: Vec<DMatrix<C64>> = Vec::with_capacity(n);
        for (j, &p) in poles.iter().enumerate() {
            if p.im < 0.0 && j > 0 && poles[j - 1] == p.conj() {
                let partner = s[j - 1].map(|v| v.conj());
                s.push(partner);
                continue;
            }
            let shifted = &ac - DMatrix::<C64>::identity(n, n) * p;
            let mj = &u1t * shifted; // (n−m)×n
            let q = full_qr(&mj.adjoint()).q; // n×n
            s.push(q.columns(n - m, m).into_owned());
        }
        Ok(Self {
            poles: poles.to_vec(),
            u0,
            z,
            s,
        })
    }

    /// Index of the conjugate partner of pole j, if it is complex.
    pub fn partner(&self, j: usize) -> Option<usize> {
        let p = self.poles[j];
        if p.im > 0.0 {
            Some(j + 1)
        } else if p.im < 0.0 {
            Some(j - 1)
        } else {
            None
        }
    }

    /// Projection of y onto 𝒮ⱼ, normalised; None when y is (numerically) orthogonal to 𝒮ⱼ.
    pub fn project(&self, j: usize, y: &DVector<C64>) -> Option<DVector<C64>> {
        let x = &self.s[j] * (self.s[j].adjoint() * y);
        let nx = x.norm();
        (nx > 1e-300).then(|| x / C64::new(nx, 0.0))
    }

    /// Sets column j of X, and its conjugate partner's.
    pub fn set(&self, x: &mut DMatrix<C64>, j: usize, v: &DVector<C64>) {
        x.set_column(j, v);
        if let Some(k) = self.partner(j) {
            x.set_column(k, &v.map(|e| e.conj()));
        }
    }

    /// K = Z⁻¹ U₀ᵀ (A − X Λ X⁻¹).
    pub fn gain(&self, a: &DMatrix<f64>, x: &DMatrix<C64>) -> Result<DMatrix<f64>> {
        let n = a.nrows();
        let lambda = DMatrix::from_diagonal(&DVector::from_column_slice(&self.poles));
        let xl = x * lambda;
        // M = (XΛ) X⁻¹  ⇔  Xᵀ Mᵀ = (XΛ)ᵀ.
        let lu = x.transpose().lu();
        let mt = lu
            .solve(&xl.transpose())
            .ok_or(LtiError::Singular("the eigenvector matrix X"))?;
        let m_real = mt.transpose().map(|v| v.re);
        if m_real.iter().any(|v| !v.is_finite()) {
            return Err(LtiError::Singular("the eigenvector matrix X"));
        }
        let rhs = self.u0.transpose() * (a - m_real);
        let k = self
            .z
            .clone()
            .solve_upper_triangular(&rhs)
            .ok_or(LtiError::Singular("the triangular factor of B"))?;
        debug_assert_eq!(k.shape(), (self.z.nrows(), n));
        Ok(k)
    }
}

/// |det X| for X with unit columns: 1 for orthonormal columns, 0 for dependent ones.
pub fn abs_det(x: &DMatrix<C64>) -> f64 {
    x.clone().lu().determinant().norm()
}
