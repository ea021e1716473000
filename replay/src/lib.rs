//! Recorded data as the true plant of a run (`[plant.replay]`): a CSV log whose columns are
//! mapped by header name, an MCAP log whose JSON messages' fields are mapped by name the same
//! way, or a run's own `.rrd`, read into a [`Table`] of plant samples on the
//! run's grid (PROTOCOL.md §4, without the fault slots, which the scenario's `[[fault]]` table
//! fills). The `uio-replay-plant` component publishes them; `uio-replay-plant --check` reads the file
//! before a run so that bad data is refused with exit 2 before anything runs.

pub mod csv;
pub mod mcap;
pub mod params;
pub mod rrd;
pub mod samples;
pub mod table;

pub use params::Params;
pub use table::{Facts, Table};

/// Reads the data the parameters name, on the run's grid of `steps` steps of `dt`.
pub fn load(p: &Params) -> Result<Table, String> {
    match p.format.as_str() {
        "csv" => csv::load(p),
        "mcap" => mcap::load(p),
        "rrd" => rrd::load(p),
        other => Err(format!(
            "{}: format {other:?}: a .csv or .mcap log or a run's .rrd",
            p.path
        )),
    }
}
