//! The `.rrd` recording: one scalar time series per signal, buffered and sent as columns.
//!
//! Series that share their time stamps form a group with one time column; rows are buffered and
//! each series is sent with `send_columns` every [`FLUSH_STEPS`] steps, so the recorder makes a
//! few large writes instead of one small write per sample. Timelines: `step` (sequence) and
//! `sim_time` (seconds). What is sent is thinned and filtered by a [`Selection`] and digested
//! ([`crate::digest`]); the digest is written when the recording is closed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use std::sync::{Arc, Mutex};

use rerun::blueprint::Blueprint;
use rerun::external::arrow::array::{Array, Float64Array, ListArray};
use rerun::external::arrow::buffer::{OffsetBuffer, ScalarBuffer};
use rerun::external::arrow::datatypes::{DataType, FieldRef};
use rerun::time::Timeline;
use rerun::{Color, ComponentDescriptor, RecordingStream, RecordingStreamBuilder, Scalars, SerializedComponentColumn, SeriesLines, TextDocument, TimeColumn};

use super::file_sink::UncompressedFileSink;
use super::select::Selection;
use crate::digest::{self, Running};
use crate::palette::Rgb;

/// Steps buffered before a group is sent.
pub const FLUSH_STEPS: usize = 4096;

struct Group {
    steps: Vec<i64>,
    /// sim_time in nanoseconds (Rerun's duration unit).
    times_ns: Vec<i64>,
    series: Vec<(String, Vec<f64>)>,
    /// The current row is not recorded (thinned out): its values are dropped.
    skip: bool,
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
    /// The file, for messages.
    path: PathBuf,
    /// The first write error of the file sink (which writes on Rerun's thread).
    error: Arc<Mutex<Option<String>>>,
    select: Selection,
    /// Per entity sent, and the scenario text.
    digests: BTreeMap<String, Running>,
    scenario_digest: String,
}

impl RrdSink {
    /// Opens `path` for writing, with a blueprint and the scenario text as a document.
    pub fn create(path: &Path, name: &str, blueprint: Blueprint, scenario_toml: &str) -> Result<Self, String> {
        let sink = UncompressedFileSink::create(path)?;
        let error = sink.error_slot();
        let rec = RecordingStreamBuilder::new("uio-observers")
            .recording_name(name)
            .with_blueprint(blueprint)
            .buffered()
            .map_err(|e| format!("{}: cannot record: {e}", path.display()))?;
        rec.set_sink(Box::new(sink));
        let scenario_text = format!("```toml\n{scenario_toml}\n```");
        let scenario_digest = digest::of_text(&scenario_text);
        rec.log_static("scenario", &TextDocument::from_markdown(scenario_text)).map_err(|e| e.to_string())?;
        let template = Scalars::new([0.0f64]).columns_of_unit_batches().map_err(|e| e.to_string())?.next().ok_or("no Scalars column")?;
        let DataType::List(item) = template.list_array.data_type().clone() else {
            return Err("unexpected Scalars layout".into());
        };
        Ok(RrdSink {
            rec,
            groups: Vec::new(),
            item,
            descriptor: template.descriptor,
            path: path.to_path_buf(),
            error,
            select: Selection::default(),
            digests: BTreeMap::new(),
            scenario_digest,
        })
    }

    /// Records only what `select` selects (set before the first row).
    pub fn select(&mut self, select: Selection) {
        self.select = select;
    }

    /// A new group of series sharing time stamps; returns its index.
    pub fn group(&mut self) -> usize {
        self.groups.push(Group { steps: Vec::new(), times_ns: Vec::new(), series: Vec::new(), skip: false });
        self.groups.len() - 1
    }

    /// Registers a series in `group` with its legend name, colour and line width (points),
    /// logged once as static `SeriesLines` so every view draws it the same way.
    pub fn series(&mut self, group: usize, path: &str, legend: &str, color: Rgb, width: f32) -> SeriesId {
        let [r, g, b] = color;
        let lines = SeriesLines::new().with_names([legend]).with_colors([Color::from_rgb(r, g, b)]).with_widths([width]);
        let _ = self.rec.log_static(path, &lines);
        let g = &mut self.groups[group];
        g.series.push((path.to_string(), Vec::new()));
        SeriesId(group, g.series.len() - 1)
    }

    /// Starts a row of `group` at step k (a row of a step not selected is dropped).
    #[inline]
    pub fn row(&mut self, group: usize, k: u64, t: f64) {
        let selected = self.select.step(k);
        let g = &mut self.groups[group];
        g.skip = !selected;
        if selected {
            g.steps.push(k as i64);
            g.times_ns.push((t * 1e9).round() as i64);
        }
    }

    /// Sets a series' value in its group's current row.
    #[inline]
    pub fn push(&mut self, id: SeriesId, v: f64) {
        let g = &mut self.groups[id.0];
        if !g.skip {
            g.series[id.1].1.push(v);
        }
    }

    /// Sends every group holding at least [`FLUSH_STEPS`] rows; fails once the file could not
    /// be written (a full disk), naming it.
    pub fn flush_full(&mut self) -> Result<(), String> {
        for i in 0..self.groups.len() {
            if self.groups[i].steps.len() >= FLUSH_STEPS {
                self.send(i)?;
            }
        }
        self.write_error()
    }

    /// The file sink's first write error, if any.
    fn write_error(&self) -> Result<(), String> {
        match self.error.lock().ok().and_then(|e| e.clone()) {
            Some(e) => Err(format!("{}: cannot write: {e}", self.path.display())),
            None => Ok(()),
        }
    }

    fn send(&mut self, i: usize) -> Result<(), String> {
        let g = &mut self.groups[i];
        if g.steps.is_empty() {
            return Ok(());
        }
        let rows = g.steps.len();
        // Fresh buffers of a whole batch: the per-step pushes never grow them again.
        let step_values = std::mem::replace(&mut g.steps, Vec::with_capacity(FLUSH_STEPS));
        let offsets = OffsetBuffer::<i32>::from_lengths(std::iter::repeat_n(1, rows));
        let mut columns = Vec::new();
        for (path, values) in &mut g.series {
            // A series never filled in this mode (hops in-process), or not selected, is not recorded.
            if values.is_empty() || !self.select.entity(path) {
                values.clear();
                continue;
            }
            if values.len() != rows {
                return Err(format!("{path}: {} values for {rows} rows", values.len()));
            }
            self.digests.entry(path.clone()).or_default().update(&step_values, Some(&g.times_ns), values);
            let array = Float64Array::from(std::mem::replace(values, Vec::with_capacity(FLUSH_STEPS)));
            let list = ListArray::new(self.item.clone(), offsets.clone(), Arc::new(array), None);
            columns.push((path.clone(), SerializedComponentColumn::new(list, self.descriptor.clone())));
        }
        // One time column per group, shared (the buffers are reference-counted).
        let steps = TimeColumn::new(Some(true), Timeline::new_sequence("step"), ScalarBuffer::from(step_values));
        let times = TimeColumn::new(Some(true), Timeline::new_duration("sim_time"), ScalarBuffer::from(std::mem::replace(&mut g.times_ns, Vec::with_capacity(FLUSH_STEPS))));
        for (path, column) in columns {
            self.rec.send_columns(path.as_str(), [steps.clone(), times.clone()], [column]).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// Sends what is left, the number of steps the run completed (a thinned or filtered
    /// recording cannot tell it), and the digest of everything sent; waits until it is on disk,
    /// and closes the file (writing its footer). Returns the digest, entity → 16 hex digits.
    pub fn finish(mut self, steps_completed: u64) -> Result<BTreeMap<String, String>, String> {
        for i in 0..self.groups.len() {
            self.send(i)?;
        }
        self.rec.send_property("steps", &TextDocument::new(steps_completed.to_string())).map_err(|e| e.to_string())?;
        let mut digests: BTreeMap<String, String> = self.digests.iter().map(|(k, d)| (k.clone(), d.hex())).collect();
        digests.insert(digest::SCENARIO_KEY.into(), self.scenario_digest.clone());
        self.rec.send_property("digest", &TextDocument::new(digest::to_json(&digests))).map_err(|e| e.to_string())?;
        let flushed = self.rec.flush_blocking();
        self.write_error()?;
        flushed.map_err(|e| format!("{}: cannot write: {e}", self.path.display()))?;
        // Dropping the stream drops the file sink, which writes the footer.
        let (rec, error, path) = (self.rec, self.error, self.path);
        drop(rec);
        if let Some(e) = error.lock().ok().and_then(|e| e.clone()) {
            return Err(format!("{}: cannot write its footer: {e}", path.display()));
        }
        Ok(digests)
    }
}
