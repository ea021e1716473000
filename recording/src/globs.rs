//! Entity globs, with the one rule shared by `uio-launcher run --record` and `uio-launcher plot
//! --signals`: `*` matches within one path segment, `**` across segments, and a pattern
//! without a leading `/` gets one (entity paths are rooted).

use globset::{GlobBuilder, GlobSet, GlobSetBuilder};
use scenario::quoted;

/// A compiled set of entity globs; an entity matches when any pattern matches it.
#[derive(Debug, Clone)]
pub struct Globs(GlobSet, Vec<String>);

impl Globs {
    /// Compiles `patterns`; an error quotes the pattern that is not a glob and says why.
    pub fn new(patterns: &[String]) -> Result<Self, String> {
        let mut set = GlobSetBuilder::new();
        for p in patterns {
            let rooted = if p.starts_with('/') {
                p.clone()
            } else {
                format!("/{p}")
            };
            set.add(
                GlobBuilder::new(&rooted)
                    .literal_separator(true)
                    .build()
                    .map_err(|e| format!("{}: {}", quoted(p), e.kind()))?,
            );
        }
        set.build()
            .map(|g| Globs(g, patterns.to_vec()))
            .map_err(|e| e.to_string())
    }

    /// The patterns that match none of `paths` (a typo, most likely: worth a warning).
    pub fn unmatched<'a>(&self, paths: impl IntoIterator<Item = &'a str>) -> Vec<String> {
        let mut hit = vec![false; self.1.len()];
        for p in paths {
            for i in self.0.matches(p) {
                hit[i] = true;
            }
        }
        self.1
            .iter()
            .zip(hit)
            .filter(|(_, h)| !h)
            .map(|(p, _)| p.clone())
            .collect()
    }

    /// Whether the entity at `path` matches any pattern.
    pub fn matches(&self, path: &str) -> bool {
        self.0.is_match(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn star_stays_in_its_segment_and_a_root_is_implied() {
        let g = |p: &str| Globs::new(&[p.to_string()]).unwrap();
        assert!(g("/plant/x/*").matches("/plant/x/1") && !g("/plant/*").matches("/plant/x/1"));
        assert!(
            g("/observer/uio/**").matches("/observer/uio/xhat/1")
                && !g("/observer/uio/**").matches("/observer/luenberger/xhat/1")
        );
        assert!(g("plant/x/?").matches("/plant/x/1"));
        assert!(g("/plant/x/1").matches("/plant/x/1") && !g("/plant/x/1").matches("/plant/x/10"));
        let two = Globs::new(&["/plant/x/*".into(), "/plant/y/*".into()]).unwrap();
        assert!(two.matches("/plant/x/2") && two.matches("/plant/y/1") && !two.matches("/input/1"));
        assert!(
            Globs::new(&["/plant/[x".into()])
                .unwrap_err()
                .starts_with("'/plant/[x': ")
        );
        assert_eq!(two.unmatched(["/plant/x/1", "/input/1"]), ["/plant/y/*"]);
    }
}
