//! What a sweep keeps of a realisation: the figures its statistics and its choice of the worst
//! realisations are made of, and nothing else. A shard writes these rows to its file and
//! `uio-launcher sweep merge` reads them back (JSON numbers read back to the same bits: serde_json's
//! `float_roundtrip`), so the merged statistics are computed from the same values, in the same
//! order, as the unsharded sweep's.

use serde::{Deserialize, Serialize};

use crate::summary::Summary;

/// One completed realisation.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Row {
    /// Its seed.
    pub seed: u64,
    /// Its fault-diagnosis figures (summary.json's `diagnosis`), if the scenario has faults or
    /// diagnosers.
    pub diagnosis: Option<diagnosis::Diagnosis>,
    /// Per observer: its name and tail max |x − x̂|.
    pub observers: Vec<(String, Option<f64>)>,
}

impl Row {
    /// The row of realisation `seed` from its summary.
    pub fn of(seed: u64, s: &Summary) -> Row {
        Row {
            seed,
            diagnosis: s.diagnosis.clone(),
            observers: s
                .observers
                .iter()
                .map(|o| (o.name.clone(), o.tail_max_abs_error))
                .collect(),
        }
    }

    /// How bad the realisation went: wrong isolations, then false alarms, then the longest
    /// delay (a fault never detected counts as the longest).
    pub fn badness(&self) -> (usize, u64, u64) {
        let Some(d) = &self.diagnosis else {
            return (0, 0, 0);
        };
        let wrong = d.faults.iter().filter(|f| !f.correct).count();
        let delay = d
            .faults
            .iter()
            .map(|f| f.delay.map_or(u64::MAX, |x| (x * 1e9) as u64))
            .max()
            .unwrap_or(0);
        (wrong, d.false_alarms, delay)
    }
}

/// The seeds of the `k` worst rows, worst first; among equally bad ones the earlier seed
/// first (a stable sort of the rows in seed order), so that the worst of a set of shards are
/// the worst of the whole sweep, and among each shard's own `k` worst.
pub fn worst(rows: &[Row], k: usize) -> Vec<u64> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(rows[i].badness()));
    order.iter().take(k).map(|&i| rows[i].seed).collect()
}
