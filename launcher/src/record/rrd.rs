//! The `.rrd` recording: one scalar time series per signal, buffered and sent as columns.
//!
//! Series that share their time stamps form a group with one time column; rows are buffered and
//! each series is sent with `send_columns` every [`FLUSH_STEPS`] steps, so the recorder makes a
//! few large writes instead of one small write per sample. Timelines: `step` (sequence) and
//! `sim_time` (seconds).

use std::path::Path;

use std::sync::Arc;

use rerun::blueprint::Blueprint;
use rerun::external::arrow::array::{Array, Float64Array, ListArray};
use rerun::external::arrow::buffer::{OffsetBuffer, ScalarBuffer};
use rerun::external::arrow::datatypes::{DataType, FieldRef};
use rerun::time::Timeline;
use rerun::{ComponentDescriptor, RecordingStream, RecordingStreamBuilder, Scalars, SerializedComponentColumn, SeriesLines, TextDocument, TimeColumn};

use super::file_sink::UncompressedFileSink;

/// Steps buffered before a group is sent.
pub const FLUSH_STEPS: usize = 4096;

struct Group {
    steps: Vec<i64>,
    /// sim_time in nanoseconds (Rerun's duration unit).
    times_ns: Vec<i64>,
    series: Vec<(String, Vec<f64>)>,
}

/// Identifies a series: (group, index in group).
#[derive(Debug, Clone, Copy)]
pub struct SeriesId(usize, usize);

/// A recording being written.
pub struct RrdSink {
    rec: RecordingStream,
    groups: Vec<Group>,
    /// The list item field and descriptor Rerun uses for `Scalars`, taken from its own
    /// serialisation so the columns built here are exactly what `Scalars` would produce.
    item: FieldRef,
    descriptor: ComponentDescriptor,
}

impl RrdSink {
    /// Opens `path` for writing, with a blueprint and the scenario text as a document.
    pub fn create(path: &Path, name: &str, blueprint: Blueprint, scenario_toml: &str) -> Result<Self, String> {
        let sink = UncompressedFileSink::create(path)?;
        let rec = RecordingStreamBuilder::new("uio-observers")
            .recording_name(name)
            .with_blueprint(blueprint)
            .buffered()
            .map_err(|e| format!("{}: cannot record: {e}", path.display()))?;
        rec.set_sink(Box::new(sink));
        rec.log_static("scenario", &TextDocument::from_markdown(format!("```toml\n{scenario_toml}\n```")))
            .map_err(|e| e.to_string())?;
        let template = Scalars::new([0.0f64]).columns_of_unit_batches().map_err(|e| e.to_string())?.next().ok_or("no Scalars column")?;
        let DataType::List(item) = template.list_array.data_type().clone() else {
            return Err("unexpected Scalars layout".into());
        };
        Ok(RrdSink { rec, groups: Vec::new(), item, descriptor: template.descriptor })
    }

    /// A new group of series sharing time stamps; returns its index.
    pub fn group(&mut self) -> usize {
        self.groups.push(Group { steps: Vec::new(), times_ns: Vec::new(), series: Vec::new() });
        self.groups.len() - 1
    }

    /// Registers a series in `group` with its legend name.
    pub fn series(&mut self, group: usize, path: &str, legend: &str) -> SeriesId {
        let _ = self.rec.log_static(path, &SeriesLines::new().with_names([legend]));
        let g = &mut self.groups[group];
        g.series.push((path.to_string(), Vec::new()));
        SeriesId(group, g.series.len() - 1)
    }

    /// Starts a row of `group` at step k.
    #[inline]
    pub fn row(&mut self, group: usize, k: u64, t: f64) {
        let g = &mut self.groups[group];
        g.steps.push(k as i64);
        g.times_ns.push((t * 1e9).round() as i64);
    }

    /// Sets a series' value in its group's current row.
    #[inline]
    pub fn push(&mut self, id: SeriesId, v: f64) {
        self.groups[id.0].series[id.1].1.push(v);
    }

    /// Sends every group holding at least [`FLUSH_STEPS`] rows.
    pub fn flush_full(&mut self) -> Result<(), String> {
        for i in 0..self.groups.len() {
            if self.groups[i].steps.len() >= FLUSH_STEPS {
                self.send(i)?;
            }
        }
        Ok(())
    }

    fn send(&mut self, i: usize) -> Result<(), String> {
        let g = &mut self.groups[i];
        if g.steps.is_empty() {
            return Ok(());
        }
        let rows = g.steps.len();
        // One time column per group, shared (the buffers are reference-counted).
        let steps = TimeColumn::new(Some(true), Timeline::new_sequence("step"), ScalarBuffer::from(std::mem::take(&mut g.steps)));
        let times = TimeColumn::new(Some(true), Timeline::new_duration("sim_time"), ScalarBuffer::from(std::mem::take(&mut g.times_ns)));
        let offsets = OffsetBuffer::<i32>::from_lengths(std::iter::repeat_n(1, rows));
        for (path, values) in &mut g.series {
            // A series never filled in this mode (hops in-process) is not recorded.
            if values.is_empty() {
                continue;
            }
            if values.len() != rows {
                return Err(format!("{path}: {} values for {rows} rows", values.len()));
            }
            let array = Float64Array::from(std::mem::take(values));
            let list = ListArray::new(self.item.clone(), offsets.clone(), Arc::new(array), None);
            let column = SerializedComponentColumn::new(list, self.descriptor.clone());
            self.rec.send_columns(path.as_str(), [steps.clone(), times.clone()], [column]).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// Sends what is left, waits until it is on disk, and closes the file (writing its footer).
    pub fn finish(mut self) -> Result<(), String> {
        for i in 0..self.groups.len() {
            self.send(i)?;
        }
        self.rec.flush_blocking().map_err(|e| format!("recording: {e}"))?;
        drop(self.rec);
        Ok(())
    }
}
