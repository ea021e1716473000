//! What `launcher plot` draws: entities chosen by glob (`--signals '/observer/uio/**'`) and a
//! time window (`--from`, `--to`).

/// The choice of signals and time.
#[derive(Debug, Clone, Default)]
pub struct Selection {
    /// Entity globs; empty means every entity. `*` matches within one path segment, `**` any
    /// number of segments, `?` one character.
    pub signals: Vec<String>,
    /// First time drawn, s (steps for a recording without its scenario).
    pub from: Option<f64>,
    /// Last time drawn.
    pub to: Option<f64>,
}

impl Selection {
    /// Checks the window: finite bounds, `from` before `to`. The message names the option.
    pub fn validate(&self) -> Result<(), String> {
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
        for g in &self.signals {
            if !g.starts_with('/') {
                return Err(format!("--signals: '{g}' must be an entity path glob starting with '/', e.g. '/observer/uio/**'"));
            }
        }
        Ok(())
    }

    /// Whether the entity at `path` is selected.
    pub fn entity(&self, path: &str) -> bool {
        self.signals.is_empty() || self.signals.iter().any(|g| glob(g, path))
    }

    /// Whether time `x` is in the window.
    pub fn time(&self, x: f64) -> bool {
        self.from.is_none_or(|a| x >= a) && self.to.is_none_or(|b| x <= b)
    }
}

/// Matches an entity path against a glob of path segments.
pub fn glob(pattern: &str, path: &str) -> bool {
    let p: Vec<&str> = pattern.trim_matches('/').split('/').filter(|s| !s.is_empty()).collect();
    let s: Vec<&str> = path.trim_matches('/').split('/').filter(|s| !s.is_empty()).collect();
    segments(&p, &s)
}

fn segments(p: &[&str], s: &[&str]) -> bool {
    match p.split_first() {
        None => s.is_empty(),
        Some((&"**", rest)) => (0..=s.len()).any(|k| segments(rest, &s[k..])),
        Some((first, rest)) => !s.is_empty() && segment(first.as_bytes(), s[0].as_bytes()) && segments(rest, &s[1..]),
    }
}

fn segment(p: &[u8], s: &[u8]) -> bool {
    match p.split_first() {
        None => s.is_empty(),
        Some((b'*', rest)) => (0..=s.len()).any(|k| segment(rest, &s[k..])),
        Some((b'?', rest)) => !s.is_empty() && segment(rest, &s[1..]),
        Some((c, rest)) => s.first() == Some(c) && segment(rest, &s[1..]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_by_segment() {
        assert!(glob("/observer/uio/**", "/observer/uio/xhat/1"));
        assert!(glob("/observer/uio/**", "/observer/uio/log10_max_abs_error"));
        assert!(!glob("/observer/uio/**", "/observer/luenberger/xhat/1"));
        assert!(glob("/observer/*/error/*", "/observer/luenberger/error/3"));
        assert!(!glob("/observer/*/error/*", "/observer/luenberger/xhat/3"));
        assert!(!glob("/plant/*", "/plant/x/1"));
        assert!(glob("/plant/x/?", "/plant/x/1"));
        assert!(glob("/**/residual/*", "/observer/uio/residual/2"));
        assert!(glob("/plant/x/1", "/plant/x/1") && !glob("/plant/x/1", "/plant/x/10"));
    }

    #[test]
    fn a_window_must_be_finite_and_ordered() {
        let w = |from, to| Selection { signals: vec![], from, to }.validate();
        assert!(w(Some(1.0), Some(2.0)).is_ok());
        assert!(w(Some(2.0), Some(1.0)).unwrap_err().contains("--from 2"));
        assert!(w(Some(1.0), Some(1.0)).is_err());
        assert!(w(Some(f64::NAN), None).unwrap_err().contains("--from"));
        assert!(w(None, Some(f64::INFINITY)).unwrap_err().contains("--to"));
    }
}
