//! The launcher: reads a scenario, designs its observers and controller, runs the components
//! (as separate processes over iceoryx2, or in one process), and records every signal to a
//! Rerun `.rrd` with a summary of how each observer did.

pub mod bench;
pub mod calibrate;
pub mod design_report;
pub mod error;
pub mod limits;
pub mod output;
pub mod plan;
pub mod replay;
pub mod run;
pub mod shipped;
pub mod summary;
pub mod sweep;
pub mod vary;

pub use error::LaunchError;
pub use scenario::Scenario;
