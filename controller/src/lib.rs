//! The controller component: state feedback on an observer's estimate,
//!
//! ```text
//! u_k = N r_k − G x̂_k − G_ξ ξ_k − M ŵ_{k−1},      ξ_{k+1} = ξ_k + dt (r_k − z_k)
//! ```
//!
//! (seed 000 eq. 24, with the reference prefilter N of [`design`]; at an operating point the
//! design is in deviations and u_op − N r_op + G x_op is added, [`ControllerConfig::offset`]; the integrators ξ of
//! [`design::integral`] and the cancellation M ŵ of [`design::feedforward`] when asked), its
//! design, and the process shell that runs it in lockstep.

pub mod design;
pub mod shell;

use lti::MatData;
use lti::input_estimate::InputEstimateStep;
use lti::kernel::{mul_acc, mul_into};
use lti::sampled::SampledSignal;
use lti::signal::Signal;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// What the launcher tells the controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControllerConfig {
    /// Feedback gain G (l×n).
    pub g: MatData,
    /// Reference prefilter N (l×l).
    pub n: MatData,
    /// Reference signals r, one per input.
    pub references: Vec<Signal>,
    /// Sample period, s.
    pub dt: f64,
    /// The observer whose estimate is fed back.
    pub observer: String,
    /// Integral action, if asked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integral: Option<IntegralConfig>,
    /// Cancellation of the unknown input, if asked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feedforward: Option<FeedforwardConfig>,
    /// At an operating point, c_u = u_op − N r_op + G x_op (l values), added to u: the design
    /// is in deviations, δu = N(r − r_op) − G(x̂ − x_op) (− G_ξξ − Mδŵ), and the plant takes
    /// u = u_op + δu. `None` at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<Vec<f64>>,
}

impl ControllerConfig {
    /// Whether the controller reads the plant's samples as well as its observer's: for ŵ, or for
    /// measured tracked outputs.
    pub fn reads_plant(&self) -> bool {
        self.feedforward.is_some() || self.integral.as_ref().is_some_and(|i| i.y.is_some())
    }
}

/// The integrators ξ_{k+1} = ξ_k + dt (r_k − z_k) and their gain. The tracked outputs z = C_t x
/// are measured, z_k = M y_k, when C_t = MC (so that neither an observer's bias nor a model error
/// leaves a steady-state error), else estimated, z_k = C_t x̂_k.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntegralConfig {
    /// G_ξ, l×l_t: one column per integrator.
    pub gi: MatData,
    /// C_t (l_t×n, on x̂), or M (l_t×p, on the plant's y_k) when `y` is given.
    pub ct: MatData,
    /// The references (0-based) the integrators hold the tracked outputs at: the commanded
    /// inputs' when some inputs are measured disturbances; empty: all l (l_t = l).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub references: Vec<usize>,
    /// [start, end) of y_k in the plant's sample, when z is measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<[usize; 2]>,
}

/// M ŵ_{k−1} = (MW) y_k − (MWCΦ) x̂_{k−1} − (MWCΓ_B) u_{k−1}, from the plant's sample k (its y_k
/// and the u_{k−1} it held) and the previous estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeedforwardConfig {
    /// MW, l×p.
    pub mw: MatData,
    /// MWCΦ, l×n.
    pub mw_c_phi: MatData,
    /// MWCΓ_B, l×l.
    pub mw_c_gamma_b: MatData,
    /// [start, end) of y_k in the plant's sample.
    pub y: [usize; 2],
    /// [start, end) of u_{k−1} in the plant's sample.
    pub u_prev: [usize; 2],
    /// At an operating point, M(c − w_op) = −M W(y_op − CΦx_op − CΓ_Bu_op) (l values), so that
    /// what is cancelled is Mδŵ = M(ŵ − w_op). `None` at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<Vec<f64>>,
}

/// State feedback as a step function.
#[derive(Debug, Clone)]
pub struct Controller {
    g: DMatrix<f64>,
    n: DMatrix<f64>,
    r: DVector<f64>,
    references: Vec<SampledSignal>,
    dt: f64,
    gx: DVector<f64>,
    u: DVector<f64>,
    integral: Option<Integral>,
    feedforward: Option<Feedforward>,
    reads_plant: bool,
    /// c_u at an operating point.
    offset: Option<Vec<f64>>,
}

#[derive(Debug, Clone)]
struct Integral {
    gi: DMatrix<f64>,
    /// Which of r each integrator compares with.
    references: Vec<usize>,
    ct: DMatrix<f64>,
    y: Option<std::ops::Range<usize>>,
    xi: DVector<f64>,
    z: DVector<f64>,
}

#[derive(Debug, Clone)]
struct Feedforward {
    /// Mŵ_{k−1}, with M folded into W, WCΦ and WCΓ_B.
    m_what: InputEstimateStep,
    y: std::ops::Range<usize>,
    u_prev: std::ops::Range<usize>,
}

impl Controller {
    /// From the configuration; fails if G and the references do not conform.
    pub fn new(cfg: &ControllerConfig) -> Result<Self, String> {
        let g: DMatrix<f64> = (&cfg.g).into();
        if g.nrows() != cfg.references.len() {
            return Err(format!(
                "G has {} rows but there are {} references",
                g.nrows(),
                cfg.references.len()
            ));
        }
        let n: DMatrix<f64> = (&cfg.n).into();
        if n.shape() != (g.nrows(), g.nrows()) {
            return Err(format!(
                "N is {}×{}, must be {}×{}",
                n.nrows(),
                n.ncols(),
                g.nrows(),
                g.nrows()
            ));
        }
        let (l, nx) = g.shape();
        let integral = cfg
            .integral
            .as_ref()
            .map(|i| {
                let (gi, ct): (DMatrix<f64>, DMatrix<f64>) = ((&i.gi).into(), (&i.ct).into());
                let y = i.y.map(|[a, b]| a..b);
                let cols = y.as_ref().map_or(nx, |y| y.len());
                let references = if i.references.is_empty() {
                    (0..l).collect()
                } else {
                    i.references.clone()
                };
                let lt = references.len();
                if gi.shape() != (l, lt) || ct.shape() != (lt, cols) {
                    return Err(format!(
                        "integral: G_ξ is {}×{} and C_t {}×{}, must be {l}×{lt} and {lt}×{cols}",
                        gi.nrows(),
                        gi.ncols(),
                        ct.nrows(),
                        ct.ncols()
                    ));
                }
                if references.iter().any(|&j| j >= l) {
                    return Err(format!(
                        "integral: references must index the {l} references"
                    ));
                }
                Ok(Integral {
                    gi,
                    references,
                    ct,
                    y,
                    xi: DVector::zeros(lt),
                    z: DVector::zeros(lt),
                })
            })
            .transpose()?;
        let feedforward = cfg
            .feedforward
            .as_ref()
            .map(|f| {
                let (mw, a, b): (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) = (
                    (&f.mw).into(),
                    (&f.mw_c_phi).into(),
                    (&f.mw_c_gamma_b).into(),
                );
                let (y, u_prev) = (f.y[0]..f.y[1], f.u_prev[0]..f.u_prev[1]);
                if mw.shape() != (l, y.len())
                    || a.shape() != (l, nx)
                    || b.shape() != (l, l)
                    || u_prev.len() != l
                {
                    return Err(
                        "feedforward: MW, MWCΦ, MWCΓ_B and the sample's ranges do not conform"
                            .to_string(),
                    );
                }
                let mut m_what = InputEstimateStep::new(mw, &a, &b);
                if let Some(c) = &f.offset {
                    if c.len() != l || c.iter().any(|v| !v.is_finite()) {
                        return Err(format!("feedforward: offset must hold {l} finite values"));
                    }
                    m_what = m_what.with_offset(c.clone());
                }
                Ok(Feedforward { m_what, y, u_prev })
            })
            .transpose()?;
        if let Some(c) = &cfg.offset
            && (c.len() != l || c.iter().any(|v| !v.is_finite()))
        {
            return Err(format!(
                "offset must hold {l} finite values (one per input)"
            ));
        }
        Ok(Self {
            gx: DVector::zeros(l),
            u: DVector::zeros(l),
            r: DVector::zeros(l),
            g,
            n,
            references: SampledSignal::all(&cfg.references, cfg.dt),
            dt: cfg.dt,
            integral,
            feedforward,
            reads_plant: cfg.reads_plant(),
            offset: cfg.offset.clone(),
        })
    }

    /// Whether it reads the plant's sample (for ŵ, or measured tracked outputs).
    pub fn reads_plant(&self) -> bool {
        self.reads_plant
    }

    /// u_k = N r(t_k) − G x̂_k (− G_ξ ξ_k − M ŵ_{k−1}); `plant` is the plant's sample k, read only
    /// when [`Self::reads_plant`] (may be empty otherwise).
    pub fn step(&mut self, k: u64, xhat: &[f64], plant: &[f64]) -> &[f64] {
        // (Slices, not nalgebra's iterators: this runs every step.)
        let (r, gx, u) = (
            self.r.as_mut_slice(),
            self.gx.as_mut_slice(),
            self.u.as_mut_slice(),
        );
        for (r, s) in r.iter_mut().zip(&self.references) {
            *r = s.sample_step(k);
        }
        mul_into(u, &self.n, r);
        mul_into(gx, &self.g, xhat);
        if let Some(i) = &mut self.integral {
            mul_acc(gx, &i.gi, i.xi.as_slice());
            // ξ_{k+1} = ξ_k + dt (r_k − z_k), after u_k used ξ_k.
            match &i.y {
                Some(y) => mul_into(i.z.as_mut_slice(), &i.ct, &plant[y.clone()]),
                None => mul_into(i.z.as_mut_slice(), &i.ct, xhat),
            }
            for ((xi, &j), z) in
                i.xi.as_mut_slice()
                    .iter_mut()
                    .zip(&i.references)
                    .zip(i.z.as_slice())
            {
                *xi += self.dt * (r[j] - z);
            }
        }
        if let Some(f) = &mut self.feedforward {
            // M ŵ_{k−1} once there is an x̂_{k−1}; nothing is cancelled at k = 0.
            if f.m_what
                .push(&plant[f.y.clone()], &plant[f.u_prev.clone()], xhat)
            {
                for (gx, m) in gx.iter_mut().zip(&f.m_what.value) {
                    *gx += m;
                }
            }
        }
        for (u, gx) in u.iter_mut().zip(gx.iter()) {
            *u -= gx;
        }
        if let Some(c) = &self.offset {
            for (u, c) in u.iter_mut().zip(c) {
                *u += c;
            }
        }
        u
    }
}
