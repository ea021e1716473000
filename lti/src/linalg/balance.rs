//! Balancing (Parlett & Reinsch; LAPACK `xGEBAL` with job 'S'): D⁻¹AD with D a diagonal of
//! powers of two, so that each row and column have comparable norms. Exact in floating point
//! (powers of two), the eigenvalues unchanged; the Schur iteration of [`crate::linalg::evd`]
//! runs on the balanced matrix.

use nalgebra::DMatrix;

/// D⁻¹ A D with D a diagonal of powers of two (Parlett–Reinsch balancing).
pub fn balance(a: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let mut b = a.clone();
    let mut converged = false;
    while !converged {
        converged = true;
        for i in 0..n {
            let mut c = 0.0;
            let mut r = 0.0;
            for j in 0..n {
                if j != i {
                    c += b[(j, i)].abs();
                    r += b[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let mut g = r / 2.0;
            while c < g {
                f *= 2.0;
                c *= 4.0;
            }
            g = r * 2.0;
            while c >= g {
                f /= 2.0;
                c /= 4.0;
            }
            if (c + r) / f < 0.95 * s {
                converged = false;
                for j in 0..n {
                    b[(j, i)] *= f;
                    b[(i, j)] /= f;
                }
            }
        }
    }
    b
}
