//! How a process waits for its next sample.
//!
//! Only one component has work at any moment of a lockstep step, and on a machine with fewer
//! cores than processes a waiting process must give its core away: every strategy here either
//! yields between polls or sleeps in the kernel, none spins without yielding.

use std::str::FromStr;

/// Wait strategy for [`crate::Inlet::wait_step`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wait {
    /// Poll the subscriber, `sched_yield` between polls. Fastest when a core is free.
    Yield,
    /// Block on an iceoryx2 event until the publisher notifies (one wake-up per hop).
    Block,
    /// Yield-poll for up to this many microseconds, then block.
    SpinThenBlock(u32),
}

impl Wait {
    /// Whether publishers must notify an event after each send.
    pub fn needs_events(self) -> bool {
        !matches!(self, Wait::Yield)
    }

    /// The default for this machine: yielding polls (measured fastest on 2 cores and up; a
    /// yielding process never starves the one with work).
    pub fn default_for_machine() -> Wait {
        Wait::Yield
    }
}

impl FromStr for Wait {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "yield" => Ok(Wait::Yield),
            "block" => Ok(Wait::Block),
            _ => match s.strip_prefix("spin-then-block") {
                Some("") => Ok(Wait::SpinThenBlock(50)),
                Some(rest) => rest
                    .strip_prefix(':')
                    .and_then(|us| us.parse().ok())
                    .map(Wait::SpinThenBlock)
                    .ok_or_else(|| format!("'{s}': write spin-then-block:<microseconds>")),
                None => Err(format!("'{s}' is not a wait strategy (yield, block, spin-then-block[:µs])")),
            },
        }
    }
}

impl std::fmt::Display for Wait {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Wait::Yield => write!(f, "yield"),
            Wait::Block => write!(f, "block"),
            Wait::SpinThenBlock(us) => write!(f, "spin-then-block:{us}"),
        }
    }
}
