//! The discrete algebraic Riccati equation (DARE) and the steady-state Kalman filter.
//!
//! ```text
//! X = AᵀXA − AᵀXB(R + BᵀXB)⁻¹BᵀXA + Q,     A n×n, B n×m, Q = Qᵀ ⪰ 0, R = Rᵀ ≻ 0,
//! ```
//!
//! scipy's `solve_discrete_are(a, b, q, r)`. The stabilising solution X makes the closed loop
//! A − BK, K = (R + BᵀXB)⁻¹BᵀXA, Schur-stable; it is symmetric, ⪰ 0 and unique, and it exists
//! if and only if (A, B) is stabilisable and (A, Q) has no unobservable mode on the unit circle
//! (e.g. Lancaster & Rodman, "Algebraic Riccati Equations", Oxford 1995; for the filter,
//! Chan, Goodwin & Sin, IEEE TAC 29(2), 1984). Detectability of (A, Q) is sufficient, not
//! necessary: an unobservable mode outside the circle still leaves a stabilising solution.
//!
//! Method: the structure-preserving doubling algorithm (SDA) of Chu, Fan, Lin & Wang,
//! "Structure-preserving algorithms for periodic discrete-time algebraic Riccati equations",
//! Int. J. Control 77(8), 767–788, 2004. With G = BR⁻¹Bᵀ the DARE reads X = AᵀX(I + GX)⁻¹A + Q,
//! and from A₀ = A, G₀ = G, H₀ = Q,
//!
//! ```text
//! W_k     = I + G_k H_k
//! A_{k+1} = A_k W_k⁻¹ A_k
//! G_{k+1} = G_k + A_k W_k⁻¹ G_k A_kᵀ
//! H_{k+1} = H_k + A_kᵀ H_k W_k⁻¹ A_k
//! ```
//!
//! H_k is the Riccati difference iterate after 2ᵏ steps from 0, so H_k ↑ X. When (A, B) is
//! stabilisable and (A, Q) detectable the convergence is quadratic,
//! ‖H_k − X‖ = O(ρ(A − BK)^{2^{k+1}}) (Lin & Xu, "Convergence analysis of structure-preserving
//! doubling algorithms for Riccati-type matrix equations", SIAM J. Matrix Anal. Appl. 28(1),
//! 2006), ~log₂(36/(1 − ρ)) steps to reach ε: 19 for seed 001's missile at ρ = 0.9999. Why SDA and not
//! scipy's generalized Schur method (Van Dooren 1981): it needs only products and n×n solves,
//! and nalgebra has no real QZ with reordering. W_k is never singular: G_k, H_k ⪰ 0, so the
//! eigenvalues of G_k H_k are ≥ 0.
//!
//! Then Newton steps in correction form (Hewer, "An iterative technique for the computation of
//! the steady state gains for the discrete optimal regulator", IEEE TAC 16(4), 1971):
//!
//! ```text
//! K = (R + BᵀXB)⁻¹BᵀXA,  A_c = A − BK,  Res(X) = Q + A_cᵀXA_c + KᵀRK − X,
//! X ← X + Δ,  Δ = A_cᵀΔA_c + Res(X)                         (a Stein equation)
//! ```
//!
//! Res(X) is the DARE's residual in a form that is stationary in K (an error in K enters at second
//! order), evaluated in double-double (`dd.rs`) and rounded once. SDA's X is off by its
//! accumulated rounding amplified by the DARE's condition — up to 1.3·10⁻¹¹ on the sampled seeds,
//! whose closed loops sit at ρ ≈ 0.998 … 0.9999 — and Newton with a double-precision residual
//! stops at cond·ε (7.9·10⁻¹³ there); with the residual exact to ~ε², one or two steps take X to
//! within its own rounding (mixed-precision iterative refinement): every entry within ~1 ulp of
//! the exact solution on the reference cases (lti/tests/dare_reference.rs), most bit for bit.
//!
//! When (A, Q) is not detectable — H₀ = Q never sees the unobservable modes, so SDA diverges or
//! finds a non-stabilising solution — Newton's method from the stabilising gain of the
//! regularised problem (Q + δI: observable, so SDA converges) converges monotonically to the
//! stabilising solution (Hewer 1971; Lancaster & Rodman 1995).
//!
//! Refusals: non-finite or non-conforming input, Q or R not symmetric (scipy's test,
//! ‖M − Mᵀ‖₁ ≤ 100 ε ‖M‖₁), Q not ⪰ 0, R not ≻ 0, and no stabilising solution — named by its
//! cause (uncontrollable modes not inside the unit circle, unobservable modes on it) when the
//! staircase forms find one, else by the closed-loop spectral radius.

pub use crate::linalg::norm::one_norm;
use nalgebra::DMatrix;

use crate::dd::DdMatrix;
use crate::eig::{C64, eigenvalues, format_list, spectral_radius};
use crate::error::{LtiError, Result};
use crate::linalg::product::{self, mul, mul_symmetric};
use crate::lyapunov;
use crate::staircase::{controllability_staircase, observability_staircase};

type Mat = DMatrix<f64>;

/// Doubling steps before giving up: quadratic convergence needs ~log₂(36/(1 − ρ)) of them,
/// so 60 covers closed loops up to ρ = 1 − 10⁻¹⁶.
const MAX_DOUBLING: usize = 60;

/// The largest order whose Riccati residual is evaluated in double-double.
pub const DD_MAX: usize = 64;

/// Newton steps before giving up (from a regularised start: monotone, then quadratic).
const MAX_NEWTON: usize = 60;

/// Newton steps refining a stabilising SDA solution (it stops on its own once the correction
/// is rounding: 2–3 steps on the seeds; 6 from SDA's relative residual 5.8e-6 on a random
/// 8-state, 1-output filter whose X spans 1e8).
const MAX_REFINE: usize = 12;

/// A closed loop with ρ ≥ 1 − NEAR_UNIT is checked for modes on the unit circle before it is
/// accepted: a critical case (an uncontrollable or Q-unobservable mode on the circle) ends with
/// that mode in the closed loop, at ρ = 1 up to the eigenvalue's rounding, which for a defective
/// mode is ~√ε ≈ 10⁻⁸.
const NEAR_UNIT: f64 = 1e-6;

/// The largest relative residual (see [`Dare::residual`]) accepted as a solution: a backstop.
/// Well-conditioned solutions sit at a few ε; an ill-conditioned one cannot: on a random
/// 8-state, 1-output filter with three unstable modes (X up to 1.1e8, κ(X) = 4e8) Newton
/// converges at 4.3e-10 and scipy's `solve_discrete_are` returns 2.6e-8 by this measure. 1e-8
/// accepts ours there and still refuses an iteration that went wrong.
const RESIDUAL_TOL: f64 = 1e-8;

/// The stabilising solution of a DARE and what it gives.
#[derive(Debug, Clone, PartialEq)]
pub struct Dare {
    /// X, symmetric positive semi-definite.
    pub x: Mat,
    /// K = (R + BᵀXB)⁻¹BᵀXA, the optimal gain of u = −Kx.
    pub k: Mat,
    /// ρ(A − BK) < 1.
    pub closed_loop_radius: f64,
    /// The residual of the returned X (evaluated in double-double), relative to its terms:
    /// ‖Res(X)‖₁ / (‖Q‖₁ + ‖A_cᵀXA_c‖₁ + ‖KᵀRK‖₁ + ‖X‖₁).
    pub residual: f64,
    /// Doubling steps, then Newton steps.
    pub iterations: (usize, usize),
}

/// The stabilising solution of X = AᵀXA − AᵀXB(R + BᵀXB)⁻¹BᵀXA + Q (scipy's
/// `solve_discrete_are(a, b, q, r)`).
pub fn solve_dare(a: &Mat, b: &Mat, q: &Mat, r: &Mat) -> Result<Dare> {
    solve(a, b, q, r, Words::Control)
}

/// How a refusal names the obstruction: for a regulator, or for the filter whose DARE is the
/// dual one, DARE(Aᵀ, Cᵀ, Q_d, R).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Words {
    Control,
    Filter,
}

fn solve(a: &Mat, b: &Mat, q: &Mat, r: &Mat, words: Words) -> Result<Dare> {
    let n = a.nrows();
    let m = b.ncols();
    conform("A", a, n, n)?;
    conform("B", b, n, m)?;
    conform("Q", q, n, n)?;
    conform("R", r, m, m)?;
    finite("A", a)?;
    finite("B", b)?;
    let q = symmetric("Q", q, Definite::Semi)?;
    let r = symmetric("R", r, Definite::Positive)?;
    // G = BR⁻¹Bᵀ = YᵀY with Y = L⁻¹Bᵀ, R = LLᵀ: symmetric ⪰ 0 by construction.
    let chol = r
        .clone()
        .cholesky()
        .ok_or_else(|| not_definite("R", &r, "positive definite"))?;
    let y = chol
        .l()
        .solve_lower_triangular(&b.transpose())
        .ok_or(LtiError::Singular("R"))?;
    let g = y.transpose() * &y;

    let first = sda(a, &g, &q);
    // Above DD_MAX states SDA's X is refined first and the radius taken once, of the refined
    // X's closed loop, which the refinement has already formed (each n × n eigenvalue
    // computation and residual is ~0.3 s at n = 1000). A non-stabilising X fails the same test
    // after its refinement, which cannot make it stabilising (Smith's sum diverges with A_c).
    let (first, large) = match first {
        Some((x, steps)) if n > DD_MAX => {
            let refined = refine_large(a, b, &q, &r, x)?;
            (Some((refined.x.clone(), steps)), Some(refined))
        }
        other => (other, None),
    };
    let first_radius = match (&first, &large) {
        (_, Some(refined)) => Some(spectral_radius(&eigenvalues(&refined.ac)?)),
        (Some((x, _)), None) => Some(radius(a, b, &r, x)?),
        (None, _) => None,
    };
    let stabilising = first_radius.is_some_and(|rho| rho < 1.0);
    let (mut x, mut doubling, mut newton) = match first {
        Some((x, steps)) => (x, steps, 0),
        None => (Mat::zeros(n, n), MAX_DOUBLING, 0),
    };
    if !stabilising {
        // No convergence, or a non-stabilising solution. If nothing on the unit circle obstructs,
        // (A, Q) has unobservable modes outside it (SDA then diverges with them or converges to
        // a solution blind to them): start Newton from the regularised problem's gain.
        if let Some(why) = obstruction(a, b, &q, words) {
            return Err(LtiError::NoStabilisingSolution(why));
        }
        // Any δ > 0 makes (A, Q + δI) observable; its size only sets how far Newton starts from
        // X (1/‖G‖ is X's natural scale when Q = 0).
        let delta = 1e-2 * one_norm(&q).max(1.0 / one_norm(&g));
        let delta = if delta.is_finite() && delta > 0.0 {
            delta
        } else {
            1.0
        };
        let shifted = &q + Mat::identity(n, n) * delta;
        let Some((start, steps)) = sda(a, &g, &shifted) else {
            return Err(no_solution(a, b, &q, None, words));
        };
        let (refined, steps_newton, converged) = newton_steps(a, b, &q, &r, start, MAX_NEWTON)?;
        if !converged {
            return Err(LtiError::NoConvergence("Newton's method for the DARE"));
        }
        x = refined;
        doubling = steps;
        newton = steps_newton;
    } else {
        // Refinement, kept if it does not raise the residual: from SDA's X two or three steps
        // (quadratic convergence from ~10⁻¹² … 10⁻⁸ off). In a critical case the Stein operator is
        // singular (A − BK has a mode on the circle): the steps fail, and the radius check below
        // names the cause.
        if let Some(refined) = &large {
            newton = refined.kept;
        } else if let Ok((refined, steps, _)) = newton_steps(a, b, &q, &r, x.clone(), MAX_REFINE)
            && let (Ok((new, _)), Ok((old, _))) =
                (residual(a, b, &q, &r, &refined), residual(a, b, &q, &r, &x))
            && new <= old
        {
            x = refined;
            newton = steps;
        }
    }
    let rho = match (stabilising, &large, first_radius) {
        (true, Some(_), Some(rho)) => rho,
        _ => radius(a, b, &r, &x)?,
    };
    let clearly_inside = rho < 1.0 - NEAR_UNIT;
    if !clearly_inside {
        if let Some(why) = obstruction(a, b, &q, words) {
            return Err(LtiError::NoStabilisingSolution(why));
        }
        let inside = rho < 1.0;
        if !inside {
            return Err(no_solution(a, b, &q, Some(rho), words));
        }
    }
    let (res, k) = match large {
        Some(refined) if stabilising => (refined.score, refined.k),
        _ => residual(a, b, &q, &r, &x)?,
    };
    let small = res <= RESIDUAL_TOL;
    if !small {
        return Err(LtiError::NoConvergence(
            "the DARE solution (relative residual above 1e-8)",
        ));
    }
    Ok(Dare {
        x,
        k,
        closed_loop_radius: rho,
        residual: res,
        iterations: (doubling, newton),
    })
}

/// The steady-state Kalman filter of x_{k+1} = A x_k + w_k, y_k = C x_k + v_k, with
/// cov(w) = Q_d, cov(v) = R, w and v white and uncorrelated.
#[derive(Debug, Clone, PartialEq)]
pub struct Kalman {
    /// P = cov(x_k − x̂_{k|k−1}), the a priori (predicted) error covariance: the stabilising
    /// solution of P = APAᵀ − APCᵀ(CPCᵀ + R)⁻¹CPAᵀ + Q_d, i.e. DARE(Aᵀ, Cᵀ, Q_d, R).
    pub p: Mat,
    /// L = PCᵀ(CPCᵀ + R)⁻¹, the measurement-update (filter) gain:
    /// x̂_{k|k} = x̂_{k|k−1} + L (y_k − C x̂_{k|k−1}) (MATLAB `kalman`'s M).
    pub gain: Mat,
    /// A L, the one-step predictor gain: x̂_{k+1|k} = A x̂_{k|k−1} + A L (y_k − C x̂_{k|k−1})
    /// (MATLAB `kalman`'s L without cross-covariance).
    pub predictor_gain: Mat,
    /// cov(x_k − x̂_{k|k}) = (I − LC) P (I − LC)ᵀ + L R Lᵀ (Joseph's form: symmetric, ⪰ 0).
    pub p_updated: Mat,
    /// S = CPCᵀ + R, the innovation covariance.
    pub innovation: Mat,
    /// ρ(A − ALC) = ρ((I − LC)A) < 1: the decay factor of both error recursions.
    pub radius: f64,
}

/// The steady-state Kalman filter (Anderson & Moore, "Optimal Filtering", 1979, ch. 4; the
/// predictor form's covariance is the DARE of the dual pair (Aᵀ, Cᵀ)). Refuses as
/// [`solve_dare`] does, with (A, C) in place of (A, B) read dually: an unobservable mode not
/// inside the unit circle, or a mode on it that the process noise does not excite.
pub fn steady_state_kalman(a: &Mat, c: &Mat, qd: &Mat, r: &Mat) -> Result<Kalman> {
    let (n, p) = (a.nrows(), c.nrows());
    conform("C", c, p, n)?;
    let d = solve(&a.transpose(), &c.transpose(), qd, r, Words::Filter)?;
    let r = symmetric("R", r, Definite::Positive)?;
    let pm = d.x;
    let s = sym(&(c * &pm * c.transpose() + &r));
    // L = P Cᵀ S⁻¹ = (S⁻¹ C P)ᵀ, S symmetric positive definite.
    let chol = s
        .clone()
        .cholesky()
        .ok_or(LtiError::Singular("the innovation covariance"))?;
    let gain = chol.solve(&(c * &pm)).transpose();
    let i_lc = Mat::identity(n, n) - &gain * c;
    let p_updated =
        sym(&(mul(&mul(&i_lc, &pm), &i_lc.transpose()) + &gain * &r * gain.transpose()));
    Ok(Kalman {
        predictor_gain: a * &gain,
        p: pm,
        gain,
        p_updated,
        innovation: s,
        radius: d.closed_loop_radius,
    })
}

/// SDA from (A, G, H): (X, steps), or None if it broke down or did not converge.
fn sda(a: &Mat, g: &Mat, h: &Mat) -> Option<(Mat, usize)> {
    let n = a.nrows();
    let (mut ak, mut gk, mut hk) = (a.clone(), g.clone(), h.clone());
    for step in 1..=MAX_DOUBLING {
        // Products and solves through `linalg::product`: nalgebra's own below 96 states (the
        // reference cases' bits), faer's blocked kernels above (the 500 … 1000-state models).
        let w = Mat::identity(n, n) + mul(&gk, &hk);
        let (wa, wg) = product::solve_pair(&w, &ak, &gk)?; // W⁻¹A_k, W⁻¹G_k
        let at = ak.transpose();
        let h_next = sym(&(&hk + mul_symmetric(&mul(&at, &hk), &wa)));
        let g_next = sym(&(&gk + mul_symmetric(&mul(&ak, &wg), &at)));
        let a_next = mul(&ak, &wa);
        if !(h_next
            .iter()
            .chain(g_next.iter())
            .chain(a_next.iter())
            .all(|v| v.is_finite()))
        {
            return None;
        }
        // H_k increases to X; the step is A_kᵀ(…)A_k, so it dies with A_k (quadratically). A few
        // ε of ‖H‖ is rounding: stop there (a step that small cannot change X in double).
        let change = one_norm(&(&h_next - &hk));
        let size = one_norm(&h_next);
        hk = h_next;
        gk = g_next;
        ak = a_next;
        if change <= 4.0 * n as f64 * f64::EPSILON * size {
            return Some((hk, step));
        }
    }
    None
}

/// Up to `max` Newton steps from X, stopping when the correction is below rounding or stops
/// shrinking: (X, steps kept, converged).
fn newton_steps(
    a: &Mat,
    b: &Mat,
    q: &Mat,
    r: &Mat,
    mut x: Mat,
    max: usize,
) -> Result<(Mat, usize, bool)> {
    let mut last = f64::INFINITY;
    for step in 1..=max {
        let (k, ac) = gain(a, b, r, &x)?;
        let res = riccati_residual(a, b, q, r, &x, &k);
        let delta = lyapunov::discrete(&ac, &res)?;
        let size = one_norm(&delta);
        if !size.is_finite() {
            return Err(LtiError::NoConvergence("Newton's method for the DARE"));
        }
        // Past the quadratic phase the correction is rounding noise: one larger than the last
        // says so, and X stays as it was.
        if size > last && size <= 1e-8 * one_norm(&x) {
            return Ok((x, step - 1, true));
        }
        x = sym(&(&x + delta));
        if size <= 4.0 * f64::EPSILON * one_norm(&x) {
            return Ok((x, step, true));
        }
        last = size;
    }
    Ok((x, max, false))
}

/// Newton refinement above [`DD_MAX`] states, where the residual is formed in double: one step
/// at a time, kept while it lowers the relative residual, stopped once that is at rounding
/// ([`REFINED`]). Each step is a Stein equation (Smith's doubling, ~log₂(36/(1 − ρ)) products
/// of n × n); on the 1000-state model of BENCHMARKS.md SDA's X scored 5.4e-10, one step
/// 1.2e-15, and the next five moved X only by its rounding (corrections 1.9e-7 … 1.7e-7 on
/// ‖X‖₁ = 2.2e5) at 4–5 s each — the stopping rule of [`newton_steps`], made for
/// double-double residuals, never fired.
fn refine_large(a: &Mat, b: &Mat, q: &Mat, r: &Mat, x: Mat) -> Result<Refined> {
    let mut cur = Refined::of(a, b, q, r, x, 0)?;
    while cur.kept < MAX_REFINE && cur.score > REFINED {
        let Ok(delta) = lyapunov::discrete(&cur.ac, &cur.res) else {
            break;
        };
        if !one_norm(&delta).is_finite() {
            break;
        }
        let next_x = sym(&(&cur.x + delta));
        match Refined::of(a, b, q, r, next_x, cur.kept + 1) {
            Ok(next) if next.score < cur.score => cur = next,
            _ => break,
        }
    }
    Ok(cur)
}

/// A large model's iterate with what its test and its Newton step both need, each formed once:
/// K and A_c = A − BK, Res(X) (in double above [`DD_MAX`]) and the relative residual of
/// [`residual`] (A_cᵀXA_c by its lower triangle from 96 states on).
struct Refined {
    x: Mat,
    k: Mat,
    ac: Mat,
    res: Mat,
    score: f64,
    kept: usize,
}

impl Refined {
    fn of(a: &Mat, b: &Mat, q: &Mat, r: &Mat, x: Mat, kept: usize) -> Result<Self> {
        let (k, ac) = gain(a, b, r, &x)?;
        let acxac = mul_symmetric(&mul(&ac.transpose(), &x), &ac);
        let krk = k.transpose() * r * &k;
        let res = sym(&(q + &acxac + &krk - &x));
        let scale = one_norm(q) + one_norm(&acxac) + one_norm(&krk) + one_norm(&x);
        let norm = one_norm(&res);
        let score = if scale > 0.0 { norm / scale } else { norm };
        Ok(Refined {
            x,
            k,
            ac,
            res,
            score,
            kept,
        })
    }
}

/// The relative residual (as [`Dare::residual`]) at which a large model's refinement stops:
/// a few hundred ε, where a double-precision Newton step no longer improves X (1.2e-15 after
/// one step on the 1000-state model, then 5.4e-16 … 5.8e-16).
const REFINED: f64 = 64.0 * f64::EPSILON;

/// K = (R + BᵀXB)⁻¹BᵀXA and A − BK.
fn gain(a: &Mat, b: &Mat, r: &Mat, x: &Mat) -> Result<(Mat, Mat)> {
    // From 96 states on through faer's products (the n × n ones dominate); nalgebra's below,
    // in the same order: the reference designs' bits.
    let bt = b.transpose();
    let (s, rhs) = if a.nrows() < product::LARGE {
        (sym(&(r + &bt * x * b)), &bt * x * a)
    } else {
        let btx = mul(&bt, x);
        (sym(&(r + mul(&btx, b))), mul(&btx, a))
    };
    let k = match s.clone().cholesky() {
        Some(ch) => ch.solve(&rhs),
        // R + BᵀXB ≻ 0 for X ⪰ 0; an iterate slightly indefinite by rounding still solves.
        None => s.lu().solve(&rhs).ok_or(LtiError::Singular("R + BᵀXB"))?,
    };
    let ac = a - b * &k;
    Ok((k, ac))
}

/// Res(X) = Q + A_cᵀXA_c + KᵀRK − X, A_c = A − BK (the DARE's residual when K is X's gain),
/// evaluated in double-double and rounded once. In double its rounding, ~ε‖A_c‖²‖X‖, would be
/// the floor of Newton's refinement, and the Stein operator amplifies it by its condition
/// (10³ … 10⁴ on the sampled seeds, far more when X spans many decades); computed this way the
/// correction sees X's true residual and X converges to within its own rounding — mixed-precision
/// iterative refinement.
///
/// Above [`DD_MAX`] states the residual is formed in double: double-double products cost ~20×
/// theirs, and at n = 500 they were half of a UIO's design time. There X keeps SDA's and a
/// double-precision Newton step's accuracy (cond·ε) instead of ~1 ulp.
fn riccati_residual(a: &Mat, b: &Mat, q: &Mat, r: &Mat, x: &Mat, k: &Mat) -> Mat {
    if a.nrows() > DD_MAX {
        let ac = a - b * k;
        let acxac = mul(&mul(&ac.transpose(), x), &ac);
        return sym(&(q + acxac + k.transpose() * r * k - x));
    }
    let [a, b, q, r, x, k] = [a, b, q, r, x, k].map(DdMatrix::from_f64);
    let ac = a.add(&b.mul(&k), -1.0);
    let acxac = ac.transpose().mul(&x.mul(&ac));
    let krk = k.transpose().mul(&r.mul(&k));
    sym(&q.add(&acxac, 1.0).add(&krk, 1.0).add(&x, -1.0).to_f64())
}

/// (‖Res(X)‖₁ / (‖Q‖₁ + ‖A_cᵀXA_c‖₁ + ‖KᵀRK‖₁ + ‖X‖₁), K): the residual relative to the terms
/// it is the sum of, so that the correctly rounded X scores ~ε however its entries spread.
fn residual(a: &Mat, b: &Mat, q: &Mat, r: &Mat, x: &Mat) -> Result<(f64, Mat)> {
    let (k, ac) = gain(a, b, r, x)?;
    let res = one_norm(&riccati_residual(a, b, q, r, x, &k));
    let scale = one_norm(q)
        + one_norm(&mul(&mul(&ac.transpose(), x), &ac))
        + one_norm(&(k.transpose() * r * &k))
        + one_norm(x);
    Ok((if scale > 0.0 { res / scale } else { res }, k))
}

/// ρ(A − BK) for X's gain.
fn radius(a: &Mat, b: &Mat, r: &Mat, x: &Mat) -> Result<f64> {
    let (_, ac) = gain(a, b, r, x)?;
    Ok(spectral_radius(&eigenvalues(&ac)?))
}

/// Why no stabilising solution exists, if the staircase forms show it: uncontrollable modes of
/// (A, B) not inside the unit circle, or unobservable modes of (A, Q) on it. B and Q are scaled
/// to unit norm first: the staircase's rank tolerance is relative to max(‖A‖, ‖B‖), and a
/// weight's scale says nothing about which modes it sees.
fn obstruction(a: &Mat, b: &Mat, q: &Mat, words: Words) -> Option<String> {
    let unit = |m: &Mat| {
        let s = one_norm(m);
        if s > 0.0 { m / s } else { m.clone() }
    };
    let mut why = Vec::new();
    let uc = controllability_staircase(a, &unit(b))
        .uncontrollable_modes()
        .unwrap_or_default();
    let bad: Vec<C64> = uc
        .into_iter()
        .filter(|e| e.norm() >= 1.0 - NEAR_UNIT)
        .collect();
    let mut near = bad.clone();
    if !bad.is_empty() {
        let modes = format_list(&bad);
        why.push(match words {
            Words::Control => format!("(A, B) is not stabilisable: uncontrollable modes {modes} not inside the unit circle"),
            Words::Filter => format!("(A, C) is not detectable: unobservable modes {modes} not inside the unit circle"),
        });
    }
    let uo = observability_staircase(a, &unit(q))
        .unobservable_modes()
        .unwrap_or_default();
    let bad: Vec<C64> = uo
        .into_iter()
        .filter(|e| (e.norm() - 1.0).abs() < NEAR_UNIT)
        .collect();
    near.extend(&bad);
    if !bad.is_empty() {
        why.push(match words {
            Words::Control => format!("(A, Q) has unobservable modes {} on the unit circle", format_list(&bad)),
            Words::Filter => format!(
                "the process noise does not excite the modes {} on the unit circle ((A, Q_d) is not stabilisable there)",
                format_list(&bad)
            ),
        });
    }
    if why.is_empty() {
        return None;
    }
    let mut why = why.join("; ");
    if near.iter().any(|e| {
        let d = (e.norm() - 1.0).abs();
        d > 1e-12 && d < NEAR_UNIT
    }) {
        why.push_str(" (a modulus within 1e-6 of 1 counts as on the circle)");
    }
    Some(why)
}

/// The refusal when the iteration failed: the structural cause if there is one.
fn no_solution(a: &Mat, b: &Mat, q: &Mat, rho: Option<f64>, words: Words) -> LtiError {
    let loop_name = if words == Words::Control {
        "A − BK"
    } else {
        "A − ALC"
    };
    LtiError::NoStabilisingSolution(obstruction(a, b, q, words).unwrap_or_else(|| match rho {
        Some(rho) => {
            format!("the closed loop {loop_name} is not Schur-stable (spectral radius {rho:.6})")
        }
        None => "the doubling iteration did not converge".into(),
    }))
}

fn conform(name: &str, m: &Mat, rows: usize, cols: usize) -> Result<()> {
    if m.shape() != (rows, cols) {
        return Err(LtiError::Dimension(format!(
            "{name} is {}×{}, expected {rows}×{cols}",
            m.nrows(),
            m.ncols()
        )));
    }
    Ok(())
}

pub(crate) fn finite(name: &str, m: &Mat) -> Result<()> {
    if m.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(LtiError::InvalidInput(format!(
            "{name} has non-finite entries"
        )))
    }
}

/// What a symmetric argument must be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Definite {
    /// ⪰ 0 (a covariance, a state weight).
    Semi,
    /// ≻ 0 (an input weight, a measurement covariance that is inverted).
    Positive,
}

/// (M + Mᵀ)/2 after checking M finite, symmetric to scipy's tolerance (‖M − Mᵀ‖₁ ≤ 100 ε ‖M‖₁)
/// and definite: λ_min ≥ −τ for ⪰ 0, λ_min > τ for ≻ 0, τ = 100·n·ε·‖M‖₁ — the rounding of a
/// matrix that was formed by products, so that a computed covariance of exact rank deficiency
/// passes as ⪰ 0 and an R with cond(R) ≳ 10¹³/n counts as singular.
pub fn symmetric(name: &str, m: &Mat, definite: Definite) -> Result<Mat> {
    finite(name, m)?;
    let norm = one_norm(m);
    if one_norm(&(m - m.transpose())) > 100.0 * f64::EPSILON * norm {
        return Err(LtiError::InvalidInput(format!("{name} is not symmetric")));
    }
    let s = sym(m);
    if s.nrows() == 0 {
        return Ok(s);
    }
    let tol = 100.0 * s.nrows() as f64 * f64::EPSILON * norm;
    let min = s.clone().symmetric_eigenvalues().min();
    let ok = match definite {
        Definite::Semi => min >= -tol,
        Definite::Positive => min > tol,
    };
    if ok {
        Ok(s)
    } else {
        Err(not_definite(
            name,
            &s,
            if definite == Definite::Semi {
                "positive semi-definite"
            } else {
                "positive definite"
            },
        ))
    }
}

fn not_definite(name: &str, s: &Mat, what: &str) -> LtiError {
    let ev = s.clone().symmetric_eigenvalues();
    LtiError::InvalidInput(format!(
        "{name} is not {what}: its eigenvalues range from {:.3e} to {:.3e}",
        ev.min(),
        ev.max()
    ))
}

pub(crate) fn sym(m: &Mat) -> Mat {
    (m + m.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_closed_form() {
        // x = a²x − a²x²b²/(r + b²x) + q with a = 2, b = 1, q = 1, r = 1: x² − 4x − 1 = 0.
        let m = |v: f64| Mat::from_element(1, 1, v);
        let d = solve_dare(&m(2.0), &m(1.0), &m(1.0), &m(1.0)).unwrap();
        let want = 2.0 + 5f64.sqrt();
        assert!(
            (d.x[(0, 0)] - want).abs() <= 2.0 * f64::EPSILON * want,
            "{}",
            d.x[(0, 0)]
        );
        assert!(d.closed_loop_radius < 1.0);
    }

    #[test]
    fn zero_weight_and_no_input() {
        // Q = 0 with A stable: X = 0. No input columns: X solves the Stein equation X = AᵀXA + Q.
        let a = Mat::from_row_slice(2, 2, &[0.5, 0.2, 0.0, -0.3]);
        let d = solve_dare(
            &a,
            &Mat::identity(2, 2),
            &Mat::zeros(2, 2),
            &Mat::identity(2, 2),
        )
        .unwrap();
        assert_eq!(d.x, Mat::zeros(2, 2));
        let d = solve_dare(
            &a,
            &Mat::zeros(2, 0),
            &Mat::identity(2, 2),
            &Mat::zeros(0, 0),
        )
        .unwrap();
        let stein = lyapunov::discrete(&a, &Mat::identity(2, 2)).unwrap();
        assert!(
            (&d.x - &stein).amax() <= 4.0 * f64::EPSILON * stein.amax(),
            "{} vs {stein}",
            d.x
        );
        let unstable = Mat::from_row_slice(2, 2, &[1.5, 0.0, 0.0, 0.5]);
        let e = solve_dare(
            &unstable,
            &Mat::zeros(2, 0),
            &Mat::identity(2, 2),
            &Mat::zeros(0, 0),
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .ends_with("uncontrollable modes 1.5 not inside the unit circle"),
            "{e}"
        );
    }

    #[test]
    fn a_mode_within_the_margin_of_the_circle_is_named_so() {
        // The uncontrollable mode 1 − 10⁻⁸ is stable, but its closed loop cannot be told from
        // a marginal one: refused, and the message says why a stable modulus is listed.
        let a = Mat::from_row_slice(2, 2, &[1.0 - 1e-8, 0.0, 0.0, 2.0]);
        let b = Mat::from_row_slice(2, 1, &[0.0, 1.0]);
        let e = solve_dare(&a, &b, &Mat::identity(2, 2), &Mat::identity(1, 1))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "no stabilising solution: (A, B) is not stabilisable: uncontrollable modes 1 not inside the unit circle \
             (a modulus within 1e-6 of 1 counts as on the circle)"
        );
    }

    #[test]
    fn scalar_not_detectable_but_solvable() {
        // q = 0, a = 2: x = 0 solves but does not stabilise; x = 3 does (a − bk = 1/2).
        let m = |v: f64| Mat::from_element(1, 1, v);
        let d = solve_dare(&m(2.0), &m(1.0), &m(0.0), &m(1.0)).unwrap();
        assert!(
            (d.x[(0, 0)] - 3.0).abs() <= 4.0 * f64::EPSILON * 3.0,
            "{}",
            d.x[(0, 0)]
        );
        assert!((d.closed_loop_radius - 0.5).abs() < 1e-15);
    }
}
