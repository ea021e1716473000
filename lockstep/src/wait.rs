//! How a process waits for its next sample.
//!
//! Only one component has work at any moment of a lockstep step, and on a machine with fewer
//! cores than processes a waiting process must give its core away: every strategy here either
//! yields between polls or sleeps in the kernel. The one exception, `spin-then-yield`, spins
//! only for a bounded few nanoseconds before it starts yielding.

use std::str::FromStr;

/// Wait strategy for [`crate::Inlet::wait_step`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wait {
    /// Poll the subscriber, `sched_yield` between polls. Fastest when a core is free.
    Yield,
    /// Block on an iceoryx2 event until the publisher notifies (one wake-up per hop).
    Block,
    /// Block in an iceoryx2 WaitSet (epoll) to which the event listener is attached.
    WaitSet,
    /// Yield-poll for up to this many microseconds, then block.
    SpinThenBlock(u32),
    /// Poll, sleeping this many microseconds between polls: for processes off the critical
    /// path, which then take a core only briefly and work through a batch of samples.
    Sleep(u32),
    /// Busy-poll (with the CPU's spin hint) for up to this many nanoseconds, then yield-poll.
    SpinThenYield(u32),
}

impl Wait {
    /// Whether publishers must notify an event after each send.
    pub fn needs_events(self) -> bool {
        matches!(self, Wait::Block | Wait::WaitSet | Wait::SpinThenBlock(_))
    }

    /// The default: yielding polls, whatever the machine (measured fastest on 2 cores and up;
    /// a yielding process never starves the one with work). A function, not a constant, so a
    /// choice by core count can be added without touching the callers.
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
            "waitset" => Ok(Wait::WaitSet),
            _ if s.starts_with("spin-then-yield:") => s["spin-then-yield:".len()..]
                .parse()
                .map(Wait::SpinThenYield)
                .map_err(|_| format!("'{s}': write spin-then-yield:<nanoseconds>")),
            _ if s.starts_with("sleep:") => s["sleep:".len()..]
                .parse()
                .map(Wait::Sleep)
                .map_err(|_| format!("'{s}': write sleep:<microseconds>")),
            _ => match s.strip_prefix("spin-then-block") {
                Some("") => Ok(Wait::SpinThenBlock(50)),
                Some(rest) => rest
                    .strip_prefix(':')
                    .and_then(|us| us.parse().ok())
                    .map(Wait::SpinThenBlock)
                    .ok_or_else(|| format!("'{s}': write spin-then-block:<microseconds>")),
                None => Err(format!(
                    "'{s}' is not a wait strategy (yield, block, waitset, spin-then-block[:µs], spin-then-yield:ns, sleep:µs)"
                )),
            },
        }
    }
}

impl std::fmt::Display for Wait {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Wait::Yield => write!(f, "yield"),
            Wait::Block => write!(f, "block"),
            Wait::WaitSet => write!(f, "waitset"),
            Wait::SpinThenBlock(us) => write!(f, "spin-then-block:{us}"),
            Wait::Sleep(us) => write!(f, "sleep:{us}"),
            Wait::SpinThenYield(ns) => write!(f, "spin-then-yield:{ns}"),
        }
    }
}
