//! Das & Ghosal's reduced-order observer (1981) and its unknown-input form (seed 000,
//! eqs. 14–23). With Cᵍ the Moore–Penrose inverse and L a basis of ker C with LLᵍ = I − CᵍC
//! (eq. 11), every state is x = Cᵍy + Lh (eq. 14) and
//!
//! ```text
//! q̇ = (LᵍAL − KCAL) q + [(LᵍAL − KCAL)K + LᵍACᵍ − KCACᵍ] y + (LᵍB − KCB) u     (eq. 23)
//! x̂ = L q + (Cᵍ + LK) y                                                         (eq. 19)
//! ```
//!
//! with error dynamics F = LᵍAL − KCAL, of order n − rank C. The unknown input enters the error
//! through LᵍE_d − KCE_d (eq. 17); it vanishes for
//!
//! ```text
//! K = (LᵍE_d)(CE_d)ᵍ + H (I − CE_d(CE_d)ᵍ)                                       (eq. 22)
//! ```
//!
//! which exists iff LᵍE_d − LᵍE_d(CE_d)ᵍ(CE_d) = 0 (eq. 21 as corrected: the printed operand
//! order does not conform). H is free: given, or chosen here so that F has the requested poles,
//! F = (LᵍAL − K₀CAL) − H·ΠCAL with K₀ = (LᵍE_d)(CE_d)ᵍ, Π = I − CE_d(CE_d)ᵍ.
//!
//! L is the orthonormal basis [`lti::subspace::kernel_basis`]: n − rank C columns for any C
//! (the dimension from the SVD's rank rule), the coordinate vectors the paper picks where ker C
//! is spanned by them (C = [I 0] → L = [0; I]), and Lᵍ = Lᵀ. (The paper's "independent columns of
//! I − CᵍC", picked one at a time with a rank test, gave L too many columns on general C when
//! two columns agreed to rounding: a rank-deficient L and a silently divergent observer.)
//!
//! Sampled counterpart: x_{k+1} = A_d x_k + …, y_{k+1} − CA_dCᵍy_k − CB_du_k = CA_dLh_k + CE_dw_k
//! plays the role of ẏ, and the same equations hold with (A_d, B_d, E_d): q_{k+1} = F_d q_k + …,
//! x̂_k = Lq_k + (Cᵍ + LK_d)y_k.

use lti::pinv::pinv;
use lti::subspace::kernel_basis;
use lti::{C64, Discrete, Mat, Model};

use super::{
    Checks, DesignError, Designed, Domain, Gain, Pair, Report, eig, free_gain, require_stable,
    sampled_report,
};
use crate::runtime::LinearObserver;
use lti::linalg::norm::one_norm as norm1;

/// How K is chosen.
#[derive(Debug, Clone)]
pub(super) enum Free {
    /// Placed poles or an LQE gain on the error pair.
    Gain(Gain),
    /// The UIO's free matrix H of eq. 22.
    H(Mat),
}

/// The design in one domain.
pub(super) struct Core {
    pub cg: Mat,
    pub l: Mat,
    pub lg: Mat,
    pub k: Mat,
    pub f: Mat,
    /// y-gain of eq. 23: FK + LᵍACᵍ − KCACᵍ.
    pub ky: Mat,
    /// u-gain of eq. 23: LᵍB − KCB.
    pub ku: Mat,
    pub fixed: Vec<C64>,
    pub notes: Vec<String>,
}

// one job: Das & Ghosal's reduced-order design in the paper's order (the basis, the existence
// conditions, the gain, eq. 23's matrices), each step using the last.
#[allow(clippy::too_many_arguments)]
pub(super) fn core(
    a: &Mat,
    b: &Mat,
    c: &Mat,
    e: &Mat,
    gain: &Free,
    uio: bool,
    carried: &[C64],
    domain: Domain,
    checks: &mut Checks,
) -> Result<Core, DesignError> {
    let cg = pinv(c);
    let l = kernel_basis(c);
    let lg = l.transpose(); // L orthonormal: Lᵍ = Lᵀ
    let r = l.ncols();
    let lgal = &lg * a * &l;
    // The size of the data the reduced pairs are products of: their rank decisions are made
    // against it (CAL is rounding of ‖C‖‖A‖ along a mode no sensor sees).
    let data_scale = norm1(a) * norm1(&l) * norm1(c).max(1.0);
    let cal = c * a * &l;
    let mut notes = Vec::new();
    let (k, fixed) = if uio {
        let ced = c * e;
        let ced_g = pinv(&ced);
        let lge = &lg * e;
        let res21 = &lge - &lge * &ced_g * &ced;
        // Relative to the data: ‖LᵍE_d‖ ≤ ‖E_d‖ for an orthonormal L, so the scale is E_d's own
        // (a scale from Lᵍ let a residual of 1.6e-2 pass as 1e-15 of a 1e13 Lᵍ).
        let scale = e.amax();
        let tol = 1e-10 * scale;
        checks.require(
            "LgEd − LgEd(CEd)g(CEd) = 0 (eq. 21)",
            res21.amax() <= tol,
            format!(
                "max |residual| = {:.3e} (tolerance 1e-10·max|Ed| = {:.3e})",
                res21.amax(),
                tol
            ),
        )?;
        let k0 = &lge * &ced_g;
        let pi = Mat::identity(c.nrows(), c.nrows()) - &ced * &ced_g;
        let (h, fixed) = match gain {
            Free::H(h) => {
                if h.shape() != (r, c.nrows()) {
                    return Err(checks.error(
                        "H",
                        format!(
                            "is {}×{}, must be {}×{}",
                            h.nrows(),
                            h.ncols(),
                            r,
                            c.nrows()
                        ),
                    ));
                }
                (h.clone(), Vec::new())
            }
            Free::Gain(g @ Gain::Place { .. }) => {
                let at = &lgal - &k0 * &cal;
                let ct = &pi * &cal;
                notes.push("H placed on the pair (LgAL − K0·CAL, Π·CAL)".to_string());
                let pair = Pair {
                    a: &at,
                    c: &ct,
                    name: "(LgAL − K0CAL, ΠCAL)",
                    scale: data_scale * (1.0 + norm1(&k0)),
                    state_map: Some(&lg),
                    output_map: None,
                };
                free_gain(checks, &pair, g, carried, domain)?
            }
            Free::Gain(g @ Gain::Lqe(_)) => {
                // Π = UUᵀ (an orthogonal projector): the DARE needs independent outputs, so the
                // pair's output is UᵀCAL, and H = H̃Uᵀ gives HΠ = H̃Uᵀ as placement's H does.
                let at = &lgal - &k0 * &cal;
                // U from the SVD of CE_d itself (its left null space), not from the projector's
                // SVD: Π's eigenvalues are 0 and 1 to rounding, and a basis read off it can
                // be off by degrees or gain a spurious column.
                let ut = lti::subspace::left_null_space(&ced);
                let ct = &ut * &cal;
                notes.push(
                    "H from the DARE of the pair (LgAL − K0·CAL, Uᵀ·CAL), Π = UUᵀ".to_string(),
                );
                let pair = Pair {
                    a: &at,
                    c: &ct,
                    name: "(LgAL − K0CAL, UᵀCAL)",
                    scale: data_scale * (1.0 + norm1(&k0)),
                    state_map: Some(&lg),
                    output_map: Some(&ut),
                };
                let (ht, fixed) = free_gain(checks, &pair, g, carried, domain)?;
                (ht * &ut, fixed)
            }
        };
        let k = k0 + h * pi;
        let res20 = &lge - &k * &ced;
        checks.require(
            "LgEd − KCEd = 0 (eq. 20)",
            res20.amax() <= tol,
            format!(
                "max |residual| = {:.3e} (tolerance 1e-10·max|Ed| = {:.3e})",
                res20.amax(),
                tol
            ),
        )?;
        (k, fixed)
    } else {
        match gain {
            Free::Gain(g) => {
                let pair = Pair {
                    a: &lgal,
                    c: &cal,
                    name: "(LgAL, CAL)",
                    scale: data_scale,
                    state_map: Some(&lg),
                    output_map: None,
                };
                free_gain(checks, &pair, g, carried, domain)?
            }
            Free::H(_) => return Err(checks.error("H", "only the unknown-input form takes H")),
        }
    };
    let f = &lgal - &k * &cal;
    require_stable(checks, "F = LgAL − KCAL stable", &eig(&f), domain)?;
    let ky = &f * &k + &lg * a * &cg - &k * c * a * &cg;
    let ku = &lg * b - &k * c * b;
    Ok(Core {
        cg,
        l,
        lg,
        k,
        f,
        ky,
        ku,
        fixed,
        notes,
    })
}

pub(super) fn design(
    model: Option<&Model>,
    dm: &Discrete,
    gain: Free,
    uio: bool,
) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let kind = if uio { "das-ghosal-uio" } else { "das-ghosal" };
    let mut checks = Checks::new(kind);
    let lqe = matches!(&gain, Free::Gain(g) if g.is_lqe());
    let ct = match model.filter(|_| !lqe) {
        Some(model) => Some(core(
            &model.a,
            &model.b,
            &model.c,
            &model.e,
            &gain,
            uio,
            &[],
            Domain::Continuous,
            &mut checks,
        )?),
        None => None,
    };
    let carried = ct.as_ref().map(|c| c.fixed.clone()).unwrap_or_default();
    let mut sampled = Checks::sampled(kind, dt);
    let d = core(
        &dm.a,
        &dm.b,
        &dm.c,
        &dm.e,
        &gain,
        uio,
        &carried,
        Domain::Discrete(dt),
        &mut sampled,
    )?;
    let q = &d.cg + &d.l * &d.k;
    let runtime = LinearObserver::new(&d.f, &d.ku, &d.ky, &d.l, &q);
    let matrices = |c: &Core| {
        vec![
            ("L".into(), c.l.clone()),
            ("Lg".into(), c.lg.clone()),
            ("K".into(), c.k.clone()),
            ("F".into(), c.f.clone()),
        ]
    };
    let report = match ct {
        Some(ct) => {
            let mut notes = ct.notes.clone();
            if let Free::H(_) = gain {
                notes.push("H given: the sampled observer uses the same H, so its poles are close to, not equal to, e^{p·dt}".into());
            }
            Report {
                kind,
                conditions: checks.into_list(),
                poles: eig(&ct.f),
                discrete_poles: eig(&d.f),
                matrices: matrices(&ct),
                fixed_modes: ct.fixed,
                notes,
                sampled_only: false,
            }
        }
        None => sampled_report(
            kind,
            sampled,
            &d.f,
            d.fixed.clone(),
            matrices(&d),
            d.notes.clone(),
            dt,
        ),
    };
    Ok(Designed {
        report,
        runtime,
        what: None,
    })
}
