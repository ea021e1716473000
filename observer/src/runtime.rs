//! The sampled-data observer every design reduces to, as a step function.
//!
//! ```text
//! z_{k+1} = F z_k + G u_k + K y_k,      x̂_k = P z_k + Q y_k,      z_0 = 0.
//! ```
//!
//! With an initial estimate x̂₀ (`xhat0` in the scenario) the start is z_0 = P⁺(x̂₀ − Q y_0),
//! formed at the first sample: x̂_0 = x̂₀ exactly for full-order observers (P = I), and its
//! projection P P⁺(x̂₀ − Qy_0) + Qy_0 on what a reduced-order observer can hold (the part of the
//! state the outputs give is taken from y_0). Without it z_0 = 0, so x̂_0 = Q y_0: for a UIO
//! x̂_0 = H y_0, for a Luenberger observer 0.
//!
//! A design made in deviations from an operating point (x_op, u_op, y_op; [`lti::OperatingPoint`])
//! runs on the plant's absolute signals with two constant offsets,
//!
//! ```text
//! z_{k+1} = F z_k + G u_k + K y_k + c_z,   c_z = −(G u_op + K y_op),
//! x̂_k     = P z_k + Q y_k + c_x,           c_x = x_op − Q y_op,
//! ```
//!
//! i.e. z⁺ = Fz + Gδu + Kδy and x̂ = x_op + Pz + Qδy: without an initial estimate z_0 = 0 starts
//! the observer at the operating point, x̂_0 = x_op + Qδy_0.
//!
//! At step k the observer is given y_k and u_{k−1} (the input the plant held over the last
//! step): it first advances z_{k−1} → z_k with the stored y_{k−1}, then forms x̂_k. All buffers are
//! allocated at construction; `step` does not allocate.

use lti::MatData;
use lti::kernel::{copy, mul_acc, mul_into};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// The matrices of a sampled observer (what the launcher sends to an observer process).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearObserver {
    /// F, r×r.
    pub f: MatData,
    /// G, r×l.
    pub g: MatData,
    /// K, r×p.
    pub k: MatData,
    /// P, n×r.
    pub p: MatData,
    /// Q, n×p.
    pub q: MatData,
    /// The initial estimate x̂₀ (n values); `None`: z_0 = 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xhat0: Option<Vec<f64>>,
    /// The offsets of a design in deviations from an operating point; `None` at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<Offset>,
}

/// c_z (r values) and c_x (n values) of an observer run at an operating point (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Offset {
    /// c_z = −(G u_op + K y_op).
    pub z: Vec<f64>,
    /// c_x = x_op − Q y_op.
    pub x: Vec<f64>,
}

impl LinearObserver {
    /// From the five matrices.
    pub fn new(
        f: &DMatrix<f64>,
        g: &DMatrix<f64>,
        k: &DMatrix<f64>,
        p: &DMatrix<f64>,
        q: &DMatrix<f64>,
    ) -> Self {
        Self {
            f: f.into(),
            g: g.into(),
            k: k.into(),
            p: p.into(),
            q: q.into(),
            xhat0: None,
            offset: None,
        }
    }

    /// The same observer run on absolute signals at the operating point `op` (its x, u, y):
    /// sets c_z = −(G u_op + K y_op) and c_x = x_op − Q y_op (module docs); none at the origin.
    pub fn at_operating_point(&mut self, op: &lti::OperatingPoint) {
        if op.is_origin() {
            self.offset = None;
            return;
        }
        let (x_op, u_op, y_op) = (&op.x[..], &op.u[..], &op.y[..]);
        let m = |d: &MatData| DMatrix::<f64>::from(d);
        let (u, y) = (
            DMatrix::from_column_slice(u_op.len(), 1, u_op),
            DMatrix::from_column_slice(y_op.len(), 1, y_op),
        );
        let cz = -(m(&self.g) * &u + m(&self.k) * &y);
        let cx = DMatrix::from_column_slice(x_op.len(), 1, x_op) - m(&self.q) * &y;
        self.offset = Some(Offset {
            z: cz.as_slice().to_vec(),
            x: cx.as_slice().to_vec(),
        });
    }

    /// Observer order r (size of z).
    pub fn order(&self) -> usize {
        self.f.rows
    }

    /// Number of estimated states n.
    pub fn states(&self) -> usize {
        self.p.rows
    }

    /// Number of outputs p.
    pub fn outputs(&self) -> usize {
        self.k.cols
    }

    /// Number of known inputs l.
    pub fn inputs(&self) -> usize {
        self.g.cols
    }

    /// Checks that the five matrices conform.
    pub fn check(&self) -> Result<(), String> {
        let r = self.f.rows;
        let ok = self.f.cols == r
            && self.g.rows == r
            && self.k.rows == r
            && self.p.cols == r
            && self.q.rows == self.p.rows
            && self.q.cols == self.k.cols
            && [&self.f, &self.g, &self.k, &self.p, &self.q]
                .iter()
                .all(|m| m.data.len() == m.rows * m.cols)
            && self
                .xhat0
                .as_ref()
                .is_none_or(|x| x.len() == self.p.rows && x.iter().all(|v| v.is_finite()))
            && self.offset.as_ref().is_none_or(|o| {
                o.z.len() == r
                    && o.x.len() == self.p.rows
                    && o.z.iter().chain(&o.x).all(|v| v.is_finite())
            });
        if ok {
            Ok(())
        } else {
            Err("observer matrices do not conform".into())
        }
    }

    /// A runnable instance with zero initial state.
    pub fn instantiate(&self) -> ObserverState {
        let r = self.order();
        let p: DMatrix<f64> = (&self.p).into();
        let zero = |m: &MatData| m.data.iter().all(|&x| x == 0.0);
        let g_zero = zero(&self.g);
        let l = if g_zero { 0 } else { self.inputs() };
        // [F G K] (or [F K] when G = 0), acting on the stacked [z; u; y].
        let mut fgk = DMatrix::zeros(r, r + l + self.outputs());
        fgk.columns_mut(0, r).copy_from(&DMatrix::from(&self.f));
        if !g_zero {
            fgk.columns_mut(r, l).copy_from(&DMatrix::from(&self.g));
        }
        fgk.columns_mut(r + l, self.outputs())
            .copy_from(&DMatrix::from(&self.k));
        ObserverState {
            p_identity: p.is_square() && p == DMatrix::identity(p.nrows(), p.ncols()),
            q_zero: zero(&self.q),
            stacked: vec![0.0; fgk.ncols()],
            fgk,
            l,
            p: (&self.p).into(),
            q: (&self.q).into(),
            z_next: vec![0.0; r],
            xhat: vec![0.0; self.states()],
            started: false,
            start: self
                .xhat0
                .as_ref()
                .map(|x0| (x0.clone(), lti::pinv::pinv(&p))),
            offset: self.offset.clone(),
        }
    }
}

/// A running observer: matrices and preallocated state.
#[derive(Debug, Clone)]
pub struct ObserverState {
    /// [F G K], or [F K] when G = 0: z⁺ = F z + G u + K y is one pass over each row, summed
    /// in the same order as the three products one after another (the same bits).
    fgk: DMatrix<f64>,
    /// The columns of G in `fgk`: l, or 0 when G = 0.
    l: usize,
    p: DMatrix<f64>,
    q: DMatrix<f64>,
    /// [z_k; u_{k−1}; y_k] (u's part empty when G = 0): z_k, then what the next update reads.
    stacked: Vec<f64>,
    z_next: Vec<f64>,
    xhat: Vec<f64>,
    started: bool,
    /// (x̂₀, P⁺) when the scenario gives an initial estimate.
    start: Option<(Vec<f64>, DMatrix<f64>)>,
    /// P = I (full-order observers): x̂ = z + Qy needs no product with P.
    p_identity: bool,
    /// Q = 0 (predictor-form Luenberger): skip Q y.
    q_zero: bool,
    /// (c_z, c_x) at an operating point.
    offset: Option<Offset>,
}

impl ObserverState {
    /// One step: takes y_k and u_{k−1}, returns x̂_k.
    pub fn step(&mut self, y: &[f64], u_prev: &[f64]) -> &[f64] {
        let r = self.z_next.len();
        if self.started {
            // z_k = F z_{k−1} + G u_{k−1} + K y_{k−1}: `stacked` holds z_{k−1} and y_{k−1}.
            if self.l > 0 {
                copy(&mut self.stacked[r..r + self.l], u_prev);
            }
            mul_into(&mut self.z_next, &self.fgk, &self.stacked);
            if let Some(o) = &self.offset {
                for (z, c) in self.z_next.iter_mut().zip(&o.z) {
                    *z += c;
                }
            }
            copy(&mut self.stacked[..r], &self.z_next);
        } else if let Some((x0, p_pinv)) = &self.start {
            // z_0 = P⁺(x̂₀ − Q y_0 − c_x), with x̂ as the scratch vector.
            mul_into(&mut self.xhat, &self.q, y);
            for (v, x) in self.xhat.iter_mut().zip(x0) {
                *v = x - *v;
            }
            if let Some(o) = &self.offset {
                for (v, c) in self.xhat.iter_mut().zip(&o.x) {
                    *v -= c;
                }
            }
            mul_into(&mut self.stacked[..r], p_pinv, &self.xhat);
        }
        self.started = true;
        let (z, rest) = self.stacked.split_at_mut(r);
        copy(&mut rest[self.l..], y);
        // Exact identities and zeros are skipped: for finite values the result differs from the
        // full product only in the sign of a zero, and both run modes execute this same code.
        if self.p_identity {
            copy(&mut self.xhat, z);
        } else {
            mul_into(&mut self.xhat, &self.p, z);
        }
        if !self.q_zero {
            mul_acc(&mut self.xhat, &self.q, y);
        }
        if let Some(o) = &self.offset {
            for (v, c) in self.xhat.iter_mut().zip(&o.x) {
                *v += c;
            }
        }
        &self.xhat
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_step_uses_zero_state_then_advances() {
        // z⁺ = 0.5 z + u + y, x̂ = z + 2y.
        let one = |v: f64| DMatrix::from_element(1, 1, v);
        let obs = LinearObserver::new(&one(0.5), &one(1.0), &one(1.0), &one(1.0), &one(2.0));
        let mut s = obs.instantiate();
        assert_eq!(s.step(&[3.0], &[0.0]), &[6.0]); // z0 = 0
        assert_eq!(s.step(&[1.0], &[10.0]), &[15.0]); // z1 = 0 + 10 + 3 = 13, x̂ = 13 + 2
    }

    #[test]
    fn initial_estimate_sets_the_first_sample() {
        // Full order: x̂_0 = x̂₀ whatever y_0. Reduced (P = [1; 1], Q = [0; 1]): the projection.
        let one = |v: f64| DMatrix::from_element(1, 1, v);
        let mut obs = LinearObserver::new(&one(0.5), &one(1.0), &one(1.0), &one(1.0), &one(2.0));
        obs.xhat0 = Some(vec![7.0]);
        let mut s = obs.instantiate();
        assert_eq!(s.step(&[3.0], &[0.0]), &[7.0]); // z0 = 7 − 6 = 1
        assert_eq!(s.step(&[1.0], &[10.0]), &[15.5]); // z1 = 0.5 + 10 + 3, x̂ = 13.5 + 2
        let col = |a: f64, b: f64| DMatrix::from_column_slice(2, 1, &[a, b]);
        let mut obs = LinearObserver::new(
            &one(0.5),
            &one(0.0),
            &one(1.0),
            &col(1.0, 1.0),
            &col(0.0, 1.0),
        );
        obs.xhat0 = Some(vec![4.0, 2.0]);
        let mut s = obs.instantiate();
        // z0 = P⁺([4, 2] − [0, 1]) = (4 + 1)/2 = 2.5: x̂_0 = [2.5, 3.5].
        assert_eq!(s.step(&[1.0], &[0.0]), &[2.5, 3.5]);
    }
}
