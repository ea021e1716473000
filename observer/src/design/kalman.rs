//! The steady-state discrete Kalman filter of the exact sampled plant (Kalman 1960; Anderson &
//! Moore, "Optimal Filtering", 1979, ch. 4), the baseline a control engineer reaches for:
//!
//! ```text
//! x_{k+1} = Φ x_k + B_d u_k + w_k,  y_k = C x_k + ν_k,   cov w = Q_d,  cov ν = R,
//! P = ΦPΦᵀ − ΦPCᵀ(CPCᵀ + R)⁻¹CPΦᵀ + Q_d,       M = PCᵀ(CPCᵀ + R)⁻¹,
//! x̂_{k|k} = x̂_{k|k−1} + M (y_k − C x̂_{k|k−1}),   x̂_{k+1|k} = Φ x̂_{k|k} + B_d u_k.
//! ```
//!
//! With z_k = x̂_{k|k−1} this is the runtime form z_{k+1} = Φ(I − MC) z + B_d u + ΦM y,
//! x̂_k = (I − MC) z + M y: the filtered estimate. The unknown inputs w(t) of the scenario are
//! not modelled (they are what the unknown-input observers reject and the filter does not).
//! There is no continuous design: the report's poles are ln(z)/dt of the filter's.

use lti::{Discrete, Mat, steady_state_kalman};

use super::{Checks, DesignError, Designed, Domain, Report, eig, require_stable};
use crate::runtime::LinearObserver;

const KIND: &str = "kalman";

pub(super) fn design(dm: &Discrete, qd: &Mat, r: &Mat) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let mut checks = Checks::sampled(KIND, dt);
    // A mode no sensor sees on or outside the unit circle: named, before the Riccati iteration
    // fails on it (WECC: "the Stein operator is singular").
    super::refuse_unseen(
        &mut checks,
        &dm.a,
        &dm.c,
        "(Φ, C)",
        Domain::Discrete(dt),
        true,
    )?;
    let kf = steady_state_kalman(&dm.a, &dm.c, qd, r).map_err(|e| {
        checks.error(
            "DARE(Φᵀ, Cᵀ, Q_d, R) has a stabilising solution",
            e.to_string(),
        )
    })?;
    let n = dm.a.nrows();
    let p_upd = Mat::identity(n, n) - &kf.gain * &dm.c;
    let f = &dm.a * &p_upd;
    let discrete = eig(&f);
    require_stable(
        &mut checks,
        "Φ(I − MC) stable",
        &discrete,
        Domain::Discrete(dt),
    )?;
    let (continuous, _) = lti::eig::continuous_image(&discrete, dt);
    let runtime = LinearObserver::new(&f, &dm.b, &kf.predictor_gain, &p_upd, &kf.gain);
    Ok(Designed {
        report: Report {
            kind: KIND,
            conditions: checks.into_list(),
            matrices: vec![
                ("M".into(), kf.gain.clone()),
                ("P".into(), kf.p.clone()),
                ("S".into(), kf.innovation.clone()),
            ],
            poles: continuous,
            discrete_poles: discrete,
            fixed_modes: vec![],
            sampled_only: true,
            notes: vec![format!("ρ(Φ(I − MC)) = {:.6}", kf.radius)],
        },
        runtime,
        what: None,
    })
}
