//! Transport errors.

use thiserror::Error;

/// What can go wrong on the bus.
#[derive(Debug, Error)]
pub enum LockstepError {
    /// An iceoryx2 call failed.
    #[error("iceoryx2: {0}")]
    Ipc(String),
    /// A sample of the wrong step arrived: the lockstep is broken.
    #[error("lockstep broken on {topic}: expected step {expected}, got {got}")]
    Step {
        /// The service.
        topic: String,
        /// The step this component is at.
        expected: u64,
        /// The step the sample carries.
        got: u64,
    },
    /// A sample carried the wrong number of values.
    #[error("{topic}: sample has {got} values, expected {expected}")]
    Length {
        /// The service.
        topic: String,
        /// Expected count.
        expected: usize,
        /// Received count.
        got: usize,
    },
    /// A sample of another protocol version arrived.
    #[error(
        "{topic}: sample of protocol version {got}, this component speaks {}",
        crate::PROTOCOL_VERSION
    )]
    Protocol {
        /// The service.
        topic: String,
        /// The version the sample carries.
        got: u32,
    },
    /// Nothing arrived within the timeout.
    #[error("no sample on {topic} for {secs} s (step {step}): is the peer still running?")]
    Timeout {
        /// The service.
        topic: String,
        /// The step waited for.
        step: u64,
        /// The timeout, s.
        secs: u64,
    },
    /// File-system work on the run directory failed.
    #[error("{0}")]
    Io(String),
}

impl LockstepError {
    pub(crate) fn ipc(e: impl std::fmt::Debug) -> Self {
        LockstepError::Ipc(format!("{e:?}"))
    }
}
