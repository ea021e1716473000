//! The stationary covariance of a member's residual under process and measurement noise.
//!
//! For an observer (F, G, K, P, Q) of the sampled plant x_{k+1} = Φx_k + B_d u_k + w_k,
//! y_k = Cx_k + ν_k, the Sylvester equation
//!
//! ```text
//! M Φ − F M = K C
//! ```
//!
//! gives the state z tracks: ζ = z − Mx obeys ζ_{k+1} = Fζ_k + Kν_k − Mw_k (G = MB_d), and, the
//! observer being one (PM + QC = I), the residual on outputs S is r_k = S(−CPζ_k + (I − CQ)ν_k)
//! whatever x does. With ζ_k independent of ν_k,
//!
//! ```text
//! Σ_ζ = F Σ_ζ Fᵀ + K R Kᵀ + M Q_d Mᵀ,       Σ_r = S[CP Σ_ζ PᵀCᵀ + (I − CQ) R (I − CQ)ᵀ]Sᵀ.
//! ```

use lti::Mat;
use observer::LinearObserver;

use crate::residual::Residual;

/// M with MΦ − FM = KC, by its Kronecker form (Φᵀ ⊗ I − I ⊗ F) vec M = vec KC.
pub fn tracked(phi: &Mat, f: &Mat, k: &Mat, c: &Mat) -> Result<Mat, String> {
    let (n, r) = (phi.nrows(), f.nrows());
    let op = phi.transpose().kronecker(&Mat::identity(r, r)) - Mat::identity(n, n).kronecker(f);
    let rhs = k * c;
    let v = op
        .lu()
        .solve(&Mat::from_column_slice(r * n, 1, rhs.as_slice()))
        .ok_or("the observer shares an eigenvalue with the plant (MΦ − FM = KC has no unique solution)")?;
    Ok(Mat::from_column_slice(r, n, v.as_slice()))
}

/// Σ_r of the residual on `outputs`.
pub fn residual_covariance(
    phi: &Mat,
    c: &Mat,
    obs: &LinearObserver,
    outputs: &[usize],
    qd: &Mat,
    rn: &Mat,
) -> Result<Mat, String> {
    let Residual {
        f,
        k,
        p: pm,
        q,
        s,
        i_cq,
        cp,
    } = Residual::new(c, obs, outputs);
    let m = tracked(phi, &f, &k, c)?;
    let n = phi.nrows();
    let defect = (&pm * &m + &q * c - Mat::identity(n, n)).norm();
    if defect > 1e-8 * (1.0 + (&pm * &m).norm()) {
        return Err(format!(
            "it does not estimate the plant's state (‖PM + QC − I‖ = {defect:.1e})"
        ));
    }
    let w = &k * rn * k.transpose() + &m * qd * m.transpose();
    let sz = lti::lyapunov::discrete(&f.transpose(), &w).map_err(|e| e.to_string())?;
    let full = &cp * sz * cp.transpose() + &i_cq * rn * i_cq.transpose();
    let out = &s * full * s.transpose();
    Ok((&out + out.transpose()) * 0.5)
}
