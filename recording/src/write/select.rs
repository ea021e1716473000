//! What of a run is written to its recording: every N-th step (`--record-every N`) and the
//! entities matching any of the `--record GLOB` patterns. The run's figures are computed on
//! every step regardless; only the file is thinned, since a long run at a high rate fills
//! disks (a 300 s run at 1 kHz writes about 430 MB in full).

use crate::globs::Globs;

/// The steps and entities to record, and whether the file is compressed.
#[derive(Debug, Clone)]
pub struct Selection {
    every: u64,
    globs: Option<Globs>,
    compress: bool,
}

impl Default for Selection {
    fn default() -> Self {
        Selection {
            every: 1,
            globs: None,
            compress: false,
        }
    }
}

impl Selection {
    /// Steps 0, N, 2N, … of the entities matching any pattern (all entities when there is
    /// none). In a pattern `*` matches within one path segment and `**` across segments, so
    /// `/observer/uio/**` is everything of observer `uio` and `/plant/x/*` every true state;
    /// a pattern without a leading `/` gets one.
    pub fn new(every: u64, patterns: &[String]) -> Result<Self, String> {
        if every == 0 {
            return Err("--record-every must be at least 1".into());
        }
        if patterns.is_empty() {
            return Ok(Selection {
                every,
                globs: None,
                compress: false,
            });
        }
        let globs = Globs::new(patterns).map_err(|e| format!("--record {e}"))?;
        Ok(Selection {
            every,
            globs: Some(globs),
            compress: false,
        })
    }

    /// The same, written with Rerun's LZ4 chunk compression (`--compress`): about 0.64 × the
    /// bytes for seed002, for the encoding thread's time.
    pub fn compressed(self, compress: bool) -> Self {
        Selection { compress, ..self }
    }

    /// Whether the file is LZ4-compressed.
    pub fn compress(&self) -> bool {
        self.compress
    }

    /// N of `--record-every N`: steps 0, N, 2N, … are recorded.
    pub fn every(&self) -> u64 {
        self.every
    }

    /// Whether step `k` is recorded.
    #[inline]
    pub fn step(&self, k: u64) -> bool {
        self.every == 1 || k.is_multiple_of(self.every)
    }

    /// The `--record` patterns that select none of `paths`.
    pub fn unmatched<'a>(&self, paths: impl IntoIterator<Item = &'a str>) -> Vec<String> {
        self.globs
            .as_ref()
            .map_or_else(Vec::new, |g| g.unmatched(paths))
    }

    /// Whether entity `path` is recorded.
    pub fn entity(&self, path: &str) -> bool {
        self.globs.as_ref().is_none_or(|g| g.matches(path))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_by_segment() {
        let s = Selection::new(1, &["/plant/x/*".into(), "observer/uio/**".into()]).unwrap();
        assert!(
            s.entity("/plant/x/1")
                && s.entity("/observer/uio/xhat/2")
                && s.entity("/observer/uio/error/1")
        );
        assert!(
            !s.entity("/plant/y/1")
                && !s.entity("/plant/x")
                && !s.entity("/observer/luenberger/xhat/1")
        );
        assert!(Selection::new(1, &[]).unwrap().entity("/anything"));
        assert!(
            Selection::new(1, &["/plant/[x".into()])
                .unwrap_err()
                .starts_with("--record '/plant/[x': ")
        );
        assert!(Selection::new(0, &[]).is_err());
        let thin = Selection::new(10, &[]).unwrap();
        assert!(thin.step(0) && thin.step(20) && !thin.step(5));
    }
}
