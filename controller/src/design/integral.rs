//! Integral action on the tracked outputs z = C_t x (Franklin, Powell & Emami-Naeini, §7.10,
//! in its sampled form). The controller integrates the tracking error of its estimate,
//!
//! ```text
//! ξ_{k+1} = ξ_k + dt (r_k − C_t x̂_k),      u_k = −G_x x̂_k − G_ξ ξ_k,
//! ```
//!
//! and [G_x, G_ξ] is designed on the augmented sampled plant
//!
//! ```text
//! [x; ξ]_{k+1} = [[Φ, 0], [−dt C_t, I]] [x; ξ]_k + [Γ_B; 0] u_k + [0; dt I] r_k.
//! ```
//!
//! In a stable loop ξ settles, so z = r in steady state. When the tracked outputs are measured
//! (C_t = MC, [`measured`]) the controller integrates r − My: a step reference or a step unknown
//! input then leaves no steady-state error in z whatever the observer's bias. Otherwise it
//! integrates r − C_t x̂, exact when x̂ → x (an unknown-input observer under w). The augmented
//! pair is controllable iff (Φ, Γ_B) is and the plant from u to z has no zero at z = 1
//! (rank [[Φ − I, Γ_B], [C_t, 0]] = n + l): otherwise placement refuses it.

use lti::pinv::pinv;
use lti::{Discrete, Mat, Model};

/// M with C_t = MC when every tracked output is a combination of the measured ones (to 1e-10 of
/// ‖C_t‖), else `None`.
pub fn measured(ct: &Mat, c: &Mat) -> Option<Mat> {
    let m = ct * pinv(c);
    let off = (ct - &m * c).norm();
    (off <= 1e-10 * ct.norm().max(f64::MIN_POSITIVE)).then_some(m)
}

/// (Φ_a, Γ_a) of the module documentation.
pub fn augment_sampled(dm: &Discrete, ct: &Mat) -> (Mat, Mat) {
    let (n, l) = (dm.a.nrows(), ct.nrows());
    let mut phi = Mat::identity(n + l, n + l);
    phi.view_mut((0, 0), (n, n)).copy_from(&dm.a);
    phi.view_mut((n, 0), (l, n)).copy_from(&(ct * -dm.dt));
    let mut gamma = Mat::zeros(n + l, dm.b.ncols());
    gamma.view_mut((0, 0), (n, dm.b.ncols())).copy_from(&dm.b);
    (phi, gamma)
}

/// (A_a, B_a) = ([[A, 0], [−C_t, 0]], [B; 0]): the continuous integrator ξ̇ = r − C_t x, for
/// placement in continuous time.
pub fn augment_continuous(m: &Model, ct: &Mat) -> (Mat, Mat) {
    let (n, l) = (m.n(), ct.nrows());
    let mut a = Mat::zeros(n + l, n + l);
    a.view_mut((0, 0), (n, n)).copy_from(&m.a);
    a.view_mut((n, 0), (l, n)).copy_from(&(-ct));
    let mut b = Mat::zeros(n + l, m.l());
    b.view_mut((0, 0), (n, m.l())).copy_from(&m.b);
    (a, b)
}
