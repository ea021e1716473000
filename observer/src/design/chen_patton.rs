//! Chen & Patton's unknown-input decoupling observer (seed 002, eqs. 2–8):
//!
//! ```text
//! ż = F z + T B u + K y,   x̂ = z + H y,
//! H = E (CE)⁺,  T = I − HC,  F = TA − K₁C,  K₂ = F H,  K = K₁ + K₂.
//! ```
//!
//! With these, ė = F e whatever w is (E − HCE = 0 kills it). It exists iff rank CE = rank E and
//! (TA, C) is detectable; the unobservable modes of (TA, C) are the invariant zeros of (A, E, C)
//! and stay in F. K₁ places the observable part (staircase) and the fixed modes are reported.
//!
//! Sampled counterpart: the same formulas on (A_d, B_d, E_d) with poles e^{p·dt}; then
//! T_d E_d = 0 exactly, so a disturbance held over each step is rejected at every sample.

use lti::eig::format_list;
use lti::pinv::rank;
use lti::zeros::decoupling;
use lti::{C64, Discrete, Mat, Model};

use super::{
    Checks, DesignError, Designed, Domain, Gain, Pair, Report, eig, eq_detail, free_gain,
    refuse_unseen, require_stable, sampled_report,
};
use crate::runtime::LinearObserver;

const KIND: &str = "chen-patton-uio";

/// H, T, K₁, K₂, F for one domain.
pub(super) struct Core {
    pub h: Mat,
    pub t: Mat,
    pub k1: Mat,
    pub k2: Mat,
    pub f: Mat,
    pub fixed: Vec<C64>,
}

#[allow(clippy::too_many_arguments)]
pub(super) fn core(
    a: &Mat,
    c: &Mat,
    e: &Mat,
    gain: &Gain,
    carried: &[C64],
    domain: Domain,
    checks: &mut Checks,
) -> Result<Core, DesignError> {
    let n = a.nrows();
    let ce = c * e;
    let (r_ce, r_e) = (rank(&ce), rank(e));
    checks.require("rank(CE) = rank(E)", r_ce == r_e, eq_detail(r_ce, r_e))?;
    let zeros = decoupling(a, e, c, &Mat::zeros(c.nrows(), 0))
        .map_err(|err| checks.error("invariant zeros", err.to_string()))?;
    let unstable: Vec<C64> = zeros
        .zeros
        .iter()
        .copied()
        .filter(|&z| !domain.stable(z))
        .collect();
    checks.require(
        "invariant zeros of (A, E, C) stable",
        unstable.is_empty(),
        if zeros.zeros.is_empty() {
            "none".to_string()
        } else if unstable.is_empty() {
            format!("{var} = {}", format_list(&zeros.zeros), var = if domain == Domain::Continuous { "s" } else { "z" })
        } else {
            format!(
                "unstable zero(s) {var} = {z}: (TA, C) is not detectable — its unobservable mode(s) {var} = {z} stay in F = TA − K1C whatever K1 is{no_sensor}",
                z = format_list(&unstable),
                var = if domain == Domain::Continuous { "s" } else { "z" },
                no_sensor = " (no sensor sees them: no observer can estimate them)"
            )
        },
    )?;
    // H = E(CE)⁺, refined once so that HCE = E holds to ~ε (`lti::pinv::right_solve`).
    let h = lti::pinv::right_solve(e, &ce);
    let t = Mat::identity(n, n) - &h * c;
    let ta = &t * a;
    // The staircase behind the zeros decides rank over up to n stages; on the real models
    // (IEEE 39, WECC) it passed modes at z = 1 no sensor sees. The PBH test at the eigenvalues
    // on or outside the boundary is decisive, and names the states that carry them. (An LQE
    // gain's own path makes the same test on the same pair: once is enough — 1.2 s of a
    // 1000-state design.)
    if !gain.is_lqe() {
        refuse_unseen(checks, &ta, c, "(TA, C)", domain, true)?;
    }
    let (k1, fixed) = free_gain(
        checks,
        &Pair::full(&ta, c, "(TA, C)"),
        gain,
        carried,
        domain,
    )?;
    let f = &ta - &k1 * c;
    require_stable(checks, "F = TA − K1C stable", &eig(&f), domain)?;
    let k2 = &f * &h;
    Ok(Core {
        h,
        t,
        k1,
        k2,
        f,
        fixed,
    })
}

pub(super) fn design(
    model: Option<&Model>,
    dm: &Discrete,
    gain: &Gain,
) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let mut checks = Checks::new(KIND);
    let ct = match model.filter(|_| !gain.is_lqe()) {
        Some(model) => Some(core(
            &model.a,
            &model.c,
            &model.e,
            gain,
            &[],
            Domain::Continuous,
            &mut checks,
        )?),
        None => None,
    };
    let carried = ct.as_ref().map(|c| c.fixed.clone()).unwrap_or_default();
    let mut sampled = Checks::sampled(KIND, dt);
    let d = core(
        &dm.a,
        &dm.c,
        &dm.e,
        gain,
        &carried,
        Domain::Discrete(dt),
        &mut sampled,
    )?;
    let n = dm.a.nrows();
    let runtime = LinearObserver::new(
        &d.f,
        &(&d.t * &dm.b),
        &(&d.k1 + &d.k2),
        &Mat::identity(n, n),
        &d.h,
    );
    let matrices = |c: &Core| {
        vec![
            ("H".into(), c.h.clone()),
            ("T".into(), c.t.clone()),
            ("K1".into(), c.k1.clone()),
            ("K2".into(), c.k2.clone()),
            ("F".into(), c.f.clone()),
        ]
    };
    let report = match ct {
        Some(ct) => Report {
            kind: KIND,
            conditions: checks.into_list(),
            poles: eig(&ct.f),
            discrete_poles: eig(&d.f),
            matrices: matrices(&ct),
            fixed_modes: ct.fixed,
            notes: vec![],
            sampled_only: false,
        },
        None => sampled_report(
            KIND,
            sampled,
            &d.f,
            d.fixed.clone(),
            matrices(&d),
            vec![],
            dt,
        ),
    };
    Ok(Designed {
        report,
        runtime,
        what: None,
    })
}
