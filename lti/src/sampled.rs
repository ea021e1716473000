//! A [`Signal`] on one sample grid t_k = k·dt, for the step functions.
//!
//! [`Signal::held_at_step`] decides at every call whether each switch is in effect at sample k
//! (a division, and near the switch an exact comparison of decimals). On a fixed grid that
//! answer is a first sample k_T per switching time T, found once here with the same decision
//! ([`in_effect`]), so that a sample costs integer comparisons:
//!
//! ```text
//! c_k = values[i]  for the last switch i with k_T(i) ≤ k,  else c before the first switch
//! s_k = a·sin(ω·k·dt + φ) + c_k
//! ```
//!
//! The values are the signal's own, in the same expressions: the same bits as
//! [`Signal::sample_step`] and [`Signal::held_at_step`].

use crate::signal::{Signal, in_effect};

/// A signal sampled at t_k = k·dt.
#[derive(Debug, Clone)]
pub struct SampledSignal {
    dt: f64,
    /// (a, ω, φ) of the sine part, when it has one.
    sine: Option<(f64, f64, f64)>,
    /// c before any switch.
    before: f64,
    /// (k_T, value from k_T on) for each switch, in the signal's order.
    switches: Vec<(u64, f64)>,
}

impl SampledSignal {
    /// `signal` on the grid of period `dt`.
    pub fn new(signal: &Signal, dt: f64) -> Self {
        let (before, switches) = match signal {
            Signal::Step {
                time,
                before,
                after,
            } => (*before, vec![(first_in_effect(*time, dt), *after)]),
            Signal::Piecewise { times, values } => (
                0.0,
                times
                    .iter()
                    .zip(values)
                    .map(|(&t, &v)| (first_in_effect(t, dt), v))
                    .collect(),
            ),
            _ => (signal.held(0.0), Vec::new()),
        };
        SampledSignal {
            dt,
            sine: signal.sine(),
            before,
            switches,
        }
    }

    /// Each of `signals` on the grid of period `dt`.
    pub fn all(signals: &[Signal], dt: f64) -> Vec<Self> {
        signals.iter().map(|s| Self::new(s, dt)).collect()
    }

    /// (amplitude, ω in rad/s, phase) of the sine part, as [`Signal::sine`].
    pub fn sine(&self) -> Option<(f64, f64, f64)> {
        self.sine
    }

    /// c_k, as [`Signal::held_at_step`].
    #[inline]
    pub fn held_at_step(&self, k: u64) -> f64 {
        match self.switches.iter().rposition(|&(from, _)| from <= k) {
            Some(i) => self.switches[i].1,
            None => self.before,
        }
    }

    /// s_k, as [`Signal::sample_step`].
    #[inline]
    pub fn sample_step(&self, k: u64) -> f64 {
        let t = k as f64 * self.dt;
        self.sine.map_or(0.0, |(a, w, p)| a * (w * t + p).sin()) + self.held_at_step(k)
    }
}

/// The first sample k at which a switch at `time` is in effect ([`in_effect`] is monotone in
/// k): a bisection of [0, u64::MAX], `u64::MAX` for a switch never in effect (T = ∞).
fn first_in_effect(time: f64, dt: f64) -> u64 {
    if in_effect(time, 0, dt) {
        return 0;
    }
    // Invariant: not in effect at lo; in effect at hi, or hi = u64::MAX.
    let (mut lo, mut hi) = (0u64, u64::MAX);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if in_effect(time, mid, dt) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Around every switch the sampled signal gives the bits of the signal's own per-sample
    /// decision: times on the grid, just off it, beyond any run, and at or before 0.
    #[test]
    fn it_gives_the_signals_own_samples() {
        let times = [
            5.0,
            5.0000000000001,
            4.9999999999999,
            0.3,
            0.30000000000000004,
            1e-9,
            0.0,
            -1.0,
            1e300,
            f64::INFINITY,
            f64::NAN,
            123.456789,
        ];
        for dt in [0.001, 0.1, 0.01, 1.0 / 3.0, 0.0025] {
            for &t in &times {
                let step = Signal::Step {
                    time: t,
                    before: -1.5,
                    after: 2.5,
                };
                let sine = Signal::Sine {
                    amplitude: 0.7,
                    frequency_hz: 0.5,
                    phase: 0.2,
                    offset: 0.1,
                };
                let pw = Signal::Piecewise {
                    times: vec![t.min(1.0), t, t + 0.5],
                    values: vec![1.0, -2.0, 3.0],
                };
                for s in [step, sine, pw, Signal::Constant { value: 4.0 }] {
                    let sampled = SampledSignal::new(&s, dt);
                    let at = if t.is_finite() && t > 0.0 && t / dt < 1e15 {
                        (t / dt) as u64
                    } else {
                        0
                    };
                    for k in (at.saturating_sub(3)..at + 4).chain([0, 1, 2, 1 << 40]) {
                        assert_eq!(
                            sampled.sample_step(k).to_bits(),
                            s.sample_step(k, dt).to_bits(),
                            "{s:?} dt {dt} k {k}"
                        );
                        assert_eq!(
                            sampled.held_at_step(k).to_bits(),
                            s.held_at_step(k, dt).to_bits(),
                            "{s:?} dt {dt} k {k}"
                        );
                    }
                }
            }
        }
    }
}
