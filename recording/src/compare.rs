//! `uio-launcher compare`: two recordings, signal by signal and step by step, within
//! max(abs_tol, rel_tol·|a|) — the rule of Simulink's Data Inspector — or, with no tolerance
//! given, bit for bit. Latency series are timing, not signals, and are left out.

use crate::read::Recording;

/// The first disagreement found.
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    /// The signal (entity path).
    pub signal: String,
    /// The step, if the disagreement is in a value.
    pub step: Option<i64>,
    /// What differs.
    pub what: String,
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.step {
            Some(k) => write!(f, "{} at step {k}: {}", self.signal, self.what),
            None => write!(f, "{}: {}", self.signal, self.what),
        }
    }
}

/// Compares `a` with `b`; `None` tolerances mean bit equality.
pub fn compare(
    a: &Recording,
    b: &Recording,
    abs_tol: Option<f64>,
    rel_tol: Option<f64>,
) -> Result<usize, Difference> {
    let signals = |r: &Recording| {
        r.series
            .keys()
            .filter(|k| !k.starts_with("/latency"))
            .cloned()
            .collect::<Vec<_>>()
    };
    let (sa, sb) = (signals(a), signals(b));
    for s in &sa {
        if !sb.contains(s) {
            return Err(Difference {
                signal: s.clone(),
                step: None,
                what: "only in the first recording".into(),
            });
        }
    }
    for s in &sb {
        if !sa.contains(s) {
            return Err(Difference {
                signal: s.clone(),
                step: None,
                what: "only in the second recording".into(),
            });
        }
    }
    let exact = abs_tol.is_none() && rel_tol.is_none();
    let (abs_tol, rel_tol) = (abs_tol.unwrap_or(0.0), rel_tol.unwrap_or(0.0));
    let mut compared = 0;
    for s in &sa {
        let (x, y) = (&a.series[s], &b.series[s]);
        for i in 0..x.values.len().max(y.values.len()) {
            let (Some(&kx), Some(&ky)) = (x.steps.get(i), y.steps.get(i)) else {
                let k = x.steps.get(i).or(y.steps.get(i)).copied();
                return Err(Difference {
                    signal: s.clone(),
                    step: k,
                    what: format!("{} values against {}", x.values.len(), y.values.len()),
                });
            };
            if kx != ky {
                return Err(Difference {
                    signal: s.clone(),
                    step: Some(kx.min(ky)),
                    what: format!("steps differ ({kx} against {ky})"),
                });
            }
            let (va, vb) = (x.values[i], y.values[i]);
            let same = if exact {
                va.to_bits() == vb.to_bits()
            } else {
                (va - vb).abs() <= abs_tol.max(rel_tol * va.abs()) || (va.is_nan() && vb.is_nan())
            };
            if !same {
                return Err(Difference {
                    signal: s.clone(),
                    step: Some(kx),
                    what: format!("{va:e} against {vb:e} (difference {:e})", va - vb),
                });
            }
            compared += 1;
        }
    }
    Ok(compared)
}
