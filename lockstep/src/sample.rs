//! The one payload type on every service.
//!
//! iceoryx2 checks the payload's type name and layout when a port opens a service; keeping the
//! type in this one crate is what lets separately built binaries agree (else
//! `IncompatibleTypes`).

use iceoryx2::prelude::*;

/// Capacity of a sample, in f64 values.
pub const MAX_VALUES: usize = 64;

/// A fixed-layout sample: header plus up to [`MAX_VALUES`] values.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("uio_observers::Sample")]
#[repr(C)]
pub struct Sample {
    /// Step counter k.
    pub step: u64,
    /// Simulation time t_k = k·dt, s.
    pub sim_time: f64,
    /// Monotonic time at which the publisher sent the sample, ns.
    pub sent_ns: u64,
    /// Monotonic time at which the publisher took the input that completed this step, ns
    /// (0 when there was none).
    pub taken_ns: u64,
    /// Number of meaningful values.
    pub len: u32,
    /// Padding, always 0.
    pub reserved: u32,
    /// The values; entries past `len` are 0.
    pub values: [f64; MAX_VALUES],
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
