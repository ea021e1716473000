//! How an observer family's free gain is chosen: by pole placement, or as the steady-state
//! Kalman (LQE) gain of the family's own sampled error pair.
//!
//! Every family ends its design with an error recursion e⁺ = (Φ₁ − K C₁) e on a pair (Φ₁, C₁)
//! it forms itself — (Φ, C) for Luenberger, (T_dΦ, C) for Chen–Patton, (LᵍΦL, CΦL) for
//! Das–Ghosal … With `gain = "lqe"` the gain is the one-step predictor gain of that pair
//! (Anderson & Moore, "Optimal Filtering", 1979, ch. 4):
//!
//! ```text
//! P = Φ₁PΦ₁ᵀ − Φ₁PC₁ᵀ(C₁PC₁ᵀ + R)⁻¹C₁PΦ₁ᵀ + Q     (DARE(Φ₁ᵀ, C₁ᵀ, Q, R), scipy's solve_discrete_are)
//! K = Φ₁PC₁ᵀ(C₁PC₁ᵀ + R)⁻¹,        ρ(Φ₁ − KC₁) < 1.
//! ```
//!
//! It exists iff (Φ₁, C₁) is detectable and (Φ₁, Q) has no unobservable mode on the unit circle;
//! the unobservable modes of the pair (for a UIO, the invariant zeros) stay in Φ₁ − KC₁ as they
//! do under placement. Nothing is placed, so the design scales with the model (O(n³) per
//! doubling step) where placing hundreds of poles with few outputs is ill-posed.
//!
//! Weights: a weight given for the plant — Q n×n, R p×p, from the observer's keys or from the
//! scenario's `[noise]` — is carried to a pair whose state is T x and whose output is M y as
//! T Q Tᵀ and M R Mᵀ; one given at the pair's size is used as it is. Without one, Q and R are the
//! plant's identities carried the same way, T Tᵀ and M Mᵀ, so the default does not depend on the
//! basis a family picks for its pair (for the orthonormal bases of Das–Ghosal's L and the
//! DG-UIO's U they are identities; for Cumming's observer with a given H, H Hᵀ).

use lti::eig::continuous_image;
use lti::eig::{format_list, sig};
use lti::place::Method;
use lti::staircase::{observability_staircase_at, observable_by_rank_at};
use lti::{C64, Mat, Poles, steady_state_kalman};

use super::{Checks, DesignError, Domain, place_detectable};

/// The free gain of an observer family.
#[derive(Debug, Clone, PartialEq)]
pub enum Gain {
    /// Place the error dynamics at these continuous poles (the sampled design at e^{p·dt}).
    Place { poles: Poles, method: Method },
    /// The steady-state Kalman gain of the family's sampled error pair.
    Lqe(Weights),
}

/// LQE weights as given: `None` takes the identity of the pair's size.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Weights {
    /// Process weight: the pair's order, or n×n for the plant's state.
    pub q: Option<Mat>,
    /// Measurement weight: the pair's output count, or p×p for the plant's outputs.
    pub r: Option<Mat>,
}

impl Gain {
    /// Placement at `poles` with `method`.
    pub fn place(poles: Poles, method: Method) -> Self {
        Gain::Place { poles, method }
    }

    /// True for `gain = "lqe"`.
    pub fn is_lqe(&self) -> bool {
        matches!(self, Gain::Lqe(_))
    }
}

/// The error pair (Φ₁, C₁) a family forms, and how the plant's state and outputs map onto it.
pub(crate) struct Pair<'a> {
    pub a: &'a Mat,
    pub c: &'a Mat,
    /// As the papers write it, e.g. "(TA, C)".
    pub name: &'a str,
    /// T with pair state = T x; `None` when the pair's state is x itself.
    pub state_map: Option<&'a Mat>,
    /// The size (1-norm) of the data the pair was formed from, 0 when it is the plant's own:
    /// rank decisions on the pair are made against it (a reduced pair's output CΦL is rounding
    /// of ‖C‖‖Φ‖ where a mode no sensor sees makes it exactly zero).
    pub scale: f64,
    /// M with pair output = M y; `None` when it is y itself.
    pub output_map: Option<&'a Mat>,
}

impl<'a> Pair<'a> {
    /// A pair on the plant's own state and outputs.
    pub fn full(a: &'a Mat, c: &'a Mat, name: &'a str) -> Self {
        Pair {
            a,
            c,
            name,
            scale: 0.0,
            state_map: None,
            output_map: None,
        }
    }
}

/// The gain K of e⁺ = (Φ₁ − KC₁)e (or ė = (A₁ − KC₁)e when placing in continuous time) and the
/// modes it leaves fixed. `carried` are the continuous design's fixed modes (placement only).
/// LQE gains exist only for the sampled pair: the families skip their continuous design then.
pub(crate) fn free_gain(
    checks: &mut Checks,
    pair: &Pair,
    gain: &Gain,
    carried: &[C64],
    domain: Domain,
) -> Result<(Mat, Vec<C64>), DesignError> {
    match (gain, domain) {
        (Gain::Place { poles, method }, _) => place_detectable(
            checks,
            pair.a,
            pair.c,
            pair.scale,
            poles,
            carried,
            *method,
            pair.name,
            domain,
            pair.state_map.is_none(),
        ),
        (Gain::Lqe(w), Domain::Discrete(dt)) => lqe(checks, pair, w, dt),
        (Gain::Lqe(_), Domain::Continuous) => Err(checks.error(
            "gain",
            "an LQE gain is designed on the sampled pair only (a design bug)",
        )),
    }
}

fn lqe(
    checks: &mut Checks,
    pair: &Pair,
    w: &Weights,
    dt: f64,
) -> Result<(Mat, Vec<C64>), DesignError> {
    let (m, k) = (pair.a.nrows(), pair.c.nrows());
    let q = weight(
        checks,
        "Q",
        w.q.as_ref(),
        m,
        pair.state_map,
        "the pair's order",
    )?;
    let r = weight(
        checks,
        "R",
        w.r.as_ref(),
        k,
        pair.output_map,
        "the pair's output count",
    )?;
    let observable = k > 0 && observable_by_rank_at(pair.a, pair.c, pair.scale);
    // Modes no output sees on or outside the circle, by the PBH test (which the staircase's
    // accumulated rank decisions can miss on large models: IEEE 39's and WECC's modes at z = 1),
    // named with their states instead of the staircase's eigenvalues or the Riccati iteration's
    // "did not converge" — asked only where one of those says something is unstable.
    let unseen = |checks: &mut Checks| {
        super::refuse_unseen(
            checks,
            pair.a,
            pair.c,
            pair.name,
            Domain::Discrete(dt),
            pair.state_map.is_none(),
        )
    };
    let fixed = if k == 0 {
        lti::eig::eigenvalues(pair.a).unwrap_or_default()
    } else if !observable {
        let fixed = observability_staircase_at(pair.a, pair.c, pair.scale)
            .unobservable_modes()
            .map_err(|e| checks.error(pair.name, e.to_string()))?;
        if fixed.iter().any(|&z| !Domain::Discrete(dt).stable(z)) {
            unseen(checks)?;
        }
        fixed
    } else {
        Vec::new()
    };
    // The modes no gain moves must be stable before a Riccati equation is asked: it has no
    // stabilising solution otherwise, and the cause is structural, not a convergence failure.
    if m > 0 && (k == 0 || !fixed.is_empty()) {
        let unstable: Vec<C64> = fixed
            .iter()
            .copied()
            .filter(|&z| !Domain::Discrete(dt).stable(z))
            .collect();
        checks.require(
            &format!("{} detectable", pair.name),
            unstable.is_empty(),
            if unstable.is_empty() {
                format!("unobservable modes z = {} (s = {}) inside the unit circle", format_list(&fixed), format_list(&continuous_image(&fixed, dt).0))
            } else {
                format!(
                    "unobservable mode(s) z = {} (s = {}) not inside the unit circle: no sensor sees them, no observer gain can move them",
                    format_list(&unstable),
                    format_list(&continuous_image(&unstable, dt).0)
                )
            },
        )?;
    }
    let gain = if k == 0 {
        Mat::zeros(m, 0)
    } else {
        let solved = steady_state_kalman(pair.a, pair.c, &q, &r);
        // Unseen modes are closed-loop eigenvalues no gain moves, so a DARE whose closed loop
        // is stable by the domain's rule has none: the PBH test (an n × n eigenvalue problem,
        // 0.45 s of the 1000-state design) runs only when it failed or is not.
        if solved.as_ref().map_or(true, |kf| {
            !Domain::Discrete(dt).stable(C64::new(kf.radius, 0.0))
        }) {
            unseen(checks)?;
        }
        let kf = solved.map_err(|e| {
            checks.error(
                &format!(
                    "DARE(Φ1ᵀ, C1ᵀ, Q, R) on {} has a stabilising solution",
                    pair.name
                ),
                e.to_string(),
            )
        })?;
        checks.require(
            &format!(
                "DARE(Φ1ᵀ, C1ᵀ, Q, R) on {} has a stabilising solution",
                pair.name
            ),
            true,
            format!(
                "ρ(Φ1 − KC1) = {}{}",
                sig(kf.radius),
                if fixed.is_empty() {
                    String::new()
                } else {
                    format!(", fixed modes {}", format_list(&fixed))
                }
            ),
        )?;
        kf.predictor_gain
    };
    checks.weights = Some((q, r));
    Ok((gain, fixed))
}

/// A weight at the pair's size: the plant's identity carried (T Tᵀ) when not given, as given when it has the pair's size,
/// T W Tᵀ when it has the plant's size and the pair maps it by T.
fn weight(
    checks: &Checks,
    name: &str,
    given: Option<&Mat>,
    size: usize,
    map: Option<&Mat>,
    what: &str,
) -> Result<Mat, DesignError> {
    let Some(wm) = given else {
        return Ok(match map {
            Some(t) => {
                let carried = t * t.transpose();
                (&carried + carried.transpose()) * 0.5
            }
            None => Mat::identity(size, size),
        });
    };
    if wm.shape() == (size, size) {
        return Ok(wm.clone());
    }
    match map {
        Some(t) if wm.shape() == (t.ncols(), t.ncols()) => {
            let mapped = t * wm * t.transpose();
            Ok((&mapped + mapped.transpose()) * 0.5)
        }
        _ => {
            let plant = map
                .map(|t| format!(" or {0}×{0}", t.ncols()))
                .unwrap_or_default();
            Err(checks.error(
                name,
                format!(
                    "is {}×{}, must be {size}×{size} ({what}){plant}",
                    wm.nrows(),
                    wm.ncols()
                ),
            ))
        }
    }
}
