//! State-feedback design: G placed (any method of [`lti::place`]) or given, and the closed
//! loop it makes, continuous eig(A − BG) and sampled eig(A_d − B_dG) (G is applied to samples
//! held over each step). By the separation principle the loop with an observer has these
//! eigenvalues plus the observer's.
//!
//! With u = N r − G x̂ and tracked outputs z = C_t x (one per input), the reference prefilter
//!
//! ```text
//! N = −(C_t (A − BG)⁻¹ B)⁻¹
//! ```
//!
//! gives the closed loop unit DC gain from r to z, so z settles on a constant r (Franklin,
//! Powell & Emami-Naeini, *Feedback Control of Dynamic Systems*, §7.9). The exact sampling has
//! the same DC gain, (I − A_d + B_dG)⁻¹B_d = −(A − BG)⁻¹B, so N holds for the sampled loop too.
//! Without tracked outputs N = I: u = r − G x̂.

use lti::eig::{continuous_image, eigenvalues, format_list};
use lti::place::{place, Method};
use lti::{Discrete, Mat, Model, Poles, C64};

/// How G is obtained.
#[derive(Debug, Clone, PartialEq)]
pub enum FeedbackSpec {
    /// Place eig(A − BG).
    Poles {
        /// Continuous closed-loop poles.
        poles: Poles,
        /// Placement method.
        placement: Method,
    },
    /// G given.
    Gain(Mat),
}

/// A designed state feedback.
#[derive(Debug, Clone)]
pub struct FeedbackDesign {
    /// G, l×n.
    pub g: Mat,
    /// The reference prefilter N, l×l (I without tracked outputs).
    pub n: Mat,
    /// eig(A − BG), sorted.
    pub closed_loop: Vec<C64>,
    /// eig(A_d − B_dG), sorted.
    pub discrete_closed_loop: Vec<C64>,
    /// The unstable continuous closed-loop eigenvalues (empty when stable).
    pub unstable: Vec<C64>,
}

impl FeedbackDesign {
    /// Whether the continuous and the sampled loops are both asymptotically stable.
    pub fn stable(&self) -> bool {
        self.unstable.is_empty() && self.discrete_closed_loop.iter().all(|z| z.norm() < 1.0)
    }

    /// "unstable closed loop: eig(A − BG) has +122.271" style description, if unstable.
    pub fn instability(&self) -> Option<String> {
        if !self.unstable.is_empty() {
            Some(format!("unstable closed loop: eig(A − BG) has {}", format_list(&self.unstable)))
        } else if !self.stable() {
            let bad: Vec<C64> = self.discrete_closed_loop.iter().copied().filter(|z| z.norm() >= 1.0).collect();
            Some(format!("unstable sampled closed loop: eig(A_d − B_dG) has {} (|z| ≥ 1): dt too coarse", format_list(&bad)))
        } else {
            None
        }
    }
}

/// Designs (or checks) G for `model` sampled with period dt, and the prefilter N for the tracked
/// outputs z = C_t x (`track`, l×n), if any.
pub fn design(model: &Model, spec: &FeedbackSpec, track: Option<&Mat>, dt: f64) -> Result<FeedbackDesign, String> {
    let g = match spec {
        FeedbackSpec::Poles { poles, placement } => place(&model.a, &model.b, poles, *placement).map_err(|e| e.to_string())?.gain,
        FeedbackSpec::Gain(g) => {
            if g.shape() != (model.l(), model.n()) {
                return Err(format!("gain is {}×{}, must be {}×{}", g.nrows(), g.ncols(), model.l(), model.n()));
            }
            g.clone()
        }
    };
    let closed_loop = eigenvalues(&(&model.a - &model.b * &g)).map_err(|e| e.to_string())?;
    let dm = model.discretize(dt);
    let discrete_closed_loop = eigenvalues(&(&dm.a - &dm.b * &g)).map_err(|e| e.to_string())?;
    let unstable: Vec<C64> = closed_loop.iter().copied().filter(|z| z.re >= 0.0).collect();
    let n = match track {
        None => Mat::identity(model.l(), model.l()),
        // An unstable loop is refused (or run on request) for its instability, the reason that
        // matters; a prefilter that cannot be formed for it is then left at I.
        Some(ct) => match prefilter(model, &g, ct) {
            Ok(n) => n,
            Err(_) if !unstable.is_empty() => Mat::identity(model.l(), model.l()),
            Err(e) => return Err(e),
        },
    };
    Ok(FeedbackDesign { g, n, closed_loop, discrete_closed_loop, unstable })
}

/// G for a discrete-time plant given per step (Φ, Γ_B): placed at e^{p·dt} on (Φ, Γ_B), or
/// given; `closed_loop` is then ln(z)/dt of eig(Φ − Γ_BG), and the prefilter makes the sampled
/// loop's DC gain one: N = (C_t (I − Φ + Γ_BG)⁻¹ Γ_B)⁻¹.
pub fn design_discrete(dm: &Discrete, spec: &FeedbackSpec, track: Option<&Mat>) -> Result<FeedbackDesign, String> {
    let (n, l) = (dm.a.nrows(), dm.b.ncols());
    let g = match spec {
        FeedbackSpec::Poles { poles, placement } => place(&dm.a, &dm.b, &poles.to_discrete(dm.dt), *placement).map_err(|e| e.to_string())?.gain,
        FeedbackSpec::Gain(g) => {
            if g.shape() != (l, n) {
                return Err(format!("gain is {}×{}, must be {l}×{n}", g.nrows(), g.ncols()));
            }
            g.clone()
        }
    };
    let acl = &dm.a - &dm.b * &g;
    let discrete_closed_loop = eigenvalues(&acl).map_err(|e| e.to_string())?;
    let (closed_loop, _) = continuous_image(&discrete_closed_loop, dm.dt);
    let unstable: Vec<C64> = closed_loop.iter().copied().filter(|z| z.re >= 0.0).collect();
    let prefilter = match track {
        None => Mat::identity(l, l),
        Some(ct) if ct.shape() != (l, n) => return Err(format!("track is {}×{}, must be {l}×{n} (one tracked output per input)", ct.nrows(), ct.ncols())),
        Some(ct) => {
            let x = (Mat::identity(n, n) - &acl).lu().solve(&dm.b);
            let dc = x.map(|x| ct * x);
            match dc.as_ref().and_then(|dc| dc.clone().try_inverse()).filter(|i| i.iter().all(|v| v.is_finite())) {
                Some(i) => i,
                None if !unstable.is_empty() => Mat::identity(l, l),
                None => return Err("the sampled closed loop's DC gain to the tracked outputs, C_t(I − Φ + Γ_BG)⁻¹Γ_B, is singular: those outputs cannot follow r".into()),
            }
        }
    };
    Ok(FeedbackDesign { g, n: prefilter, closed_loop, discrete_closed_loop, unstable })
}

/// N = −(C_t (A − BG)⁻¹ B)⁻¹ (see the module documentation).
fn prefilter(model: &Model, g: &Mat, ct: &Mat) -> Result<Mat, String> {
    if ct.shape() != (model.l(), model.n()) {
        return Err(format!("track is {}×{}, must be {}×{} (one tracked output per input)", ct.nrows(), ct.ncols(), model.l(), model.n()));
    }
    let acl = &model.a - &model.b * g;
    let x = acl.lu().solve(&model.b).ok_or("A − BG has an eigenvalue at 0: the closed loop has no finite DC gain, so no prefilter can make the tracked outputs follow r")?;
    let dc = ct * x;
    let inv = dc.clone().try_inverse().filter(|i| i.iter().all(|v| v.is_finite()));
    inv.map(|i| -i).ok_or_else(|| format!("the closed loop's DC gain to the tracked outputs, C_t(A − BG)⁻¹B = {dc:.4}, is singular: those outputs cannot follow r"))
}
