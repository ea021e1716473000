//! Full-order observer by the generalized inverse (seed 001, eqs. 10–17). From x = Cᵍy + h and
//! ẏ = CAh + CACᵍy + CBu (eq. 14), Luenberger's construction on the pair (A, CA) gives
//!
//! ```text
//! q̇ = (A − KCA) q + (B − KCB) u + (AK − KCAK) y,     x̂ = q + K y,      (eqs. 16–17)
//! ```
//!
//! with error ė = (A − KCA)e: it needs (A, CA) observable (true when (A, C) is observable and A
//! is non-singular, the paper's lemma).
//!
//! Sampled counterpart: with y_{k+1} − CB_du_k = CA_d x_k in place of ẏ, the estimator
//! ξ_{k+1} = A_dξ_k + B_du_k + K(y_{k+1} − CB_du_k − CA_dξ_k) and q_k = ξ_k − Ky_k give the same
//! equations with A_d, B_d: q_{k+1} = (A_d − KCA_d)q_k + (B_d − KCB_d)u_k + (A_d − KCA_d)K y_k.

use lti::pinv::rank;
use lti::{Discrete, Mat, Model};

use super::{
    Checks, DesignError, Designed, Domain, Gain, Pair, Report, eig, free_gain, require_stable,
    sampled_report,
};
use crate::runtime::LinearObserver;

const KIND: &str = "gi-full-order";

fn core(
    a: &Mat,
    c: &Mat,
    gain: &Gain,
    carried: &[lti::C64],
    domain: Domain,
    checks: &mut Checks,
) -> Result<(Mat, Mat, Vec<lti::C64>), DesignError> {
    let ca = c * a;
    // The pair's output is CA·x = ẏ − CBu (or y_{k+1} − CB_du_k): an R given for y weights it.
    let (k, fixed) = free_gain(
        checks,
        &Pair::full(a, &ca, "(A, CA)"),
        gain,
        carried,
        domain,
    )?;
    let f = a - &k * &ca;
    require_stable(checks, "F = A − KCA stable", &eig(&f), domain)?;
    Ok((k, f, fixed))
}

pub(super) fn design(
    model: Option<&Model>,
    dm: &Discrete,
    gain: &Gain,
) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let mut checks = Checks::new(KIND);
    let n = dm.a.nrows();
    let continuous = match model.filter(|_| !gain.is_lqe()) {
        Some(model) => Some(core(
            &model.a,
            &model.c,
            gain,
            &[],
            Domain::Continuous,
            &mut checks,
        )?),
        None => None,
    };
    let carried = continuous.as_ref().map(|c| c.2.clone()).unwrap_or_default();
    let mut sampled = Checks::sampled(KIND, dt);
    let (kd, fd, fixed_d) = core(
        &dm.a,
        &dm.c,
        gain,
        &carried,
        Domain::Discrete(dt),
        &mut sampled,
    )?;
    let g = &dm.b - &kd * &dm.c * &dm.b;
    let ky = &fd * &kd;
    let runtime = LinearObserver::new(&fd, &g, &ky, &Mat::identity(n, n), &kd);
    // The paper's lemma: (A, C) observable and A non-singular imply (A, CA) observable.
    let notes = model
        .map(|m| {
            let ra = rank(&m.a);
            format!(
                "rank(A) = {ra} of {n}{}",
                if ra == n {
                    " (A non-singular)"
                } else {
                    " (A singular: (A, CA) checked directly)"
                }
            )
        })
        .into_iter()
        .collect();
    let report = match continuous {
        Some((k, f, fixed)) => Report {
            kind: KIND,
            conditions: checks.into_list(),
            poles: eig(&f),
            discrete_poles: eig(&fd),
            fixed_modes: fixed,
            matrices: vec![("K".into(), k), ("F".into(), f)],
            notes,
            sampled_only: false,
        },
        None => sampled_report(
            KIND,
            sampled,
            &fd,
            fixed_d,
            vec![("K".into(), kd.clone()), ("F".into(), fd.clone())],
            notes,
            dt,
        ),
    };
    Ok(Designed {
        report,
        runtime,
        what: None,
    })
}
