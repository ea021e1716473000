//! Frequency responses of an observer's estimation error and of a residual: what of an unknown
//! input w, of sensor noise v and of a fault f reaches e = x − x̂ and r = S(y − Cx̂), frequency
//! by frequency ([`lti::freq`]).
//!
//! For an observer (F, G, K, P, Q) of the sampled plant x⁺ = Φx + Γ_B u + Γ_E w, y = Cx + v, the
//! plant and observer together are ([`crate::structure`]'s system; u does not reach e or r when
//! the observer is unbiased, and does not matter for the others' transfers)
//!
//! ```text
//! [x; z]⁺ = A_a [x; z] + [Γ_E; 0] w + [0; K] v,          A_a = [[Φ, 0], [KC, F]],
//! e = x − x̂ = [I − QC, −P] [x; z] − Q v,
//! r = S(y − Cx̂) = S[(I − CQ)C, −CP] [x; z] + S(I − CQ) v,
//! ```
//!
//! so w → e is (A_a, [Γ_E; 0], [I − QC, −P], 0), v → e is (A_a, [0; K], [I − QC, −P], −Q), and the
//! residual's the same with S[(I − CQ)C, −CP] and D = S(I − CQ) for v. A fault entering the state
//! through the sampled column γ enters as [γ; 0]; one added to output j as v does on that output
//! ([0; Ke_j], D = S(I − CQ)e_j). The plant's own modes cancel from e and r of an unbiased
//! observer; they stay in A_a, which is why it is this form and not the observer-order one
//! ζ = z − Mx (MΦ − FM = KC): that M does not exist when the observer shares a pole with the
//! plant (seed 002's UIO and Luenberger observer place −1, −2, −3 where the plant has −1, −2, −2).
//! At z = 1 a plant integrator (Φ with an eigenvalue at 1, a shaft angle) leaves A_a singular;
//! where M exists and the observer is unbiased, the DC gain is that of the observer-order
//! realisation (F, −MΓ_E, −P, 0) … in which the integrator is not a state, else it is not given.
//!
//! A UIO decouples w: its w → e is rounding. It is reported as decoupled when every Markov
//! parameter C_a A_a^k B_w (and D) is below [`DECOUPLED`] of ‖C_a‖‖A_a^k‖‖B_w‖, the rule of the
//! structure matrix ([`crate::structure::BLIND`]); its σ are then the rounding's, shown as such.

use std::cell::OnceCell;

use lti::Mat;
use lti::freq::Sampled;
use observer::LinearObserver;

use crate::covariance::tracked;
use crate::residual::Residual;
use crate::structure::{BLIND, FaultInput};

/// The largest relative Markov parameter of w → e below which it is rounding: the observer
/// decouples w.
pub const DECOUPLED: f64 = BLIND;

/// An observer's error and residual systems.
#[derive(Debug, Clone)]
pub struct ErrorSystems {
    /// w → e (`None` without unknown inputs).
    pub w_e: Option<Sampled>,
    /// v → e.
    pub v_e: Sampled,
    /// w → r.
    pub w_r: Option<Sampled>,
    /// v → r.
    pub v_r: Sampled,
    /// w does not reach e: every relative Markov parameter of w → e is below [`DECOUPLED`].
    pub w_decoupled: bool,
    /// The state z tracks, M (MΦ − FM = KC), when it exists and the observer is unbiased
    /// (PM + QC = I): the systems then have a realisation of the observer's order, ζ = z − Mx,
    /// which gives their DC gain where the plant has an integrator. Solved on first use only (its
    /// Kronecker system has (n·r)² entries), once.
    m: OnceCell<Option<Mat>>,
    phi: Mat,
    c: Mat,
    p: Mat,
    q: Mat,
    s_cp: Mat,
    gamma_e: Mat,
    /// F (for the grid's lower end).
    f: Mat,
    /// A_a, C_r and S(I − CQ) of the residual, for faults.
    a: Mat,
    c_r: Mat,
    s_i_cq: Mat,
    k: Mat,
    dt: f64,
}

impl ErrorSystems {
    /// For observer `obs` of the sampled plant (Φ, Γ_E, C) at `dt`, residual on `outputs`.
    pub fn new(
        phi: &Mat,
        gamma_e: &Mat,
        c: &Mat,
        obs: &LinearObserver,
        outputs: &[usize],
        dt: f64,
    ) -> Self {
        let res = Residual::new(c, obs, outputs);
        let (n, r, p, q) = (phi.nrows(), res.f.nrows(), c.nrows(), gamma_e.ncols());
        let dim = n + r;
        let mut a = Mat::zeros(dim, dim);
        a.view_mut((0, 0), (n, n)).copy_from(phi);
        a.view_mut((n, 0), (r, n)).copy_from(&(&res.k * c));
        a.view_mut((n, n), (r, r)).copy_from(&res.f);
        let joined = |left: Mat, right: Mat| {
            let mut m = Mat::zeros(left.nrows(), dim);
            m.view_mut((0, 0), (left.nrows(), n)).copy_from(&left);
            m.view_mut((0, n), (left.nrows(), r)).copy_from(&right);
            m
        };
        let c_e = joined(Mat::identity(n, n) - &res.q * c, -&res.p);
        let c_r = joined(&res.s * &res.i_cq * c, -(&res.s * &res.cp));
        let mut b_w = Mat::zeros(dim, q);
        b_w.view_mut((0, 0), (n, q)).copy_from(gamma_e);
        let mut b_v = Mat::zeros(dim, p);
        b_v.view_mut((n, 0), (r, p)).copy_from(&res.k);
        let sys = |b: &Mat, c: &Mat, d: Mat| Sampled {
            a: a.clone(),
            b: b.clone(),
            c: c.clone(),
            d,
            dt,
        };
        let s_i_cq = &res.s * &res.i_cq;
        let (w_e, w_r) = if q > 0 {
            (
                Some(sys(&b_w, &c_e, Mat::zeros(n, q))),
                Some(sys(&b_w, &c_r, Mat::zeros(outputs.len(), q))),
            )
        } else {
            (None, None)
        };
        let w_decoupled = q > 0 && markov_size(&a, &b_w, &c_e) <= DECOUPLED;
        ErrorSystems {
            m: OnceCell::new(),
            phi: phi.clone(),
            c: c.clone(),
            p: res.p.clone(),
            q: res.q.clone(),
            s_cp: &res.s * &res.cp,
            gamma_e: gamma_e.clone(),
            w_e,
            v_e: sys(&b_v, &c_e, -&res.q),
            w_r,
            v_r: sys(&b_v, &c_r, s_i_cq.clone()),
            w_decoupled,
            f: res.f.clone(),
            a,
            c_r,
            s_i_cq,
            k: res.k,
            dt,
        }
    }

    /// M, solved on first use: `None` when it does not exist or the observer is biased.
    fn tracked(&self) -> Option<&Mat> {
        self.m
            .get_or_init(|| {
                let (phi, c, f, k) = (&self.phi, &self.c, &self.f, &self.k);
                let n = phi.nrows();
                tracked(phi, f, k, c).ok().filter(|m| {
                    let sylvester = (m * phi - f * m - k * c).norm();
                    let scale = m.norm() * (phi.norm() + f.norm()) + k.norm() * c.norm();
                    let unbiased = (&self.p * m + &self.q * c - Mat::identity(n, n)).norm();
                    sylvester <= 1e-10 * scale.max(f64::MIN_POSITIVE)
                        && unbiased <= 1e-8 * (1.0 + (&self.p * m).norm())
                })
            })
            .as_ref()
    }

    /// The realisations of the observer's order (ζ = z − Mx) of w → e, v → e, w → r, v → r, when
    /// M exists: the same transfers without the plant's modes, for their DC gains.
    pub fn reduced(&self) -> Option<[Option<Sampled>; 4]> {
        let m = self.tracked()?;
        let sys = |b: Mat, c: Mat, d: Mat| Sampled {
            a: self.f.clone(),
            b,
            c,
            d,
            dt: self.dt,
        };
        let (n, q, ny) = (self.p.nrows(), self.gamma_e.ncols(), self.s_cp.nrows());
        let w_in = -(m * &self.gamma_e);
        let w = |c: Mat, rows: usize| (q > 0).then(|| sys(w_in.clone(), c, Mat::zeros(rows, q)));
        Some([
            w(-&self.p, n),
            Some(sys(self.k.clone(), -&self.p, -&self.q)),
            w(-&self.s_cp, ny),
            Some(sys(self.k.clone(), -&self.s_cp, self.s_i_cq.clone())),
        ])
    }

    /// [`ErrorSystems::fault`] in the observer's order, when M exists.
    pub fn reduced_fault(&self, input: &FaultInput) -> Option<Sampled> {
        let m = self.tracked()?;
        let (b, d) = match input {
            FaultInput::State(g) => (
                -(m * Mat::from_column_slice(g.len(), 1, g.as_slice())),
                Mat::zeros(self.s_cp.nrows(), 1),
            ),
            FaultInput::Output(j) => (
                self.k.columns(*j, 1).into_owned(),
                self.s_i_cq.columns(*j, 1).into_owned(),
            ),
        };
        Some(Sampled {
            a: self.f.clone(),
            b,
            c: -&self.s_cp,
            d,
            dt: self.dt,
        })
    }

    /// f → r for a fault entering as `input`.
    pub fn fault(&self, input: &FaultInput) -> Sampled {
        let (dim, n) = (self.a.nrows(), self.a.nrows() - self.f.nrows());
        let mut b = Mat::zeros(dim, 1);
        let mut d = Mat::zeros(self.c_r.nrows(), 1);
        match input {
            FaultInput::State(g) => b
                .view_mut((0, 0), (n, 1))
                .copy_from(&Mat::from_column_slice(g.len(), 1, g.as_slice())),
            FaultInput::Output(j) => {
                b.view_mut((n, 0), (self.f.nrows(), 1))
                    .copy_from(&self.k.columns(*j, 1));
                d.copy_from(&self.s_i_cq.columns(*j, 1));
            }
        }
        Sampled {
            a: self.a.clone(),
            b,
            c: self.c_r.clone(),
            d,
            dt: self.dt,
        }
    }

    /// The slowest rate of the observer's modes, rad/s: min |ln λ(F)| / Δt (where its σ plots
    /// should start a decade or two below).
    pub fn slowest_rate(&self) -> f64 {
        lti::eig::eigenvalues(&self.f)
            .unwrap_or_default()
            .iter()
            .map(|l| l.ln().norm() / self.dt)
            .filter(|r| r.is_finite() && *r > 0.0)
            .fold(f64::INFINITY, f64::min)
    }
}

/// max_k ‖C A^k B‖ / (‖C‖‖A^k‖‖B‖) over k < dim: ≈ ε for a transfer that is identically zero.
fn markov_size(a: &Mat, b: &Mat, c: &Mat) -> f64 {
    let (cn, bn) = (c.norm(), b.norm());
    if cn == 0.0 || bn == 0.0 {
        return 0.0;
    }
    let mut ak = Mat::identity(a.nrows(), a.nrows());
    let mut worst: f64 = 0.0;
    for _ in 0..a.nrows() {
        let scale = cn * ak.norm() * bn;
        if scale > 0.0 {
            worst = worst.max((c * &ak * b).norm() / scale);
        }
        ak = a * ak;
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use lti::eig::C64;

    /// A scalar plant x⁺ = φx + γw, y = x + v under a Luenberger observer z⁺ = (φ − l)z + l y
    /// (x̂ = z): e⁺ = (φ − l)e + γw − lv, so w → e is γ/(z − φ + l), v → e is −l/(z − φ + l),
    /// and r = y − x̂ = e + v.
    #[test]
    fn a_scalar_luenberger_observer_has_its_textbook_error_transfers() {
        let (phi, gam, l, dt) = (0.95, 0.3, 0.5, 0.1);
        let obs = LinearObserver {
            f: (&Mat::from_element(1, 1, phi - l)).into(),
            g: (&Mat::zeros(1, 0)).into(),
            k: (&Mat::from_element(1, 1, l)).into(),
            p: (&Mat::identity(1, 1)).into(),
            q: (&Mat::zeros(1, 1)).into(),
            xhat0: None,
            offset: None,
        };
        let one = Mat::identity(1, 1);
        let sys = ErrorSystems::new(
            &Mat::from_element(1, 1, phi),
            &Mat::from_element(1, 1, gam),
            &one,
            &obs,
            &[0],
            dt,
        );
        assert!(!sys.w_decoupled);
        for w in [0.01, 1.0, 10.0, 31.0] {
            let z = C64::from_polar(1.0, w * dt);
            let pole = z - (phi - l);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs();
            assert!(close(
                sys.w_e.as_ref().unwrap().sigma(w).0,
                gam / pole.norm()
            ));
            assert!(close(sys.v_e.sigma(w).0, l / pole.norm()));
            // r = e + v: v → r = 1 − l/(z − φ + l).
            assert!(close(sys.v_r.sigma(w).0, (1.0 - l / pole).norm()));
            // A bias on y1 enters as v does.
            assert!(close(
                sys.fault(&FaultInput::Output(0)).sigma(w).0,
                (1.0 - l / pole).norm()
            ));
        }
    }
}
