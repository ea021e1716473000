//! A member's residual in terms of its observer. With x̂ = Pz + Qy and S selecting the member's
//! outputs,
//!
//! ```text
//! r = S(y − Cx̂) = S(I − CQ) y − SCP z,
//! ```
//!
//! and the observer's state evolves as z_{k+1} = Fz_k + Gu_k + Ky_k. The structure matrix
//! ([`crate::structure`]) and the residual's covariance ([`crate::covariance`]) are both read off
//! these matrices.

use lti::Mat;
use observer::LinearObserver;

/// The matrices of a member's residual.
#[derive(Debug, Clone)]
pub struct Residual {
    /// The observer's F.
    pub f: Mat,
    /// Its K.
    pub k: Mat,
    /// Its P.
    pub p: Mat,
    /// Its Q.
    pub q: Mat,
    /// S: the rows of the identity of the member's outputs.
    pub s: Mat,
    /// I − CQ.
    pub i_cq: Mat,
    /// CP.
    pub cp: Mat,
}

impl Residual {
    /// For observer `obs` of a plant with output matrix C, residual on `outputs`.
    pub fn new(c: &Mat, obs: &LinearObserver, outputs: &[usize]) -> Self {
        let p = c.nrows();
        let (pm, q): (Mat, Mat) = ((&obs.p).into(), (&obs.q).into());
        Residual {
            f: (&obs.f).into(),
            k: (&obs.k).into(),
            s: Mat::identity(p, p).select_rows(outputs),
            i_cq: Mat::identity(p, p) - c * &q,
            cp: c * &pm,
            p: pm,
            q,
        }
    }
}
