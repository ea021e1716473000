//! The offset between two hosts' CLOCK_MONOTONIC, from round trips (Cristian's method, as NTP
//! uses it): the proxy sends its time t₁, the worker answers with t₁ and its own time t₂, the
//! proxy takes t₃ on arrival. If the message took as long each way, the worker's clock reads
//! θ = t₂ − (t₁ + t₃)/2 ahead of the proxy's, wrong by at most half the round trip t₃ − t₁; the
//! round trip that was shortest bounds it best. With θ, the headers of samples that cross are
//! put on the receiving host's clock, so the launcher's hop latencies compare like times.

/// θ (the remote clock minus the local one) and the round trip it came from, ns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Offset {
    /// Remote minus local, ns.
    pub theta_ns: i64,
    /// The round trip of the exchange it came from: |error| ≤ rtt/2.
    pub rtt_ns: u64,
}

/// The estimate of the exchange (t₁, t₂, t₃) with the shortest round trip.
pub fn estimate(exchanges: &[(u64, u64, u64)]) -> Option<Offset> {
    exchanges
        .iter()
        .filter(|(t1, _, t3)| t3 >= t1)
        .min_by_key(|(t1, _, t3)| t3 - t1)
        .map(|&(t1, t2, t3)| Offset {
            theta_ns: t2 as i64 - ((t1 as i128 + t3 as i128) / 2) as i64,
            rtt_ns: t3 - t1,
        })
}

/// A header time moved by `by` ns onto another clock; 0 (no time: the plant's k = 0) stays 0.
pub fn shift(t: u64, by: i64) -> u64 {
    if t == 0 {
        0
    } else {
        (t as i64).saturating_add(by).max(1) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shortest_round_trip_gives_the_offset() {
        // The remote clock is 5 s ahead. Symmetric 40 µs legs give it exactly; an asymmetric
        // exchange (10 µs out, 300 µs back) is off by 145 µs, but its round trip is longer.
        let ahead = 5_000_000_000i64;
        let ex = |t1: u64, out: u64, back: u64| {
            (t1, (t1 + out) as i64 as u64 + ahead as u64, t1 + out + back)
        };
        let e = estimate(&[
            ex(1_000, 10_000, 300_000),
            ex(2_000_000, 40_000, 40_000),
            ex(3_000_000, 90_000, 90_000),
        ])
        .unwrap();
        assert_eq!(
            e,
            Offset {
                theta_ns: ahead,
                rtt_ns: 80_000
            }
        );
        let skewed = estimate(&[ex(1_000, 10_000, 300_000)]).unwrap();
        assert_eq!(skewed.theta_ns - ahead, 10_000 - 155_000);
        assert!((skewed.theta_ns - ahead).unsigned_abs() <= skewed.rtt_ns / 2);
        assert_eq!(estimate(&[]), None);
    }

    #[test]
    fn shifting_keeps_the_absent_time() {
        assert_eq!(shift(0, -7), 0);
        assert_eq!(shift(100, -7), 93);
        assert_eq!(shift(100, 7), 107);
        assert_eq!(shift(5, -100), 1);
    }
}
