//! Scalar signals of time for known inputs and disturbances.
//!
//! Every signal is split as s(t) = a·sin(ωt + φ) + c(t), with c piecewise constant and
//! right-continuous (a value holds from its time on). The plant integrates the sine part exactly
//! through its generator and splits each step at the breakpoints of c, so no signal is
//! approximated inside a step.
//!
//! # Where a switching time falls
//!
//! Sample k is at t_k = k·dt. A scenario writes dt and every switching time T as decimals, and
//! they are compared as the decimals written, exactly: T is **on sample k** when T = k·dt in
//! decimal arithmetic (T/dt an integer), and the new value is in effect from that sample on
//! (T = 5.0, dt = 0.001: sample 5000; T = 0.3, dt = 0.1: sample 3, although 3·0.1 ≠ 0.3 in
//! binary floating point). Otherwise T lies strictly inside step k = ⌊T/dt⌋: sample k still sees
//! the old value, and the plant splits the step at T − k·dt (T = 5.0000000000001: the old value
//! at sample 5000, a switch 10⁻¹³ s into the step, the new value at sample 5001). There is no
//! tolerance: the decimal of a double is its shortest round-trip form, which is the decimal
//! written whenever it has at most 15 significant digits (see [`locate`]).

use std::cmp::Ordering;
use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

/// Where a switching time falls on the sample grid t_k = k·dt (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Switch {
    /// On sample k (T = k·dt exactly), or at or before t₀ (k = 0): in effect from sample k on.
    OnSample(u64),
    /// Strictly inside step k, `offset` = T − k·dt seconds after t_k (0 < offset < dt).
    Inside {
        /// The step t_k … t_{k+1} that contains T.
        step: u64,
        /// T − k·dt, exact in decimals, then rounded to the nearest double.
        offset: f64,
    },
    /// Beyond sample 2⁵³: after any run.
    Beyond,
}

/// Locates a switching time T on the sample grid k·dt, comparing the decimals exactly.
pub fn locate(time: f64, dt: f64) -> Switch {
    if time.is_nan() || time <= 0.0 {
        return Switch::OnSample(0);
    }
    let q = time / dt;
    if q.is_nan() || q >= 9.0e15 {
        return Switch::Beyond;
    }
    // q is within a few ulps of the exact ratio, so T lies within half a step of sample k.
    let k = q.round() as u64;
    let inside = |step: u64| match decimal_offset(time, step, dt) {
        Some((_, d, e)) => decimal_to_f64(d, e),
        None => time - step as f64 * dt,
    };
    match decimal_offset(time, k, dt).map(|o| o.0) {
        Some(Ordering::Equal) => Switch::OnSample(k),
        Some(Ordering::Greater) => Switch::Inside {
            step: k,
            offset: inside(k),
        },
        // (k ≥ 1 here: T > 0 = 0·dt.)
        Some(Ordering::Less) => Switch::Inside {
            step: k - 1,
            offset: inside(k - 1),
        },
        // Too many digits for 128-bit integers: fall back to the binary values.
        None if q == q.floor() => Switch::OnSample(q as u64),
        None => Switch::Inside {
            step: q.floor() as u64,
            offset: time - q.floor() * dt,
        },
    }
}

/// The first sample at or after T, the decimals compared exactly as [`locate`] does (0 for
/// T ≤ 0; `u64::MAX` for a T after any run, ∞ included).
pub fn first_sample_from(time: f64, dt: f64) -> u64 {
    match locate(time, dt) {
        Switch::OnSample(k) => k,
        Switch::Inside { step, .. } => step + 1,
        Switch::Beyond => u64::MAX,
    }
}

/// Whether a switch at T is in effect at sample k: T ≤ k·dt, the decimals compared exactly.
/// Allocation-free (the plant and controller call it every step); the exact comparison runs only
/// when T/dt is within 10⁻¹² (relative) of k, where the binary quotient could be on the wrong side.
pub fn in_effect(time: f64, k: u64, dt: f64) -> bool {
    if time.is_nan() || time <= 0.0 {
        return true;
    }
    let q = time / dt;
    let kf = k as f64;
    let tol = 1e-12 * q.max(1.0);
    if q < kf - tol {
        true
    } else if q > kf + tol {
        false
    } else {
        decimal_offset(time, k, dt).map_or(q <= kf, |(o, ..)| o != Ordering::Greater)
    }
}

/// A fixed stack buffer for formatting numbers without allocating.
struct StackText {
    buf: [u8; 64],
    len: usize,
}

impl StackText {
    fn new() -> Self {
        StackText {
            buf: [0; 64],
            len: 0,
        }
    }

    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.buf[..self.len]).unwrap_or("")
    }
}

impl std::fmt::Write for StackText {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len + s.len();
        if end > self.buf.len() {
            return Err(std::fmt::Error);
        }
        self.buf[self.len..end].copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// x = m·10^e with m·10^e the shortest decimal that reads back as x (x finite, > 0).
fn decimal(x: f64) -> (u64, i32) {
    let mut t = StackText::new();
    // `{:e}` prints the shortest round-trip digits: "5.0000000000001e0", "1e-3".
    let _ = write!(t, "{x:e}");
    let (mantissa, exp) = t.as_str().split_once('e').unwrap_or(("0", "0"));
    let mut m = 0u64;
    let mut frac = 0i32;
    let mut point = false;
    for c in mantissa.bytes() {
        match c {
            b'.' => point = true,
            b'0'..=b'9' => {
                m = m * 10 + (c - b'0') as u64;
                frac += point as i32;
            }
            _ => {}
        }
    }
    (m, exp.parse::<i32>().unwrap_or(0) - frac)
}

/// T − k·dt = ±D·10^e exactly, as (sign, D, e), for T, dt > 0 read as their decimals; None if
/// the integers do not fit in 128 bits (not for any T/dt below 2⁵³ with ≤ 17-digit decimals
/// whose exponents differ by less than ~20).
fn decimal_offset(time: f64, k: u64, dt: f64) -> Option<(Ordering, u128, i32)> {
    let (mt, et) = decimal(time);
    let (md, ed) = decimal(dt);
    let e = et.min(ed);
    let pow10 = |p: i32| 10u128.checked_pow(p as u32);
    let lhs = (mt as u128).checked_mul(pow10(et - e)?)?;
    let rhs = (md as u128)
        .checked_mul(k as u128)?
        .checked_mul(pow10(ed - e)?)?;
    Some((lhs.cmp(&rhs), lhs.abs_diff(rhs), e))
}

/// D·10^e correctly rounded (the standard library's parser), without allocating.
fn decimal_to_f64(d: u128, e: i32) -> f64 {
    let mut t = StackText::new();
    let _ = write!(t, "{d}e{e}");
    t.as_str().parse().unwrap_or(f64::NAN)
}

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
        /// Switching time, s (or "12 h", [`crate::units`]).
        #[serde(deserialize_with = "crate::units::de::seconds")]
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
        /// Frequency, Hz (or "1/day", "0.5 Hz").
        #[serde(deserialize_with = "crate::units::de::hertz")]
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
        /// Strictly increasing switching times, s (each may carry a unit).
        #[serde(deserialize_with = "crate::units::de::seconds_vec")]
        times: Vec<f64>,
        /// The value that holds from each time on.
        values: Vec<f64>,
    },
}

impl Signal {
    /// Checks the parameters; returns the name of the offending field and the reason.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let finite = |name: &'static str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err((name, format!("{v} is not finite")))
            }
        };
        match self {
            Signal::Constant { value } => finite("value", *value),
            Signal::Step {
                time,
                before,
                after,
            } => {
                finite("time", *time)?;
                finite("before", *before)?;
                finite("after", *after)
            }
            Signal::Sine {
                amplitude,
                frequency_hz,
                phase,
                offset,
            } => {
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
                    return Err((
                        "values",
                        format!("has {} entries, times has {}", values.len(), times.len()),
                    ));
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

    /// s(t) + d for every t ≥ 0: the same signal about another level (a plant moved to another
    /// operating point). A piecewise signal, 0 before its first time, holds d there from t = 0.
    pub fn shifted(&self, d: f64) -> Signal {
        match self.clone() {
            Signal::Constant { value } => Signal::Constant { value: value + d },
            Signal::Step {
                time,
                before,
                after,
            } => Signal::Step {
                time,
                before: before + d,
                after: after + d,
            },
            Signal::Sine {
                amplitude,
                frequency_hz,
                phase,
                offset,
            } => Signal::Sine {
                amplitude,
                frequency_hz,
                phase,
                offset: offset + d,
            },
            Signal::Piecewise {
                mut times,
                mut values,
            } => {
                values.iter_mut().for_each(|v| *v += d);
                if times[0] > 0.0 && d != 0.0 {
                    times.insert(0, 0.0);
                    values.insert(0, d);
                }
                Signal::Piecewise { times, values }
            }
        }
    }

    /// s(t).
    pub fn value(&self, t: f64) -> f64 {
        self.sine_at(t) + self.held(t)
    }

    /// The value a sampler sees at a sample time t = k·dt: the sine at t and the held part at
    /// sample k ([`Signal::held_at_step`]).
    pub fn sample(&self, t: f64, dt: f64) -> f64 {
        // t = fl(k·dt), so t/dt is within a few ulps of k.
        let k = (t / dt).round().max(0.0) as u64;
        self.sample_step(k, dt)
    }

    /// The value at sample k: the sine at t_k = k·dt and the held part at sample k.
    pub fn sample_step(&self, k: u64, dt: f64) -> f64 {
        self.sine_at(k as f64 * dt) + self.held_at_step(k, dt)
    }

    /// c at sample k: a switch is made at sample k when its time T ≤ k·dt, the decimals compared
    /// exactly (module documentation). A switch strictly inside step k − 1 shows from sample k.
    pub fn held_at_step(&self, k: u64, dt: f64) -> f64 {
        match self {
            Signal::Step {
                time,
                before,
                after,
            } => {
                if in_effect(*time, k, dt) {
                    *after
                } else {
                    *before
                }
            }
            Signal::Piecewise { times, values } => {
                match times.iter().rposition(|&ti| in_effect(ti, k, dt)) {
                    Some(i) => values[i],
                    None => 0.0,
                }
            }
            _ => self.held(0.0),
        }
    }

    /// The held value from breakpoint j (of [`Signal::breakpoints`]) on.
    pub fn held_after(&self, j: usize) -> f64 {
        match self {
            Signal::Step { after, .. } => *after,
            Signal::Piecewise { values, .. } => values[j],
            _ => self.held(0.0),
        }
    }

    /// The sinusoidal part: (amplitude, ω in rad/s, phase), if any.
    pub fn sine(&self) -> Option<(f64, f64, f64)> {
        match self {
            Signal::Sine {
                amplitude,
                frequency_hz,
                phase,
                ..
            } if *amplitude != 0.0 => Some((
                *amplitude,
                2.0 * std::f64::consts::PI * frequency_hz,
                *phase,
            )),
            _ => None,
        }
    }

    fn sine_at(&self, t: f64) -> f64 {
        self.sine().map_or(0.0, |(a, w, p)| a * (w * t + p).sin())
    }

    /// The piecewise-constant part c(t), right-continuous, comparing t with the switching times
    /// as binary numbers: the part of [`Signal::value`], and the constant part of a signal that
    /// does not switch. Sampling and the plant use [`Signal::held_at_step`].
    pub fn held(&self, t: f64) -> f64 {
        match self {
            Signal::Constant { value } => *value,
            Signal::Step {
                time,
                before,
                after,
            } => {
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
            Signal::Sine {
                amplitude, offset, ..
            } => amplitude.abs() + offset.abs(),
            Signal::Piecewise { values, .. } => values.iter().fold(0.0, |m, v| m.max(v.abs())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_holds_from_its_time_on() {
        let s = Signal::Piecewise {
            times: vec![0.0, 5.0, 10.0],
            values: vec![0.0, 1.0, -0.5],
        };
        assert_eq!(s.value(4.999), 0.0);
        assert_eq!(s.value(5.0), 1.0);
        assert_eq!(s.value(12.0), -0.5);
        assert_eq!(s.value(-1.0), 0.0);
    }

    #[test]
    fn switching_times_are_located_as_the_decimals_written() {
        // 5000·0.001 and 3·0.1 are not 5.0 and 0.3 in binary; as decimals they are.
        assert_eq!(locate(5.0, 0.001), Switch::OnSample(5000));
        assert_eq!(locate(0.3, 0.1), Switch::OnSample(3));
        assert_eq!(locate(0.7, 0.1), Switch::OnSample(7));
        assert_eq!(locate(0.0003, 1e-4), Switch::OnSample(3));
        // A time computed as 3·10⁻⁴ in binary is another decimal, 3.0000000000000003e-4.
        assert_eq!(
            locate(1e-4 * 3.0, 1e-4),
            Switch::Inside {
                step: 3,
                offset: 3e-20
            }
        );
        // 10⁻¹³ after sample 5000, and 10⁻¹³ before it: inside the neighbouring steps.
        assert_eq!(
            locate(5.0000000000001, 0.001),
            Switch::Inside {
                step: 5000,
                offset: 1e-13
            }
        );
        assert_eq!(
            locate(4.9999999999999, 0.001),
            Switch::Inside {
                step: 4999,
                offset: 0.0009999999999
            }
        );
        assert_eq!(
            locate(0.00105, 0.001),
            Switch::Inside {
                step: 1,
                offset: 5e-5
            }
        );
        assert_eq!(locate(0.0, 0.001), Switch::OnSample(0));
        assert_eq!(locate(-2.0, 0.001), Switch::OnSample(0));
        assert_eq!(locate(1e300, 0.001), Switch::Beyond);
    }

    #[test]
    fn a_switch_shows_from_its_sample_on_and_no_earlier() {
        let at = |time: f64| Signal::Step {
            time,
            before: 0.0,
            after: 1.0,
        };
        // On sample 5000: made there.
        assert_eq!(at(5.0).sample(5000.0 * 0.001, 0.001), 1.0);
        assert_eq!(at(5.0).sample_step(4999, 0.001), 0.0);
        // 10⁻¹³ later: not yet at sample 5000, made by sample 5001.
        assert_eq!(at(5.0000000000001).sample(5000.0 * 0.001, 0.001), 0.0);
        assert_eq!(at(5.0000000000001).sample_step(5001, 0.001), 1.0);
        // 10⁻¹³ earlier: made by sample 5000.
        assert_eq!(at(4.9999999999999).sample_step(5000, 0.001), 1.0);
        assert_eq!(at(4.9999999999999).sample_step(4999, 0.001), 0.0);
        // 3·0.1 = 0.30000000000000004 > 0.3, 0.3 itself on sample 3 all the same.
        let p = Signal::Piecewise {
            times: vec![0.1, 0.3],
            values: vec![2.0, 3.0],
        };
        assert_eq!(
            [0, 1, 2, 3].map(|k| p.sample_step(k, 0.1)),
            [0.0, 2.0, 2.0, 3.0]
        );
        assert_eq!(p.held_after(1), 3.0);
    }

    #[test]
    fn decimals_are_the_shortest_round_trip_digits() {
        assert_eq!(decimal(5.0000000000001), (50000000000001, -13));
        assert_eq!(decimal(0.001), (1, -3));
        assert_eq!(decimal(1234.5), (12345, -1));
        assert_eq!(decimal(0.30000000000000004), (30000000000000004, -17));
    }

    #[test]
    fn a_shifted_signal_is_the_signal_plus_the_shift_at_every_sample() {
        let dt = 0.1;
        for s in [
            Signal::Constant { value: 2.0 },
            Signal::Step {
                time: 0.35,
                before: 1.0,
                after: -3.0,
            },
            Signal::Sine {
                amplitude: 1.5,
                frequency_hz: 0.7,
                phase: 0.2,
                offset: 0.5,
            },
            Signal::Piecewise {
                times: vec![0.3, 0.8],
                values: vec![4.0, -1.0],
            },
            Signal::Piecewise {
                times: vec![-1.0, 0.5],
                values: vec![4.0, -1.0],
            },
        ] {
            let shifted = s.shifted(0.25);
            assert!(shifted.validate().is_ok());
            for k in 0..20 {
                // The sine's offset is added in another order: equal to an ulp of the sum.
                let (a, b) = (shifted.sample_step(k, dt), s.sample_step(k, dt) + 0.25);
                assert!(
                    (a - b).abs() <= 4.0 * f64::EPSILON * a.abs(),
                    "{s:?} at {k}: {a} {b}"
                );
            }
            assert_eq!(s.shifted(0.0), s);
        }
    }

    #[test]
    fn sine_with_offset() {
        let s = Signal::Sine {
            amplitude: 2.0,
            frequency_hz: 0.25,
            phase: 0.0,
            offset: 1.0,
        };
        assert!((s.value(1.0) - 3.0).abs() < 1e-15);
        assert_eq!(s.held(1.0), 1.0);
    }
}
