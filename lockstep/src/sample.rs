//! The wire format of every service (PROTOCOL.md §4): a slice of `f64` whose length a run's
//! configuration fixes per service, behind a fixed user header.
//!
//! iceoryx2 checks the payload's and the header's type names and layouts when a port opens a
//! service; keeping the header type in this one crate is what lets separately built binaries
//! agree (else `IncompatibleTypes`). The value count belongs to the run, not to the type, so a
//! sample may hold any number of values without a new protocol version.

use iceoryx2::prelude::*;

/// The protocol version every sample and configuration carries (PROTOCOL.md §9).
pub const PROTOCOL_VERSION: u32 = 1;

/// The user header of every sample (PROTOCOL.md §4): 40 bytes, little-endian, align 8.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("uio_observers::Header")]
#[repr(C)]
pub struct WireHeader {
    /// Step counter k.
    pub step: u64,
    /// Simulation time t_k = k·dt, s.
    pub sim_time: f64,
    /// CLOCK_MONOTONIC at which the publisher sent the sample, ns.
    pub sent_ns: u64,
    /// CLOCK_MONOTONIC at which the publisher took the last exact input of this step, ns; with
    /// none, when it took its inputs; 0 at the plant's k = 0.
    pub taken_ns: u64,
    /// [`PROTOCOL_VERSION`].
    pub protocol: u32,
    /// Always 0.
    pub reserved: u32,
}

impl WireHeader {
    /// What is wrong with the header's own stamps, if anything (PROTOCOL.md §6): a `sim_time`
    /// that is not finite, or a `taken_ns` later than `sent_ns` — a publisher takes its input
    /// before it sends what it made of it, so a later stamp (`u64::MAX` included) is forged, the
    /// way a component that publishes without reading would hide it.
    pub fn stamp_violation(&self) -> Option<String> {
        if !self.sim_time.is_finite() {
            return Some(format!("its sample's sim_time is {}", self.sim_time));
        }
        if self.taken_ns > self.sent_ns {
            return Some(format!(
                "its sample says it took its input at {} ns, after it sent the sample at {} ns (CLOCK_MONOTONIC)",
                self.taken_ns, self.sent_ns
            ));
        }
        None
    }
}

/// The header of a received sample, plus the time this process took it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Header {
    /// Step counter.
    pub step: u64,
    /// Simulation time, s.
    pub sim_time: f64,
    /// Sender's send time, ns.
    pub sent_ns: u64,
    /// Sender's take time of its own input, ns.
    pub taken_ns: u64,
    /// When this process took the sample, ns.
    pub received_ns: u64,
}

impl Header {
    /// The header of a received sample, taken at `received_ns`.
    pub fn of(w: &WireHeader, received_ns: u64) -> Self {
        Header {
            step: w.step,
            sim_time: w.sim_time,
            sent_ns: w.sent_ns,
            taken_ns: w.taken_ns,
            received_ns,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forged_stamps_are_named() {
        let ok = WireHeader {
            step: 3,
            sim_time: 0.003,
            sent_ns: 200,
            taken_ns: 150,
            protocol: PROTOCOL_VERSION,
            reserved: 0,
        };
        assert_eq!(ok.stamp_violation(), None);
        assert_eq!(
            WireHeader { taken_ns: 0, ..ok }.stamp_violation(),
            None,
            "the plant's k = 0"
        );
        assert!(
            WireHeader {
                taken_ns: u64::MAX,
                ..ok
            }
            .stamp_violation()
            .unwrap()
            .contains("after it sent")
        );
        assert!(
            WireHeader {
                sim_time: f64::NAN,
                ..ok
            }
            .stamp_violation()
            .unwrap()
            .contains("sim_time is NaN")
        );
        assert!(
            WireHeader {
                sim_time: f64::INFINITY,
                ..ok
            }
            .stamp_violation()
            .is_some()
        );
    }
}
