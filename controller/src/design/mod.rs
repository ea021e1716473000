//! State-feedback design: G placed, from the DARE (LQR) or given, with optional integral action
//! and cancellation of the unknown input, and the loop it makes.
//!
//! The controller runs on samples held over each step, so by default the poles asked for are
//! placed for the sampled loop exactly: eig(Φ − Γ_BG) = e^{p·dt}, as the observers are. The
//! continuous placement eig(A − BG) = p (`domain = "continuous"`) reproduces a paper's printed
//! gain; its sampled loop then only approximates the poles asked for.
//!
//! With u = N r − G x̂ and tracked outputs z = C_t x (one per input), the reference prefilter
//!
//! ```text
//! N = (C_t (I − Φ + Γ_BG)⁻¹ Γ_B)⁻¹
//! ```
//!
//! gives the sampled loop unit DC gain from r to z (Franklin, Powell & Emami-Naeini, *Feedback
//! Control of Dynamic Systems*, §7.9, in its sampled form; for an exactly sampled continuous plant
//! (I − Φ + Γ_BG)⁻¹Γ_B = −(A − BG)⁻¹B, the continuous formula). Without tracked outputs N = I:
//! u = r − G x̂. With integral action ([`integral`]) N = 0: the integrator makes z settle on r.

pub mod feedforward;
pub mod integral;
pub mod measured;

use lti::dare::solve_dare;
use lti::eig::{continuous_image, eigenvalues, format_list};
use lti::place::{Method, place, place_sampled};
use lti::{C64, Discrete, Mat, Model, Poles};

/// Where the poles asked for are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// eig(Φ − Γ_BG) = e^{p·dt}: the loop that runs.
    Sampled,
    /// eig(A − BG) = p (a continuous design applied to samples).
    Continuous,
}

impl Domain {
    /// The scenario's word.
    pub fn name(self) -> &'static str {
        match self {
            Domain::Sampled => "sampled",
            Domain::Continuous => "continuous",
        }
    }
}

/// How G is obtained.
#[derive(Debug, Clone, PartialEq)]
pub enum FeedbackSpec {
    /// Place the closed loop's poles.
    Poles {
        /// Continuous-time closed-loop poles p (placed at e^{p·dt} for the sampled loop).
        poles: Poles,
        /// Placement method.
        placement: Method,
        /// Which loop they are placed for.
        domain: Domain,
    },
    /// The discrete LQR: G = (R + Γ_BᵀXΓ_B)⁻¹Γ_BᵀXΦ, X = DARE(Φ, Γ_B, Q, R), minimising
    /// Σ x_kᵀQx_k + u_kᵀRu_k over the sampled plant (identities when not given).
    Lqr {
        /// State weight (n×n, or (n + l)×(n + l) with integral action).
        q: Option<Mat>,
        /// Input weight, l×l.
        r: Option<Mat>,
    },
    /// G given (l×n, or l×(n + l) = [G_x, G_ξ] with integral action).
    Gain(Mat),
}

/// What the loop asks besides G.
#[derive(Debug, Clone, Default)]
pub struct Options<'a> {
    /// The tracked outputs z = C_t x (l×n): the prefilter, or the integrators, make them follow r.
    pub track: Option<&'a Mat>,
    /// Integral action on the tracked outputs.
    pub integral: bool,
    /// The measured disturbances: inputs (0-based) the controller does not command
    /// ([`measured`]); `track`, the weights and a given gain then cover the commanded ones only.
    pub measured: &'a [usize],
}

/// A designed state feedback.
#[derive(Debug, Clone)]
pub struct FeedbackDesign {
    /// G, l×n (the state part G_x with integral action).
    pub g: Mat,
    /// With integral action: the integrators' gain G_ξ (l×l_c), C_t, and M when z = My is
    /// measured.
    pub integral: Option<(Mat, Mat, Option<Mat>)>,
    /// The reference prefilter N, l×l (I without tracked outputs, 0 with integral action; the
    /// unit row of a measured disturbance).
    pub n: Mat,
    /// The measured disturbances, inputs passed through from their references ([`measured`]).
    pub measured: Vec<usize>,
    /// The continuous loop's poles: eig(A − BG) when placed in continuous time, else ln(z)/dt of
    /// the sampled loop's; sorted.
    pub closed_loop: Vec<C64>,
    /// eig(Φ − Γ_BG) (of the augmented loop with integral action), sorted.
    pub discrete_closed_loop: Vec<C64>,
    /// The unstable continuous closed-loop eigenvalues (empty when stable).
    pub unstable: Vec<C64>,
    /// How G was made, in words: "placed for the sampled loop (e^{p·dt})", "LQR …", "given".
    pub how: String,
    /// With `feedforward = "what"`: MW, MWCΦ and MWCΓ_B of M ŵ_{k−1} ([`feedforward`]), set by
    /// whoever knows the observer's estimator.
    pub feedforward: Option<[Mat; 3]>,
}

impl FeedbackDesign {
    /// c_u = u_op − N r_op + G x_op of this feedback designed in deviations from `op`
    /// ([`crate::ControllerConfig::offset`]): r_op = C_t x_op, the tracked outputs at the point
    /// (`track`), or u_op without tracked outputs (N = I: the references are then the inputs'
    /// absolute levels). A measured disturbance's reference is its absolute level u_op,m, so its
    /// offset is 0: u_m = r_m.
    pub fn offset_at(&self, track: Option<&Mat>, op: &lti::OperatingPoint) -> Vec<f64> {
        let col = |v: &[f64]| Mat::from_column_slice(v.len(), 1, v);
        let x = col(&op.x);
        let mut r_op = col(&op.u);
        if let Some(ct) = track {
            let keep = measured::commanded(op.u.len(), &self.measured);
            for (i, z) in (ct * &x).iter().enumerate() {
                r_op[keep[i]] = *z;
            }
        }
        (col(&op.u) - &self.n * r_op + &self.g * x)
            .iter()
            .copied()
            .collect()
    }

    /// Whether the continuous and the sampled loops are both asymptotically stable.
    pub fn stable(&self) -> bool {
        self.unstable.is_empty() && self.discrete_closed_loop.iter().all(|z| z.norm() < 1.0)
    }

    /// Whether the controller will read the plant's samples (for ŵ, or measured tracked outputs).
    pub fn reads_plant(&self) -> bool {
        self.feedforward.is_some() || self.integral.as_ref().is_some_and(|(_, _, m)| m.is_some())
    }

    /// "unstable closed loop: eig(A − BG) has +122.271" style description, if unstable.
    pub fn instability(&self) -> Option<String> {
        if !self.unstable.is_empty() {
            Some(format!(
                "unstable closed loop: eig(A − BG) has {}",
                format_list(&self.unstable)
            ))
        } else if !self.stable() {
            let bad: Vec<C64> = self
                .discrete_closed_loop
                .iter()
                .copied()
                .filter(|z| z.norm() >= 1.0)
                .collect();
            Some(format!(
                "unstable sampled closed loop: eig(Φ − Γ_BG) has {} (|z| ≥ 1): dt too coarse",
                format_list(&bad)
            ))
        } else {
            None
        }
    }
}

/// Designs (or checks) G for the sampled plant `dm` — and its continuous `model`, when there is
/// one (not for a discrete-time plant) — with the options' prefilter or integrators.
///
/// With measured disturbances ([`Options::measured`]) G is designed on the commanded inputs'
/// columns and embedded in l rows ([`measured`]).
pub fn design(
    model: Option<&Model>,
    dm: &Discrete,
    spec: &FeedbackSpec,
    opts: &Options,
) -> Result<FeedbackDesign, String> {
    let l_all = dm.b.ncols();
    if opts.measured.is_empty() {
        return design_commanded(model, dm, spec, opts);
    }
    if let Some(&j) = opts.measured.iter().find(|&&j| j >= l_all) {
        return Err(format!(
            "measured disturbance {} is not an input (the plant has {l_all})",
            j + 1
        ));
    }
    let keep = measured::commanded(l_all, opts.measured);
    if keep.is_empty() {
        return Err("every input is a measured disturbance: the controller commands none".into());
    }
    let model_c = model.map(|m| measured::continuous(m, &keep));
    let mut d = design_commanded(model_c.as_ref(), &measured::sampled(dm, &keep), spec, opts)?;
    d.g = measured::rows(&d.g, l_all, &keep);
    d.n = measured::prefilter(&d.n, l_all, &keep);
    if let Some((gi, _, _)) = &mut d.integral {
        *gi = measured::rows(gi, l_all, &keep);
    }
    d.measured = opts.measured.to_vec();
    Ok(d)
}

/// [`design`] on every column of Γ_B.
// one job: the sampled state feedback of one specification (the pair designed on, the gain, the
// closed loop's check, the prefilter), steps sharing the pair and its sizes.
fn design_commanded(
    model: Option<&Model>,
    dm: &Discrete,
    spec: &FeedbackSpec,
    opts: &Options,
) -> Result<FeedbackDesign, String> {
    let (n, l) = (dm.a.nrows(), dm.b.ncols());
    let per = if opts.measured.is_empty() {
        "input"
    } else {
        "commanded input"
    };
    if let Some(ct) = opts.track
        && ct.shape() != (l, n)
    {
        return Err(format!(
            "track is {}×{}, must be {l}×{n} (one tracked output per {per})",
            ct.nrows(),
            ct.ncols()
        ));
    }
    // The pair G is designed on: the plant's, or the plant with the integrators (integral.rs).
    let ct = match (opts.integral, opts.track) {
        (true, Some(ct)) => Some(ct.clone()),
        (true, None) => {
            return Err(
                "integral action needs track = [[…]]: the outputs the integrators hold at r".into(),
            );
        }
        (false, _) => None,
    };
    let (phi, gamma) = match &ct {
        Some(ct) => integral::augment_sampled(dm, ct),
        None => (dm.a.clone(), dm.b.clone()),
    };
    let continuous = model.map(|m| match &ct {
        Some(ct) => integral::augment_continuous(m, ct),
        None => (m.a.clone(), m.b.clone()),
    });
    let size = phi.nrows();
    let states = if ct.is_some() {
        format!("n + l = {size} (the plant's {n} states and one integrator per tracked output)")
    } else {
        format!("{size}")
    };
    let (g_all, how) = match spec {
        FeedbackSpec::Poles {
            poles,
            placement,
            domain,
        } => {
            if poles.len() != size {
                return Err(format!(
                    "{} poles given, the loop has {states}",
                    poles.len()
                ));
            }
            match domain {
                // Ackermann's formula works on the characteristic polynomial, whose coefficients
                // in z cancel when the poles crowd at 1 (seed 003 at dt = 1 ms): it is placed in
                // the δ-domain, δ = (z − 1)/dt, where they spread as in s (`lti::place::delta`).
                Domain::Sampled if *placement == Method::Ackermann => (
                    place_sampled(&phi, &gamma, poles, dm.dt, *placement)
                        .map_err(|e| e.to_string())?
                        .gain,
                    "placed for the sampled loop in the δ-domain: eig(Φ − Γ_BG) = e^{p·dt}"
                        .to_string(),
                ),
                Domain::Sampled => (
                    place(&phi, &gamma, &poles.to_discrete(dm.dt), *placement)
                        .map_err(|e| e.to_string())?
                        .gain,
                    "placed for the sampled loop: eig(Φ − Γ_BG) = e^{p·dt}".to_string(),
                ),
                Domain::Continuous => {
                    let (a, b) = continuous.as_ref().ok_or("domain = \"continuous\" needs a continuous-time plant (a discrete-time plant's poles are placed at e^{p·dt})")?;
                    (place(a, b, poles, *placement).map_err(|e| e.to_string())?.gain, "placed in continuous time: eig(A − BG) = p (the sampled loop approximates them)".to_string())
                }
            }
        }
        FeedbackSpec::Lqr { q, r } => {
            let q = q.clone().unwrap_or_else(|| Mat::identity(size, size));
            let r = r.clone().unwrap_or_else(|| Mat::identity(l, l));
            if q.shape() != (size, size) {
                return Err(format!(
                    "Q is {}×{}, must be {size}×{size} ({states})",
                    q.nrows(),
                    q.ncols()
                ));
            }
            if r.shape() != (l, l) {
                return Err(format!(
                    "R is {}×{}, must be {l}×{l} (one row per {per})",
                    r.nrows(),
                    r.ncols()
                ));
            }
            let dare = solve_dare(&phi, &gamma, &q, &r).map_err(|e| format!("LQR: {e}"))?;
            (
                dare.k,
                format!(
                    "LQR: X = DARE(Φ, Γ_B, Q, R), relative residual {:.1e}; G = (R + Γ_BᵀXΓ_B)⁻¹Γ_BᵀXΦ",
                    dare.residual
                ),
            )
        }
        FeedbackSpec::Gain(g) => {
            if g.shape() != (l, size) {
                return Err(format!(
                    "gain is {}×{}, must be {l}×{size} ({states})",
                    g.nrows(),
                    g.ncols()
                ));
            }
            (g.clone(), "given".to_string())
        }
    };
    let acl = &phi - &gamma * &g_all;
    let discrete_closed_loop = eigenvalues(&acl).map_err(|e| e.to_string())?;
    let closed_loop = match (spec, &continuous) {
        (
            FeedbackSpec::Poles {
                domain: Domain::Continuous,
                ..
            }
            | FeedbackSpec::Gain(_),
            Some((a, b)),
        ) => eigenvalues(&(a - b * &g_all)).map_err(|e| e.to_string())?,
        _ => continuous_image(&discrete_closed_loop, dm.dt).0,
    };
    let unstable: Vec<C64> = closed_loop
        .iter()
        .copied()
        .filter(|z| z.re >= 0.0)
        .collect();
    let g = g_all.columns(0, n).into_owned();
    let (prefilter, integral) = match (&ct, opts.track) {
        (Some(ct), _) => (
            Mat::zeros(l, l),
            Some((
                g_all.columns(n, l).into_owned(),
                ct.clone(),
                integral::measured(ct, &dm.c),
            )),
        ),
        (None, None) => (Mat::identity(l, l), None),
        (None, Some(ct)) => match prefilter(&acl, &gamma, ct) {
            Ok(p) => (p, None),
            // An unstable loop is refused (or run on request) for its instability, the reason
            // that matters; a prefilter that cannot be formed for it is then left at I.
            Err(_) if !unstable.is_empty() => (Mat::identity(l, l), None),
            Err(e) => return Err(e),
        },
    };
    Ok(FeedbackDesign {
        g,
        integral,
        n: prefilter,
        measured: Vec::new(),
        closed_loop,
        discrete_closed_loop,
        unstable,
        how,
        feedforward: None,
    })
}

/// N = (C_t (I − Φ + Γ_BG)⁻¹ Γ_B)⁻¹ (see the module documentation).
fn prefilter(acl: &Mat, gamma: &Mat, ct: &Mat) -> Result<Mat, String> {
    let n = acl.nrows();
    let x = (Mat::identity(n, n) - acl).lu().solve(gamma).ok_or("Φ − Γ_BG has an eigenvalue at 1: the closed loop has no finite DC gain, so no prefilter can make the tracked outputs follow r")?;
    let dc = ct * x;
    dc.clone().try_inverse().filter(|i| i.iter().all(|v| v.is_finite())).ok_or_else(|| {
        format!("the sampled closed loop's DC gain to the tracked outputs, C_t(I − Φ + Γ_BG)⁻¹Γ_B = {dc:.4}, is singular: those outputs cannot follow r")
    })
}
