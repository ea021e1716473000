//! Ackermann's formula for a single input (Ackermann 1972):
//!
//! ```text
//! K = [0 … 0 1] 𝒞⁻¹ φ(A),    𝒞 = [b, Ab, …, Aⁿ⁻¹b],    φ(s) = ∏ⱼ (s − λⱼ),
//! ```
//!
//! so that eig(A − bK) = {λⱼ}. Exact in exact arithmetic, but 𝒞 is ill-conditioned for all but
//! small n: use it where a paper asks for it (seed 003 computes G this way).

use nalgebra::DMatrix;

use crate::eig::C64;
use crate::error::{LtiError, Result};
use crate::staircase::ctrb;

/// The gain K (1×n) with eig(A − bK) = poles, for b with one column.
pub fn ackermann(a: &DMatrix<f64>, b: &DMatrix<f64>, poles: &[C64]) -> Result<DMatrix<f64>> {
    let n = a.nrows();
    if b.ncols() != 1 {
        return Err(LtiError::Dimension(format!(
            "Ackermann's formula needs a single input, B has {} columns",
            b.ncols()
        )));
    }
    // φ(A) by Horner's rule on the monic characteristic polynomial.
    let coeffs = characteristic_polynomial(poles);
    let mut phi = DMatrix::<f64>::identity(n, n);
    for &c in &coeffs[1..] {
        phi = a * phi + DMatrix::<f64>::identity(n, n) * c;
    }
    // Row e_nᵀ 𝒞⁻¹: solve 𝒞ᵀ w = e_n.
    let mut en = DMatrix::<f64>::zeros(n, 1);
    en[(n - 1, 0)] = 1.0;
    let w = ctrb(a, b)
        .transpose()
        .lu()
        .solve(&en)
        .ok_or(LtiError::Singular("the controllability matrix"))?;
    Ok(w.transpose() * phi)
}

/// Coefficients [1, c₁, …, c_n] of ∏ (s − λⱼ), highest power first; real for a conjugate-closed set.
pub fn characteristic_polynomial(poles: &[C64]) -> Vec<f64> {
    let mut c = vec![C64::new(1.0, 0.0)];
    for &p in poles {
        let mut next = vec![C64::new(0.0, 0.0); c.len() + 1];
        for (i, &ci) in c.iter().enumerate() {
            next[i] += ci;
            next[i + 1] -= ci * p;
        }
        c = next;
    }
    c.into_iter().map(|v| v.re).collect()
}
