//! Distributions over the realisations of a sweep.

use serde::Serialize;

/// min, median, p95, max of a sample (nearest-rank percentiles), and its size.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Spread {
    /// How many values.
    pub count: usize,
    /// Smallest.
    pub min: f64,
    /// Median (the lower middle value for an even count).
    pub median: f64,
    /// 95th percentile, nearest rank.
    pub p95: f64,
    /// Largest.
    pub max: f64,
}

/// The spread of `values` (None for none).
pub fn spread(values: &[f64]) -> Option<Spread> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let rank = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    Some(Spread {
        count: v.len(),
        min: v[0],
        median: rank(0.5),
        p95: rank(0.95),
        max: v[v.len() - 1],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let v: Vec<f64> = (1..=20).map(f64::from).rev().collect();
        let s = spread(&v).unwrap();
        assert_eq!(
            (s.min, s.median, s.p95, s.max, s.count),
            (1.0, 10.0, 19.0, 20.0, 20)
        );
        assert!(spread(&[]).is_none());
    }
}
