//! Latency of the lockstep, per hop and per step, in HDR histograms (nanoseconds).
//!
//! Every sample carries the time its publisher sent it and the time the publisher took the input
//! that completed its step, so from the recorded samples alone:
//!
//! * plant → observer i:     observer_i(k).taken − plant(k).sent
//! * observer c → controller: controller(k).taken − observer_c(k).sent
//! * controller → plant:      plant(k+1).taken − controller(k).sent
//! * step:                    plant(k+1).taken − plant(k).sent (y_k out → u_k in)

use hdrhistogram::Histogram;
use serde::{Deserialize, Serialize};

/// Percentiles of one histogram, ns.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Percentiles {
    /// Median.
    pub p50: u64,
    /// 90th percentile.
    pub p90: u64,
    /// 99th percentile.
    pub p99: u64,
    /// 99.9th percentile.
    pub p999: u64,
    /// Largest value.
    pub max: u64,
}

/// One histogram per hop, and one for the step.
pub struct Latency {
    /// Hop names, e.g. "plant->observer/uio".
    pub hops: Vec<String>,
    hist: Vec<Histogram<u64>>,
    step: Histogram<u64>,
}

/// The histogram every latency goes into: 1 ns … 100 s at 3 significant digits.
pub fn histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, 100_000_000_000, 3).expect("valid bounds")
}

impl Latency {
    /// For these hops.
    pub fn new(hops: Vec<String>) -> Self {
        let hist = hops.iter().map(|_| histogram()).collect();
        Latency {
            hops,
            hist,
            step: histogram(),
        }
    }

    /// Records one hop's latency.
    pub fn hop(&mut self, i: usize, ns: u64) {
        self.hist[i].saturating_record(ns.max(1));
    }

    /// Records one step's latency.
    pub fn step(&mut self, ns: u64) {
        self.step.saturating_record(ns.max(1));
    }

    /// Number of steps recorded.
    pub fn steps(&self) -> u64 {
        self.step.len()
    }

    /// Percentiles of a histogram (all zero when it is empty).
    pub fn percentiles(h: &Histogram<u64>) -> Percentiles {
        if h.is_empty() {
            return Percentiles::default();
        }
        Percentiles {
            p50: h.value_at_quantile(0.5),
            p90: h.value_at_quantile(0.9),
            p99: h.value_at_quantile(0.99),
            p999: h.value_at_quantile(0.999),
            max: h.max(),
        }
    }

    /// The step's percentiles.
    pub fn step_percentiles(&self) -> Percentiles {
        Self::percentiles(&self.step)
    }

    /// Each measured hop's percentiles (none in-process, where there are no hops).
    pub fn hop_percentiles(&self) -> Vec<(String, Percentiles)> {
        self.hops
            .iter()
            .zip(&self.hist)
            .filter(|(_, h)| !h.is_empty())
            .map(|(n, h)| (n.clone(), Self::percentiles(h)))
            .collect()
    }
}
