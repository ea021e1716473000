//! Recording I/O: what a run writes to its Rerun `.rrd` ([`write`]: the step rows, figures,
//! latency histograms, blueprint and the column writer) and the tools that read one back
//! ([`read`], [`inspect`], [`compare`], [`export`], [`plot`]) with no run or scenario needed.
//! [`signals`] names every entity and [`palette`] colours it, for the writer and readers alike.

pub mod compare;
pub mod deviations;
pub mod digest;
pub mod export;
mod globs;
pub mod inspect;
mod nan;
pub mod palette;
pub mod plot;
pub mod read;
pub mod signals;
pub mod tools;
pub mod write;

pub use digest::Integrity;
pub use read::{Recording, Series, read};
