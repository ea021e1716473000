//! A windowed generalized likelihood ratio (GLR) test for the onset of a fault: evidence that
//! accumulates while a fault persists (Willsky & Jones, "A generalized likelihood ratio approach
//! to the detection and estimation of jumps in linear systems", IEEE TAC 21(1), 108–112, 1976;
//! Basseville & Nikiforov, "Detection of Abrupt Changes", 1993, §7.2).
//!
//! Why: the χ² test judges one sample at a time. Under a sensor bias a Luenberger or UIO
//! residual jumps, then settles to a DC value that is small against its noise (seed 003's
//! pitch-rate bias: per-sample χ² evidence ≈ 1 against a threshold of 18), so the fault is
//! isolated for the 2–3 % of its time the transient lasts. The jump itself is strong evidence
//! (≈ 45 in whitened units there); the GLR keeps it for as long as the onset stays in its window.
//!
//! 1. **Whitening in time.** A member's fault-free residual is the output of ([`crate::covariance`])
//!
//!    ```text
//!    ζ_{k+1} = Fζ_k − Mw_k + Kν_k,     r_k = Hζ_k + S(I − CQ)ν_k,     H = −SCP,
//!    ```
//!
//!    a coloured process. Its innovations form is the steady-state Kalman predictor of that
//!    system, whose two noises are correlated (S_n = KR(I − CQ)ᵀSᵀ; Q_n = MQ_dMᵀ + KRKᵀ,
//!    R_n = S(I − CQ)R(I − CQ)ᵀSᵀ): with X the stabilising solution of the filter DARE of
//!    (F − S_nR_n⁻¹H, H, Q_n − S_nR_n⁻¹S_nᵀ, R_n) (Anderson & Moore, "Optimal Filtering", 1979,
//!    §5.5),
//!
//!    ```text
//!    e_k = r_k − Hζ̂_k,   ζ̂_{k+1} = Fζ̂_k + L e_k,   Σ_e = HXHᵀ + R_n,   L = (FXHᵀ + S_n)Σ_e⁻¹,
//!    ```
//!
//!    and ε_k = W e_k (WᵀW = Σ_e⁻¹) is white, N(0, I_d), without a fault.
//! 2. **Signatures.** A unit step fault on channel j from step s adds ρ_{j,k−s} to ε_k: the
//!    noise-free response of the same filter to the fault, which enters ζ through b_j (−Mγ_j
//!    through the state, Ke_j on output j) and r directly through d_j (0, or S(I − CQ)e_j) —
//!    the routes of [`crate::structure`].
//! 3. **The test.** For an onset s and channel j, the fault's size that best explains
//!    ε_s … ε_k is c/I with c = Σ_{i ≤ k−s} ρ_{j,i}ᵀε_{s+i}, I = Σ_{i ≤ k−s} ‖ρ_{j,i}‖², and twice
//!    the log-likelihood ratio is c²/I. The statistic is its largest value
//!
//!    ```text
//!    g_k = max { c_{s,j}² / I_{j,k−s} :  k − N < s ≤ k,  s ≥ the first decided step,  j reacts }
//!    ```
//!
//!    over the onsets in a window of N samples and the channels the member's residual reacts to
//!    (its row of the structure matrix). Onsets before the first decided step are not tried: the
//!    observers' start-up transient is no fault. For one (s, j) without a fault c/√I ~ N(0, 1),
//!    so c²/I ~ χ²(1); the threshold h = χ²₁ quantile at 1 − α/(N·J) bounds P(g_k > h) by α per
//!    sample (the union bound over the N·J pairs — conservative, since neighbouring onsets are
//!    strongly correlated; the sweep measures the actual rate).
//!
//! 4. **Start-up.** The observer starts away from the plant (ζ_0 = z_0 − Mx_0), and the steady
//!    predictor forgets a wrong ζ̂_0 only at the rate of F − LH, which can be far slower than F
//!    (seed 003's members: |λ| = 0.9917 against 0.97). Until the first decided step the predictor
//!    is the time-varying Kalman filter from a diffuse start, P_0 = κI with κ = 10⁶·max(1, ‖X‖):
//!    L_k = (FP_kHᵀ + S_n)Σ_{e,k}⁻¹ and, in Joseph's form,
//!    P_{k+1} = (F − L_kH)P_k(F − L_kH)ᵀ + Q_n − L_kS_nᵀ − S_nL_kᵀ + L_kR_nL_kᵀ,
//!    which takes the start-up transient into ζ̂ within a few samples; from then on the steady L. (On seed 003's recorded residuals: innovations of
//!    variance 1.04 and lag-1 correlation −0.02 from 3 s on, against 1.5–2.3 with the steady
//!    predictor from ζ̂_0 = 0.)
//!
//! Cost per step and member: N·J·d multiply-adds (the correlations of every onset in the window
//! are kept and extended by one term), plus the predictor's r² + r·d.

use lti::Mat;
use nalgebra::DVector;
use observer::LinearObserver;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::covariance::tracked;
use crate::evaluate::whitening;
use crate::residual::Residual;
use crate::spec::GlrSpec;
use crate::structure::FaultInput;

/// One member's GLR test, designed.
#[derive(Debug, Clone)]
pub struct GlrDesign {
    /// F of the residual's model (the member's observer).
    f: Mat,
    /// H = −SCP.
    h: Mat,
    /// L, the innovations predictor's gain.
    pub gain: Mat,
    /// Q_n, R_n and S_n of the residual's model (for the start-up's time-varying gains).
    q_n: Mat,
    r_n: Mat,
    s_n: Mat,
    /// Σ_e, the innovation covariance.
    pub innovation: Mat,
    /// W with WᵀW = Σ_e⁻¹.
    w: Mat,
    /// The channels tested (indices into the bank's watched channels).
    pub channels: Vec<usize>,
    /// Per tested channel: ρ_{j,i}, i < N, row-major (N × d).
    signatures: Vec<Vec<f64>>,
    /// Per tested channel: I_{j,i} = Σ_{l ≤ i} ‖ρ_{j,l}‖².
    information: Vec<Vec<f64>>,
    /// N.
    pub window: usize,
    /// κ of the diffuse start.
    kappa: f64,
    /// h.
    pub threshold: f64,
}

impl GlrDesign {
    /// The test of a member: observer `obs` of the sampled plant (Φ, C), residual on `outputs`,
    /// testing the channels `tested` (indices into `inputs`) with noise (Q_d, R).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        phi: &Mat,
        c: &Mat,
        obs: &LinearObserver,
        outputs: &[usize],
        inputs: &[FaultInput],
        tested: Vec<usize>,
        (qd, r): (&Mat, &Mat),
        spec: GlrSpec,
        dt: f64,
    ) -> Result<Self, String> {
        let Residual {
            f, k, s, i_cq, cp, ..
        } = Residual::new(c, obs, outputs);
        let m = tracked(phi, &f, &k, c)?;
        let h = -(&s * &cp);
        let d_nu = &s * &i_cq;
        let q_n = sym(&(&m * qd * m.transpose() + &k * r * k.transpose()));
        let r_n = sym(&(&d_nu * r * d_nu.transpose()));
        let s_n = &k * r * d_nu.transpose();
        let r_inv = r_n.clone().cholesky().map(|ch| ch.inverse()).ok_or(
            "its residual has a direction without measurement noise (S(I − CQ)R(I − CQ)ᵀSᵀ is singular), \
             which the GLR's whitening in time does not cover",
        )?;
        let f_bar = &f - &s_n * &r_inv * &h;
        let q_bar = sym(&(&q_n - &s_n * &r_inv * s_n.transpose()));
        let kalman = lti::dare::steady_state_kalman(&f_bar, &h, &q_bar, &r_n)
            .map_err(|e| format!("the residual's innovations filter: {e}"))?;
        let x = kalman.p;
        let innovation = sym(&(&h * &x * h.transpose() + &r_n));
        let gain = (&f * &x * h.transpose() + &s_n)
            * innovation
                .clone()
                .cholesky()
                .ok_or("the innovation covariance is not positive definite")?
                .inverse();
        let w = whitening(&innovation);
        let window = ((spec.window / dt).round() as usize).max(1);
        let d = w.nrows();
        let mut signatures = Vec::with_capacity(tested.len());
        let mut information = Vec::with_capacity(tested.len());
        for &j in &tested {
            let (b, direct) = match &inputs[j] {
                FaultInput::State(g) => (-(&m * g), DVector::zeros(outputs.len())),
                FaultInput::Output(o) => (k.column(*o).into_owned(), d_nu.column(*o).into_owned()),
            };
            let (mut zeta, mut zeta_hat) = (DVector::zeros(f.nrows()), DVector::zeros(f.nrows()));
            let mut rho = Vec::with_capacity(window * d);
            let mut info = Vec::with_capacity(window);
            let mut total = 0.0;
            for _ in 0..window {
                let e = &h * &zeta + &direct - &h * &zeta_hat;
                let eps = &w * &e;
                total += eps.norm_squared();
                rho.extend(eps.iter());
                info.push(total);
                zeta = &f * zeta + &b;
                zeta_hat = &f * zeta_hat + &gain * e;
            }
            signatures.push(rho);
            information.push(info);
        }
        let pairs = (window * tested.len()).max(1) as f64;
        let chi = ChiSquared::new(1.0).map_err(|e| e.to_string())?;
        let threshold = chi.inverse_cdf(1.0 - spec.false_alarm / pairs);
        Ok(GlrDesign {
            f,
            h,
            gain,
            q_n,
            r_n,
            s_n,
            innovation,
            w,
            channels: tested,
            signatures,
            information,
            window,
            threshold,
            kappa: 1e6 * x.norm().max(1.0),
        })
    }

    /// d, the dimension of ε.
    pub fn dim(&self) -> usize {
        self.w.nrows()
    }
}

/// A change the test has confirmed: a step of `size` on tested channel `channel` from `onset`;
/// `open` while it is a fault not yet ended (a fault's end and the steps it undoes are closed).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Jump {
    channel: usize,
    onset: u64,
    size: f64,
    open: bool,
}

/// Most changes held at once (a fault that grows in steps, a drift, adds one per confirmation;
/// the oldest is dropped beyond this).
const MAX_JUMPS: usize = 8;

/// A member's GLR test over a run, step by step (no allocation per step once the start-up's
/// time-varying filter has ended).
///
/// Confirmation and compensation (Willsky & Jones 1976, §IV): once g_k has exceeded h for
/// `persistence` consecutive steps, the best (s, j) is taken as a change of size ν = c/I, and
/// its signature ν ρ_{j,k−s} is subtracted from the innovations that follow, so that the test
/// looks for the next change. A step back of the same channel that brings the net size |Σν|
/// below half the largest of its steps is the fault ending, and closes its changes; any other
/// change adds to the fault. The member is in alarm while an open change's onset is within the
/// window — the window is the test's memory, as one sample is the χ² test's — but every change
/// stays compensated (beyond the window with its signature's last value, ≈ its DC value) until
/// it is closed and its fault's last change has left the window: a fault that outlasts the window
/// is not found again from its own DC tail, and its end is still seen as its end.
#[derive(Debug, Clone)]
pub struct Glr {
    design: GlrDesign,
    persistence: u32,
    /// The first onset tried.
    first: u64,
    /// The first decided step: the time-varying start-up ends there.
    start: u64,
    /// P_k of the start-up, while it lasts.
    p_k: Option<Mat>,
    zeta_hat: Vec<f64>,
    next: Vec<f64>,
    e: Vec<f64>,
    eps: Vec<f64>,
    /// Per tested channel: c of onset s at slot s mod N.
    sums: Vec<Vec<f64>>,
    /// Consecutive steps with g > h.
    count: u32,
    jumps: Vec<Jump>,
    /// The step last pushed.
    now: u64,
}

impl Glr {
    /// Trying onsets from step `first` on; a change is confirmed after `persistence` consecutive
    /// exceedances.
    pub fn new(design: GlrDesign, first: u64, persistence: u32) -> Self {
        let r = design.f.nrows();
        let d = design.dim();
        Glr {
            first,
            start: first,
            p_k: (first > 0).then(|| Mat::identity(r, r) * design.kappa),
            persistence: persistence.max(1),
            zeta_hat: vec![0.0; r],
            next: vec![0.0; r],
            e: vec![0.0; design.h.nrows()],
            eps: vec![0.0; d],
            sums: vec![vec![0.0; design.window]; design.channels.len()],
            count: 0,
            jumps: Vec::with_capacity(MAX_JUMPS + 1),
            now: 0,
            design,
        }
    }

    /// The threshold h.
    pub fn threshold(&self) -> f64 {
        self.design.threshold
    }

    /// Whether a confirmed change that is not undone is held, its onset within the window (the
    /// member's GLR alarm after the step last pushed).
    pub fn alarm(&self) -> bool {
        let n = self.design.window as u64;
        self.jumps
            .iter()
            .any(|j| j.open && self.now.saturating_sub(j.onset) < n)
    }

    /// g_k of the member's residual r_k at step k: the statistic of the next change.
    pub fn push(&mut self, k: u64, r: &[f64]) -> f64 {
        let dg = &self.design;
        lti::kernel::mul_into(&mut self.e, &dg.h, &self.zeta_hat);
        for (e, &r) in self.e.iter_mut().zip(r) {
            *e = r - *e;
        }
        lti::kernel::mul_into(&mut self.eps, &dg.w, &self.e);
        lti::kernel::mul_into(&mut self.next, &dg.f, &self.zeta_hat);
        match &mut self.p_k {
            Some(p) if k < self.start => {
                let gain = start_up_gain(dg, p);
                lti::kernel::mul_acc(&mut self.next, &gain, &self.e);
            }
            _ => {
                self.p_k = None;
                lti::kernel::mul_acc(&mut self.next, &dg.gain, &self.e);
            }
        }
        std::mem::swap(&mut self.zeta_hat, &mut self.next);
        self.now = k;
        if k < self.first {
            return 0.0;
        }
        let n = dg.window as u64;
        let d = self.eps.len();
        // A fault's changes, once closed, are dropped together when the youngest has left the
        // window: their signatures' tails then cancel (to the error of their net size).
        for ch in 0..dg.channels.len() {
            let closed = |j: &Jump| !j.open && j.channel == ch;
            if self
                .jumps
                .iter()
                .filter(|j| closed(j))
                .all(|j| k - j.onset >= n)
            {
                self.jumps.retain(|j| !closed(j));
            }
        }
        // Every held change's signature leaves the innovations (its last value beyond the window).
        for jump in &self.jumps {
            let age = ((k - jump.onset) as usize).min(dg.window - 1);
            let rho = &dg.signatures[jump.channel][age * d..age * d + d];
            for (e, &r) in self.eps.iter_mut().zip(rho) {
                *e -= jump.size * r;
            }
        }
        let oldest = self.first.max((k + 1).saturating_sub(n));
        let mut best = (0.0f64, 0usize, k, 0.0f64);
        for (ch, (sums, (rho, info))) in self
            .sums
            .iter_mut()
            .zip(dg.signatures.iter().zip(&dg.information))
            .enumerate()
        {
            sums[(k % n) as usize] = 0.0;
            for s in oldest..=k {
                let age = (k - s) as usize;
                let slot = &mut sums[(s % n) as usize];
                let row = &rho[age * d..age * d + d];
                *slot += row.iter().zip(&self.eps).map(|(a, b)| a * b).sum::<f64>();
                if info[age] > 0.0 {
                    let g = *slot * *slot / info[age];
                    if g > best.0 {
                        best = (g, ch, s, *slot / info[age]);
                    }
                }
            }
        }
        let (g, channel, onset, size) = best;
        self.count = if g > dg.threshold {
            self.count.saturating_add(1)
        } else {
            0
        };
        if self.count >= self.persistence {
            self.confirm(Jump {
                channel,
                onset,
                size,
                open: true,
            });
            // The next change is looked for from the next step, in compensated innovations.
            self.first = k + 1;
            self.count = 0;
        }
        g
    }

    /// Holds a confirmed change; when it brings its channel's net size back to (near) zero, the
    /// fault has ended, and the channel's changes are closed.
    fn confirm(&mut self, mut jump: Jump) {
        let ours = |j: &&Jump| j.open && j.channel == jump.channel;
        let before: Vec<f64> = self.jumps.iter().filter(ours).map(|j| j.size).collect();
        let net: f64 = before.iter().sum::<f64>() + jump.size;
        let largest = before.iter().fold(jump.size.abs(), |a, b| a.max(b.abs()));
        if !before.is_empty() && net.abs() < 0.5 * largest {
            for j in self.jumps.iter_mut().filter(|j| j.channel == jump.channel) {
                j.open = false;
            }
            jump.open = false;
        }
        if self.jumps.len() == MAX_JUMPS {
            self.jumps.remove(0);
        }
        self.jumps.push(jump);
    }
}

/// L_k of the start-up's time-varying filter, and P_k advanced to P_{k+1} (module docs, 4).
fn start_up_gain(dg: &GlrDesign, p: &mut Mat) -> Mat {
    let ht = dg.h.transpose();
    let innovation = sym(&(&dg.h * &*p * &ht + &dg.r_n));
    let gain = match innovation.cholesky() {
        Some(ch) => (&dg.f * &*p * &ht + &dg.s_n) * ch.inverse(),
        None => dg.gain.clone(),
    };
    let a = &dg.f - &gain * &dg.h;
    let cross = &gain * dg.s_n.transpose();
    *p = sym(
        &(&a * &*p * a.transpose() + &dg.q_n - &cross - cross.transpose()
            + &gain * &dg.r_n * gain.transpose()),
    );
    gain
}

fn sym(m: &Mat) -> Mat {
    (m + m.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The design for a residual that is its measurement noise (r = ν, σ = 2: F = 0.2 with no
    /// input, so the observer's state stays 0), one tested output, dt = 1, α = 10⁻³.
    fn white_residual(window: f64) -> GlrDesign {
        let obs = LinearObserver {
            f: (&Mat::from_row_slice(1, 1, &[0.2])).into(),
            g: (&Mat::zeros(1, 0)).into(),
            k: (&Mat::zeros(1, 1)).into(),
            p: (&Mat::from_row_slice(1, 1, &[1.0])).into(),
            q: (&Mat::zeros(1, 1)).into(),
            xhat0: None,
            offset: None,
        };
        let spec = GlrSpec {
            window,
            false_alarm: 1e-3,
        };
        GlrDesign::new(
            &Mat::from_row_slice(1, 1, &[0.5]),
            &Mat::from_row_slice(1, 1, &[1.0]),
            &obs,
            &[0],
            &[FaultInput::Output(0)],
            vec![0],
            (&Mat::zeros(1, 1), &Mat::from_row_slice(1, 1, &[4.0])),
            spec,
            1.0,
        )
        .unwrap()
    }

    /// A white residual: the innovations are the residual itself, a step on the output has the
    /// flat signature ±1/σ, and a step of 2σ from step 3 on gives g_k = 4(k − 2).
    #[test]
    fn a_white_residual_is_its_own_innovation_and_a_step_accumulates_linearly() {
        let g = white_residual(5.0);
        assert!((g.innovation[(0, 0)] - 4.0).abs() < 1e-12);
        assert_eq!(g.window, 5);
        for i in 0..5 {
            assert!((g.signatures[0][i].abs() - 0.5).abs() < 1e-12);
            assert!((g.information[0][i] - 0.25 * (i + 1) as f64).abs() < 1e-12);
        }
        // The union bound over N·J = 5 pairs: χ²₁ at 1 − 2·10⁻⁴ is 13.83.
        assert!((g.threshold - 13.83).abs() < 0.01, "{}", g.threshold);
        // Persistence 10: no confirmation within these steps.
        let mut t = Glr::new(g, 0, 10);
        for k in 0..3 {
            assert_eq!(t.push(k, &[0.0]), 0.0);
        }
        for k in 3..8u64 {
            let got = t.push(k, &[4.0]);
            let want = 4.0 * (k - 2) as f64;
            assert!(
                (got - want).abs() < 1e-9 * want,
                "k {k}: {got} against {want}"
            );
        }
        assert!(!t.alarm());
    }

    /// The same white residual with a window of 20 (h = χ²₁ at 1 − 10⁻³/20, 16.45): a step of 2σ
    /// from step 3 is confirmed at its fifth sample (g = 20; persistence 1), held while it lasts
    /// (compensated, so g falls back), and cleared when the step back is confirmed five samples
    /// after it.
    #[test]
    fn a_step_is_held_until_the_step_back_is_seen() {
        let mut t = Glr::new(white_residual(20.0), 0, 1);
        let alarms: Vec<bool> = (0..22u64)
            .map(|k| {
                let r = if (3..13).contains(&k) { 4.0 } else { 0.0 };
                t.push(k, &[r]);
                t.alarm()
            })
            .collect();
        assert!((t.threshold() - 16.45).abs() < 0.01, "{}", t.threshold());
        let on: Vec<u64> = (0..22).filter(|&k| alarms[k as usize]).collect();
        assert_eq!(on, (7..17).collect::<Vec<u64>>());
    }
}
