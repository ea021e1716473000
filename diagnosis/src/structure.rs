//! Which residual reacts to which fault, computed from the designs.
//!
//! A member (F, G, K, P, Q) on the sampled plant, with a fault entering the state through a
//! column γ (x_{k+1} = Φx_k + γφ_k) or adding to output j (y_k = Cx_k + e_jφ_k), and residual
//! r = S(y − Cx̂) on its outputs S, is the system (u and the initial state do not matter for a
//! transfer)
//!
//! ```text
//! [x; z]_{k+1} = [[Φ, 0], [KC, F]] [x; z]_k + B_f φ_k,      B_f = [γ; 0]  or  [0; K e_j]
//! r_k = S[(I − CQ)C, −CP] [x; z]_k + D_f φ_k,                D_f = 0      or  S(I − CQ)e_j
//! ```
//!
//! Its transfer from φ to r is identically zero iff every Markov parameter D_f, C_a A_a^k B_f
//! (k < dim) is: the residual is then blind to the fault (for a UIO member, T γ = 0). Each is
//! measured relative to ‖C_a‖‖A_a^k‖‖B_f‖, so that rounding is told from a response.

use lti::Mat;
use nalgebra::DVector;
use observer::LinearObserver;

use crate::residual::Residual;

/// How a fault enters the plant.
#[derive(Debug, Clone)]
pub enum FaultInput {
    /// Through the state: the sampled column γ (for a fault held over the step).
    State(DVector<f64>),
    /// Added to output j.
    Output(usize),
}

/// Relative size of a response below which it is rounding.
pub const BLIND: f64 = 1e-9;

/// The largest relative Markov parameter of the fault-to-residual transfer: ≈ ε for a residual
/// blind to the fault, O(1e-3 … 1) for one that reacts.
pub fn sensitivity(
    phi: &Mat,
    c: &Mat,
    obs: &LinearObserver,
    outputs: &[usize],
    input: &FaultInput,
) -> f64 {
    let n = phi.nrows();
    let Residual {
        f, k, s, i_cq, cp, ..
    } = Residual::new(c, obs, outputs);
    let r = f.nrows();
    let dim = n + r;
    let mut a = Mat::zeros(dim, dim);
    a.view_mut((0, 0), (n, n)).copy_from(phi);
    a.view_mut((n, 0), (r, n)).copy_from(&(&k * c));
    a.view_mut((n, n), (r, r)).copy_from(&f);
    let mut ca = Mat::zeros(outputs.len(), dim);
    ca.view_mut((0, 0), (outputs.len(), n))
        .copy_from(&(&s * &i_cq * c));
    ca.view_mut((0, n), (outputs.len(), r))
        .copy_from(&(-(&s * &cp)));
    let mut b = DVector::zeros(dim);
    let mut direct = 0.0;
    match input {
        FaultInput::State(g) => b.rows_mut(0, n).copy_from(g),
        FaultInput::Output(j) => {
            b.rows_mut(n, r).copy_from(&k.column(*j));
            direct = (&s * i_cq.column(*j)).norm()
                / (s.norm() * i_cq.column(*j).norm()).max(f64::MIN_POSITIVE);
        }
    }
    let (cn, bn) = (ca.norm(), b.norm());
    let mut worst = direct;
    let mut ak = Mat::identity(dim, dim);
    for _ in 0..dim {
        let h = &ca * &ak * &b;
        let scale = cn * ak.norm() * bn;
        if scale > 0.0 {
            worst = worst.max(h.norm() / scale);
        }
        ak = &a * ak;
    }
    worst
}

/// A member's residual in steady state: its DC response to each constant fault, formed once per
/// member (T, (I − F)⁻¹, SCP) and then per fault.
///
/// The observer's state tracks z → Tx, with T from its unbiased output map PT + QC = I
/// (T = P⁺(I − QC), P of full column rank) and checked against TΦ − FT = KC. Then ζ = z − Tx
/// obeys ζ_{k+1} = Fζ_k + b φ_k and r = D_f φ − SCP ζ, whatever the plant does (its modes cancel,
/// even an integrator's), so the DC gain of the fault-to-residual transfer is
///
/// ```text
/// r_ss = D_f − SCP (I − F)⁻¹ b,      b = −Tγ (through the state)  or  K e_j (on output j).
/// ```
#[derive(Debug, Clone)]
pub struct SteadyState {
    t: Mat,
    k: Mat,
    s_i_cq: Mat,
    scp: Mat,
    resolvent: Mat,
}

impl SteadyState {
    /// For observer `obs` of the sampled plant (Φ, C), residual on `outputs`; `None` when its
    /// state is not a function of x (no T) or F has an eigenvalue at 1.
    pub fn new(phi: &Mat, c: &Mat, obs: &LinearObserver, outputs: &[usize]) -> Option<Self> {
        let Residual {
            f,
            k,
            p,
            q,
            s,
            i_cq,
            cp,
        } = Residual::new(c, obs, outputs);
        let n = phi.nrows();
        let t = lti::pinv::pinv(&p) * (Mat::identity(n, n) - &q * c);
        // T must make z an estimate of Tx: TΦ − FT = KC (and PT + QC = I).
        let sylvester = (&t * phi - &f * &t - &k * c).norm();
        let unbiased = (&p * &t + &q * c - Mat::identity(n, n)).norm();
        let scale = (t.norm() * (phi.norm() + f.norm()) + k.norm() * c.norm()).max(1.0);
        if sylvester > 1e-8 * scale || unbiased > 1e-8 * (1.0 + p.norm() * t.norm()) {
            return None;
        }
        let r = f.nrows();
        let resolvent = (Mat::identity(r, r) - &f).try_inverse()?;
        Some(SteadyState {
            scp: &s * &cp,
            s_i_cq: &s * &i_cq,
            t,
            k,
            resolvent,
        })
    }

    /// The relative steady-state response to a constant fault: ≈ ε when the residual returns to
    /// zero once the transient has passed (a UIO member's under a sensor bias, say), O(1e-3 … 1)
    /// when it stays. Measured relative to ‖D_f‖ + ‖SCP‖‖(I − F)⁻¹‖‖b‖ (with ‖T‖‖γ‖ for ‖Tγ‖),
    /// the size the terms that form it would have without cancellation.
    pub fn response(&self, input: &FaultInput) -> f64 {
        let (b, b_scale, direct) = match input {
            FaultInput::State(g) => (
                -(&self.t * g),
                self.t.norm() * g.norm(),
                DVector::zeros(self.scp.nrows()),
            ),
            FaultInput::Output(j) => (
                self.k.column(*j).into_owned(),
                self.k.column(*j).norm(),
                self.s_i_cq.column(*j).into_owned(),
            ),
        };
        let through = &self.scp * (&self.resolvent * &b);
        let rss = &direct - &through;
        // The size the response would have if nothing cancelled (a decoupled Tγ is rounding of ‖T‖‖γ‖).
        let size = direct.norm() + self.scp.norm() * self.resolvent.norm() * b_scale;
        if size > 0.0 { rss.norm() / size } else { 0.0 }
    }
}

/// Whether the residual reacts to the fault.
pub fn reacts(
    phi: &Mat,
    c: &Mat,
    obs: &LinearObserver,
    outputs: &[usize],
    input: &FaultInput,
) -> bool {
    sensitivity(phi, c, obs, outputs, input) > BLIND
}
