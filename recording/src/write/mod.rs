//! Everything the launcher keeps of a run: each step's samples assembled into a [`StepRow`],
//! the figures of merit ([`Metrics`]), the latency histograms ([`Latency`]), and the `.rrd`
//! recording ([`RrdSink`]), written in batched columns off the lockstep's critical path.

mod blueprint;
mod columns;
mod file_sink;
mod latency;
mod layout;
mod metrics;
mod rrd;
mod select;
pub mod tail;
mod what;
mod whole_run;

pub use crate::nan::nan_max;
pub use blueprint::blueprint;
pub use file_sink::UncompressedFileSink;
pub use latency::{Latency, Percentiles, histogram};
pub use layout::{LAYOUT, Layout, Line, SERIES_COMPONENT, VALUES_COMPONENT};
pub use metrics::{FaultFree, Metrics, ObserverFigures};
pub use rrd::{FLUSH_STEPS, FLUSH_VALUES, RrdSink, SeriesId};
pub use select::Selection;
pub use what::InputEstimate;

use lockstep::{Header, PlantLayout};

/// The unit of every `/latency/…` value a recording holds, stored as its `latency_unit`
/// property: µs, so that the viewer's latency axes read 3.4, not 3 400 (recordings without the
/// property hold ns; [`crate::read::Recording::latency_ns_per_value`]).
pub const LATENCY_UNIT: &str = "µs";

/// One step of a run, as every component published it.
#[derive(Debug, Clone, Default)]
pub struct StepRow {
    /// Step k.
    pub k: u64,
    /// t_k.
    pub t: f64,
    /// The plant's sample ([`PlantLayout`]).
    pub plant: Vec<f64>,
    /// The plant sample's header.
    pub plant_hdr: Header,
    /// Each observer's x̂_k, in scenario order.
    pub xhat: Vec<Vec<f64>>,
    /// Their headers.
    pub xhat_hdr: Vec<Header>,
    /// The controller's u_k (empty without a controller).
    pub u: Vec<f64>,
    /// Its header.
    pub u_hdr: Header,
}

impl StepRow {
    /// An empty row sized for a run.
    pub fn new(layout: PlantLayout, observers: usize, controller: bool) -> Self {
        StepRow {
            plant: vec![0.0; layout.len()],
            xhat: vec![vec![0.0; layout.n]; observers],
            xhat_hdr: vec![Header::default(); observers],
            u: if controller {
                vec![0.0; layout.l]
            } else {
                Vec::new()
            },
            ..Default::default()
        }
    }
}
