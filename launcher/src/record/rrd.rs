//! The `.rrd` recording: one scalar time series per signal, buffered and sent as columns.
//!
//! Rows are buffered per channel and sent with `send_columns` every [`FLUSH_STEPS`] steps, so
//! the recorder does a few large writes instead of one small write per sample. Timelines:
//! `step` (sequence) and `sim_time` (seconds).

use std::path::Path;

use rerun::blueprint::Blueprint;
use rerun::{RecordingStream, RecordingStreamBuilder, Scalars, SeriesLines, TextDocument, TimeColumn};

/// Steps buffered before a channel is sent.
pub const FLUSH_STEPS: usize = 4096;

struct Channel {
    path: String,
    steps: Vec<i64>,
    times: Vec<f64>,
    values: Vec<f64>,
}

/// A recording being written.
pub struct RrdSink {
    rec: RecordingStream,
    channels: Vec<Channel>,
}

impl RrdSink {
    /// Opens `path` for writing, with a blueprint and the scenario text as a document.
    pub fn create(path: &Path, name: &str, blueprint: Blueprint, scenario_toml: &str) -> Result<Self, String> {
        let rec = RecordingStreamBuilder::new("uio-observers")
            .recording_name(name)
            .with_blueprint(blueprint)
            .save(path)
            .map_err(|e| format!("{}: cannot record: {e}", path.display()))?;
        rec.log_static("scenario", &TextDocument::from_markdown(format!("```toml\n{scenario_toml}\n```")))
            .map_err(|e| e.to_string())?;
        Ok(RrdSink { rec, channels: Vec::new() })
    }

    /// Registers a series with its legend name; returns its id.
    pub fn channel(&mut self, path: &str, legend: &str) -> usize {
        let _ = self.rec.log_static(path, &SeriesLines::new().with_names([legend]));
        self.channels.push(Channel { path: path.to_string(), steps: Vec::new(), times: Vec::new(), values: Vec::new() });
        self.channels.len() - 1
    }

    /// Appends one value.
    #[inline]
    pub fn push(&mut self, ch: usize, k: u64, t: f64, v: f64) {
        let c = &mut self.channels[ch];
        c.steps.push(k as i64);
        c.times.push(t);
        c.values.push(v);
    }

    /// Sends every channel holding at least [`FLUSH_STEPS`] values.
    pub fn flush_full(&mut self) -> Result<(), String> {
        for i in 0..self.channels.len() {
            if self.channels[i].values.len() >= FLUSH_STEPS {
                self.send(i)?;
            }
        }
        Ok(())
    }

    fn send(&mut self, i: usize) -> Result<(), String> {
        let c = &mut self.channels[i];
        if c.values.is_empty() {
            return Ok(());
        }
        let steps = TimeColumn::new_sequence("step", c.steps.drain(..));
        let times = TimeColumn::new_duration_secs("sim_time", c.times.drain(..));
        let columns = Scalars::new(c.values.drain(..)).columns_of_unit_batches().map_err(|e| e.to_string())?;
        self.rec.send_columns(c.path.as_str(), [steps, times], columns).map_err(|e| e.to_string())
    }

    /// Sends what is left, waits until it is on disk, and closes the file (writing its footer).
    pub fn finish(mut self) -> Result<(), String> {
        for i in 0..self.channels.len() {
            self.send(i)?;
        }
        self.rec.flush_blocking().map_err(|e| format!("recording: {e}"))?;
        drop(self.rec);
        Ok(())
    }
}
