//! Where each signal sits in the plant's sample:
//! `[x (n) | y (p) | w (q) | v (r) | r (l) | u_{k−1} (l) | faults (2f)]`.
//!
//! The plant publishes the true state and the disturbances along with y so the recorder sees
//! them; observers read only y and u_{k−1}.

use std::ops::Range;

use serde::{Deserialize, Serialize};

/// Sizes of the plant's signals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlantLayout {
    /// States.
    pub n: usize,
    /// Outputs.
    pub p: usize,
    /// Unknown inputs (columns of E).
    pub q: usize,
    /// Measurement disturbances (columns of D).
    pub r: usize,
    /// Known inputs (columns of B).
    pub l: usize,
    /// Injected faults, each published as (active, value) (0 without faults: the layout of a
    /// plant that knows none, such as an external one, is unchanged).
    #[serde(default)]
    pub f: usize,
}

impl PlantLayout {
    /// Total number of values.
    pub fn len(&self) -> usize {
        self.n + self.p + self.q + self.r + 2 * self.l + 2 * self.f
    }

    /// Never empty: a plant has at least one state.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True state x_k.
    pub fn x(&self) -> Range<usize> {
        0..self.n
    }

    /// Measurement y_k.
    pub fn y(&self) -> Range<usize> {
        let s = self.n;
        s..s + self.p
    }

    /// Unknown inputs w(t_k).
    pub fn w(&self) -> Range<usize> {
        let s = self.n + self.p;
        s..s + self.q
    }

    /// Measurement disturbances v(t_k).
    pub fn v(&self) -> Range<usize> {
        let s = self.n + self.p + self.q;
        s..s + self.r
    }

    /// Known input / reference signals r(t_k).
    pub fn r(&self) -> Range<usize> {
        let s = self.n + self.p + self.q + self.r;
        s..s + self.l
    }

    /// The input the plant held over the previous step, u_{k−1} (zero at k = 0).
    pub fn u_prev(&self) -> Range<usize> {
        let s = self.n + self.p + self.q + self.r + self.l;
        s..s + self.l
    }

    /// Fault i's (active, value) at t_k: 1 while it acts, and its magnitude then (0 otherwise).
    pub fn fault(&self, i: usize) -> Range<usize> {
        let s = self.n + self.p + self.q + self.r + 2 * self.l + 2 * i;
        s..s + 2
    }

    /// Every fault's pair.
    pub fn faults(&self) -> Range<usize> {
        let s = self.n + self.p + self.q + self.r + 2 * self.l;
        s..s + 2 * self.f
    }
}
