//! What `uio-launcher plot` draws: entities chosen by glob (`--signals '/observer/uio/**'`) and a
//! time window (`--from`, `--to`).

use crate::globs::Globs;

/// What `uio-launcher plot` draws: the choice of signals and time.
#[derive(Debug, Clone, Default)]
pub struct PlotSelection {
    /// Entity globs; empty means every entity. `*` matches within one path segment, `**` any
    /// number of segments (as `uio-launcher run --record`).
    pub signals: Vec<String>,
    /// First time drawn, s (steps for a recording without its scenario).
    pub from: Option<f64>,
    /// Last time drawn.
    pub to: Option<f64>,
}

impl PlotSelection {
    /// Checks the window (finite bounds, `from` before `to`) and the globs; the message names
    /// the option.
    pub fn validate(&self) -> Result<(), String> {
        self.matcher().map(|_| ())
    }

    /// The compiled selection.
    pub fn matcher(&self) -> Result<Matcher, String> {
        for (name, v) in [("--from", self.from), ("--to", self.to)] {
            if let Some(v) = v
                && !v.is_finite()
            {
                return Err(format!("{name}: {v} is not a finite time"));
            }
        }
        if let (Some(a), Some(b)) = (self.from, self.to)
            && a >= b
        {
            return Err(format!("--from {a} must be before --to {b}"));
        }
        // The rules of `uio-launcher run --record`: `*` stops at '/', a leading '/' is implied.
        let globs = if self.signals.is_empty() {
            None
        } else {
            Some(Globs::new(&self.signals).map_err(|e| format!("--signals {e}"))?)
        };
        Ok(Matcher {
            globs,
            from: self.from,
            to: self.to,
        })
    }
}

/// A checked [`PlotSelection`].
pub struct Matcher {
    globs: Option<Globs>,
    from: Option<f64>,
    to: Option<f64>,
}

impl Matcher {
    /// Whether the entity at `path` is selected.
    pub fn entity(&self, path: &str) -> bool {
        self.globs.as_ref().is_none_or(|g| g.matches(path))
    }

    /// Whether time `x` is in the window.
    pub fn time(&self, x: f64) -> bool {
        self.from.is_none_or(|a| x >= a) && self.to.is_none_or(|b| x <= b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_by_segment() {
        let m = |g: &str| {
            PlotSelection {
                signals: vec![g.to_string()],
                from: None,
                to: None,
            }
            .matcher()
            .unwrap()
        };
        assert!(m("/observer/uio/**").entity("/observer/uio/xhat/1"));
        assert!(m("/observer/uio/**").entity("/observer/uio/log10_max_abs_error"));
        assert!(!m("/observer/uio/**").entity("/observer/luenberger/xhat/1"));
        assert!(m("/observer/*/error/*").entity("/observer/luenberger/error/3"));
        assert!(!m("/observer/*/error/*").entity("/observer/luenberger/xhat/3"));
        assert!(!m("/plant/*").entity("/plant/x/1"));
        assert!(m("plant/x/?").entity("/plant/x/1"));
        assert!(m("/plant/x/1").entity("/plant/x/1") && !m("/plant/x/1").entity("/plant/x/10"));
        assert!(
            PlotSelection {
                signals: vec!["/plant/[x".into()],
                from: None,
                to: None
            }
            .validate()
            .unwrap_err()
            .starts_with("--signals '/plant/[x': ")
        );
    }

    #[test]
    fn a_window_must_be_finite_and_ordered() {
        let w = |from, to| {
            PlotSelection {
                signals: vec![],
                from,
                to,
            }
            .validate()
        };
        assert!(w(Some(1.0), Some(2.0)).is_ok());
        assert!(w(Some(2.0), Some(1.0)).unwrap_err().contains("--from 2"));
        assert!(w(Some(1.0), Some(1.0)).is_err());
        assert!(w(Some(f64::NAN), None).unwrap_err().contains("--from"));
        assert!(w(None, Some(f64::INFINITY)).unwrap_err().contains("--to"));
    }
}
