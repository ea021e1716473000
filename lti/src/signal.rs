//! Scalar signals of time for known inputs and disturbances.
//!
//! Every signal is split as s(t) = a·sin(ωt + φ) + c(t), with c piecewise constant and
//! right-continuous (a value holds from its time on). The plant integrates the sine part exactly
//! through its generator and splits each step at the breakpoints of c, so no signal is
//! approximated inside a step.

use serde::{Deserialize, Serialize};

/// Relative tolerance (in steps) within which a switching time counts as falling on a sample.
pub const SAMPLE_NUDGE: f64 = 1e-9;

/// A scalar signal as a scenario describes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Signal {
    /// s(t) = value.
    Constant {
        /// The constant value.
        value: f64,
    },
    /// s(t) = before for t < time, after from `time` on.
    Step {
        /// Switching time, s.
        time: f64,
        /// Value before the step.
        #[serde(default)]
        before: f64,
        /// Value from the step on.
        after: f64,
    },
    /// s(t) = amplitude·sin(2π·frequency_hz·t + phase) + offset.
    Sine {
        /// Amplitude.
        amplitude: f64,
        /// Frequency, Hz.
        frequency_hz: f64,
        /// Phase at t = 0, rad.
        #[serde(default)]
        phase: f64,
        /// Constant offset.
        #[serde(default)]
        offset: f64,
    },
    /// s(t) = values[i] for times[i] ≤ t < times[i+1]; 0 before times[0].
    Piecewise {
        /// Strictly increasing switching times, s.
        times: Vec<f64>,
        /// The value that holds from each time on.
        values: Vec<f64>,
    },
}

impl Signal {
    /// Checks the parameters; returns the name of the offending field and the reason.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let finite = |name: &'static str, v: f64| {
            if v.is_finite() { Ok(()) } else { Err((name, format!("{v} is not finite"))) }
        };
        match self {
            Signal::Constant { value } => finite("value", *value),
            Signal::Step { time, before, after } => {
                finite("time", *time)?;
                finite("before", *before)?;
                finite("after", *after)
            }
            Signal::Sine { amplitude, frequency_hz, phase, offset } => {
                finite("amplitude", *amplitude)?;
                finite("frequency_hz", *frequency_hz)?;
                finite("phase", *phase)?;
                finite("offset", *offset)?;
                if *frequency_hz < 0.0 {
                    return Err(("frequency_hz", "must be ≥ 0".into()));
                }
                Ok(())
            }
            Signal::Piecewise { times, values } => {
                if times.is_empty() {
                    return Err(("times", "must not be empty".into()));
                }
                if times.len() != values.len() {
                    return Err(("values", format!("has {} entries, times has {}", values.len(), times.len())));
                }
                for t in times {
                    finite("times", *t)?;
                }
                for v in values {
                    finite("values", *v)?;
                }
                if times.windows(2).any(|w| w[1] <= w[0]) {
                    return Err(("times", "must be strictly increasing".into()));
                }
                Ok(())
            }
        }
    }

    /// s(t).
    pub fn value(&self, t: f64) -> f64 {
        self.sine_at(t) + self.held(t)
    }

    /// The value a sampler sees at t_k = k·dt: the sine at t_k and the held part just after
    /// t_k, so that a switch scheduled at t_k (but computed a rounding error later) counts as
    /// already made — the same convention the plant's step splitting uses.
    pub fn sample(&self, t: f64, dt: f64) -> f64 {
        self.sine_at(t) + self.held(t + SAMPLE_NUDGE * dt)
    }

    /// The sinusoidal part: (amplitude, ω in rad/s, phase), if any.
    pub fn sine(&self) -> Option<(f64, f64, f64)> {
        match self {
            Signal::Sine { amplitude, frequency_hz, phase, .. } if *amplitude != 0.0 => {
                Some((*amplitude, 2.0 * std::f64::consts::PI * frequency_hz, *phase))
            }
            _ => None,
        }
    }

    fn sine_at(&self, t: f64) -> f64 {
        self.sine().map_or(0.0, |(a, w, p)| a * (w * t + p).sin())
    }

    /// The piecewise-constant part c(t), right-continuous.
    pub fn held(&self, t: f64) -> f64 {
        match self {
            Signal::Constant { value } => *value,
            Signal::Step { time, before, after } => {
                if t < *time {
                    *before
                } else {
                    *after
                }
            }
            Signal::Sine { offset, .. } => *offset,
            Signal::Piecewise { times, values } => match times.iter().rposition(|&ti| ti <= t) {
                Some(i) => values[i],
                None => 0.0,
            },
        }
    }

    /// The times at which c(t) may jump.
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            Signal::Step { time, .. } => vec![*time],
            Signal::Piecewise { times, .. } => times.clone(),
            _ => Vec::new(),
        }
    }

    /// Largest |s(t)| over all t (for bounds and plot ranges).
    pub fn peak(&self) -> f64 {
        match self {
            Signal::Constant { value } => value.abs(),
            Signal::Step { before, after, .. } => before.abs().max(after.abs()),
            Signal::Sine { amplitude, offset, .. } => amplitude.abs() + offset.abs(),
            Signal::Piecewise { values, .. } => values.iter().fold(0.0, |m, v| m.max(v.abs())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_holds_from_its_time_on() {
        let s = Signal::Piecewise { times: vec![0.0, 5.0, 10.0], values: vec![0.0, 1.0, -0.5] };
        assert_eq!(s.value(4.999), 0.0);
        assert_eq!(s.value(5.0), 1.0);
        assert_eq!(s.value(12.0), -0.5);
        assert_eq!(s.value(-1.0), 0.0);
    }

    #[test]
    fn sine_with_offset() {
        let s = Signal::Sine { amplitude: 2.0, frequency_hz: 0.25, phase: 0.0, offset: 1.0 };
        assert!((s.value(1.0) - 3.0).abs() < 1e-15);
        assert_eq!(s.held(1.0), 1.0);
    }
}
