//! Cumming's reduced-order observer (1969; seed 003 eqs. 7–14). H completes C to an invertible
//! [C; H], and [E F] = [C; H]⁻¹ gives x = Ey + Fz with z = Hx. Then
//!
//! ```text
//! q̇ = (HAF − KCAF) q + (HAFK + HAE − KCAFK − KCAE) y + (HB − KCB) u     (eq. 12)
//! x̂ = F q + (E + FK) y                                                   (eq. 14)
//! ```
//!
//! with error ė = (HAF − KCAF)e; it needs (HAF, CAF) observable. By default H = Lᵀ with L the
//! Das–Ghosal basis of ker C (orthonormal, [`lti::subspace::kernel_basis`]): then [C; Lᵀ] is
//! invertible for every full-row-rank C, with E = Cᵍ, F = L, and the two observers coincide, as
//! the seed-003 paper concludes for C = [I 0].
//!
//! Sampled counterpart: the same equations with A_d, B_d (as for Das–Ghosal).

use lti::pinv::rank;
use lti::{C64, Discrete, Mat, Model};

use super::{
    Checks, DesignError, Designed, Domain, Gain, Pair, Report, eig, eq_detail, free_gain,
    require_stable, sampled_report,
};
use crate::runtime::LinearObserver;
use lti::linalg::norm::one_norm as norm1;
use lti::subspace::kernel_basis;

const KIND: &str = "cumming";

struct Core {
    e: Mat,
    f: Mat,
    k: Mat,
    fo: Mat,
    ky: Mat,
    ku: Mat,
    fixed: Vec<C64>,
}

#[allow(clippy::too_many_arguments)]
fn core(
    a: &Mat,
    b: &Mat,
    c: &Mat,
    h: &Mat,
    gain: &Gain,
    carried: &[C64],
    domain: Domain,
    checks: &mut Checks,
) -> Result<Core, DesignError> {
    let n = a.nrows();
    let p = c.nrows();
    let mut ch = Mat::zeros(n, n);
    ch.rows_mut(0, p).copy_from(c);
    ch.rows_mut(p, n - p).copy_from(h);
    let r = rank(&ch);
    checks.require(
        "[C; H] invertible",
        r == n,
        format!("rank {}", eq_detail(r, n)),
    )?;
    let inv = ch
        .try_inverse()
        .ok_or_else(|| checks.error("[C; H] invertible", "singular"))?;
    let e = inv.columns(0, p).into_owned();
    let f = inv.columns(p, n - p).into_owned();
    let haf = h * a * &f;
    let caf = c * a * &f;
    // The pair's state is z = Hx; its output CAF·z is the part of ẏ (y_{k+1}) that z drives.
    let pair = Pair {
        a: &haf,
        c: &caf,
        name: "(HAF, CAF)",
        scale: norm1(a) * norm1(h).max(norm1(c)) * norm1(&f),
        state_map: Some(h),
        output_map: None,
    };
    let (k, fixed) = free_gain(checks, &pair, gain, carried, domain)?;
    let fo = &haf - &k * &caf;
    require_stable(checks, "HAF − KCAF stable", &eig(&fo), domain)?;
    let ky = &fo * &k + h * a * &e - &k * c * a * &e;
    let ku = h * b - &k * c * b;
    Ok(Core {
        e,
        f,
        k,
        fo,
        ky,
        ku,
        fixed,
    })
}

pub(super) fn design(
    model: Option<&Model>,
    dm: &Discrete,
    gain: &Gain,
    h: Option<&Mat>,
) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let mut checks = Checks::new(KIND);
    let (n, p) = (dm.a.nrows(), dm.c.nrows());
    let h = match h {
        Some(h) if h.shape() != (n - p, n) => {
            return Err(checks.error(
                "H",
                format!("is {}×{}, must be {}×{}", h.nrows(), h.ncols(), n - p, n),
            ));
        }
        Some(h) => h.clone(),
        None => kernel_basis(&dm.c).transpose(),
    };
    if h.nrows() != n - p {
        let r = n - h.nrows();
        return Err(checks.error(
            "C",
            format!("must have full row rank {p} for Cumming's observer (rank C = {r})"),
        ));
    }
    let ct = match model.filter(|_| !gain.is_lqe()) {
        Some(model) => Some(core(
            &model.a,
            &model.b,
            &model.c,
            &h,
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
        &dm.b,
        &dm.c,
        &h,
        gain,
        &carried,
        Domain::Discrete(dt),
        &mut sampled,
    )?;
    let q = &d.e + &d.f * &d.k;
    let runtime = LinearObserver::new(&d.fo, &d.ku, &d.ky, &d.f, &q);
    let matrices = |c: &Core| {
        vec![
            ("H".into(), h.clone()),
            ("E".into(), c.e.clone()),
            ("F".into(), c.f.clone()),
            ("K".into(), c.k.clone()),
            ("HAF-KCAF".into(), c.fo.clone()),
        ]
    };
    let report = match ct {
        Some(ct) => Report {
            kind: KIND,
            conditions: checks.into_list(),
            poles: eig(&ct.fo),
            discrete_poles: eig(&d.fo),
            matrices: matrices(&ct),
            fixed_modes: ct.fixed,
            notes: vec![],
            sampled_only: false,
        },
        None => sampled_report(
            KIND,
            sampled,
            &d.fo,
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
