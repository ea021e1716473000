//! The `.rrd` recording, layout 2 ([`LAYOUT`]): one wide row per entity and step.
//!
//! Layout 1 made every scalar an entity of its own, and each of its rows carried a row id (16
//! bytes), two times (16) and a list offset (4) for 8 bytes of value: ≈ 1.4 KB a step for seed
//! 002's 33 scalars. Here the signals one component publishes share an entity
//! ([`crate::signals::entity_of`]), and a row of it holds their values as one list
//! ([`VALUES_COMPONENT`]: one instance per row, a list of K doubles), so a step costs those 36
//! bytes and one more offset once per entity, and 8 bytes per value. One list per row, not K
//! `Scalars` instances, because the viewer's selector `.[i]` picks element i of a list
//! instance — that is how a plot shows one signal of an entity ([`super::blueprint`]). Each
//! entity carries, as statics, the signal behind each element ([`SERIES_COMPONENT`]) and its
//! legend, colour and width (`SeriesLines`); readers split the rows back into the signals.
//!
//! Entities whose signals share time stamps form a group with one time column; rows are
//! buffered and sent with `send_columns` every [`FLUSH_STEPS`] steps. Timelines: `step`
//! (sequence) and `sim_time` (seconds). What is sent is thinned and filtered by a
//! [`Selection`] and digested per signal ([`crate::digest`]); the digest is written when the
//! recording is closed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use rerun::blueprint::{Blueprint, BlueprintActivation};
use rerun::external::arrow::array::{ArrayRef, Float64Array, ListArray, StringArray};
use rerun::external::arrow::buffer::{OffsetBuffer, ScalarBuffer};
use rerun::external::arrow::datatypes::{DataType, Field, FieldRef};
use rerun::time::Timeline;
use rerun::{AsComponents as _, Color, ComponentDescriptor, RecordingStream, RecordingStreamBuilder, SerializedComponentBatch, SerializedComponentColumn, SeriesLines, TextDocument, TimeColumn};

use super::file_sink::UncompressedFileSink;
use super::layout::{Layout, Line, LAYOUT, SERIES_COMPONENT, VALUES_COMPONENT};
use super::select::Selection;
use crate::digest::{self, Running};
use crate::palette::Rgb;
use crate::signals;

/// Steps buffered before a group is sent.
pub const FLUSH_STEPS: usize = 4096;

/// Makes the blueprint once the layout is known.
type MakeBlueprint = Box<dyn FnOnce(&Layout) -> Blueprint + Send>;

struct Group {
    /// Names the entities of this group whose component also has entities in an earlier group.
    label: String,
    steps: Vec<i64>,
    /// sim_time in nanoseconds (Rerun's duration unit).
    times_ns: Vec<i64>,
    entities: Vec<usize>,
    /// The current row is not recorded (thinned out): its values are dropped.
    skip: bool,
}

struct Entity {
    path: String,
    group: usize,
    /// Every live signal registered here, in order.
    series: Vec<usize>,
    /// Its instances, once decided ([`RrdSink::freeze`]).
    instances: Option<Vec<usize>>,
}

struct Signal {
    path: String,
    legend: String,
    color: Rgb,
    width: f32,
    group: usize,
    /// Selected, and not found unfilled when its entity was frozen.
    live: bool,
    values: Vec<f64>,
}

/// Identifies a signal.
#[derive(Debug, Clone, Copy)]
pub struct SeriesId(usize);

/// A recording being written.
pub struct RrdSink {
    rec: RecordingStream,
    groups: Vec<Group>,
    entities: Vec<Entity>,
    signals: Vec<Signal>,
    /// The fields of a row's list of doubles, and of the column's list of those lists.
    inner: FieldRef,
    outer: FieldRef,
    /// The file, for messages.
    path: PathBuf,
    /// The first write error of the file sink (which writes on Rerun's thread).
    error: Arc<Mutex<Option<String>>>,
    select: Selection,
    blueprint: Option<MakeBlueprint>,
    /// Per signal sent, and the scenario text.
    digests: BTreeMap<String, Running>,
    scenario_digest: String,
}

impl RrdSink {
    /// Opens `path` for writing, with the scenario text as a document and the layout version
    /// as a property; `blueprint` is made and sent when the layout is known (the first send).
    pub fn create(path: &Path, name: &str, blueprint: impl FnOnce(&Layout) -> Blueprint + Send + 'static, scenario_toml: &str) -> Result<Self, String> {
        let sink = UncompressedFileSink::create(path)?;
        let error = sink.error_slot();
        let rec = RecordingStreamBuilder::new("uio-observers")
            .recording_name(name)
            .buffered()
            .map_err(|e| format!("{}: cannot record: {e}", path.display()))?;
        rec.set_sink(Box::new(sink));
        rec.send_property("layout", &TextDocument::new(LAYOUT.to_string())).map_err(|e| e.to_string())?;
        let scenario_text = format!("```toml\n{scenario_toml}\n```");
        let scenario_digest = digest::of_text(&scenario_text);
        rec.log_static("scenario", &TextDocument::from_markdown(scenario_text)).map_err(|e| e.to_string())?;
        let inner = Arc::new(Field::new("item", DataType::Float64, true));
        let outer = Arc::new(Field::new("item", DataType::List(inner.clone()), true));
        Ok(RrdSink {
            rec,
            groups: Vec::new(),
            entities: Vec::new(),
            signals: Vec::new(),
            inner,
            outer,
            path: path.to_path_buf(),
            error,
            select: Selection::default(),
            blueprint: Some(Box::new(blueprint)),
            digests: BTreeMap::new(),
            scenario_digest,
        })
    }

    /// Records only what `select` selects (set before the first signal).
    pub fn select(&mut self, select: Selection) {
        self.select = select;
    }

    /// A new group of signals sharing time stamps; returns its index. `label` names its
    /// entities where their component already has one in an earlier group
    /// (`/observer/uio/what` beside `/observer/uio`).
    pub fn group(&mut self, label: &str) -> usize {
        self.groups.push(Group { label: label.to_string(), steps: Vec::new(), times_ns: Vec::new(), entities: Vec::new(), skip: false });
        self.groups.len() - 1
    }

    /// Registers signal `path` in `group` with its legend name, colour and line width (points).
    pub fn series(&mut self, group: usize, path: &str, legend: &str, color: Rgb, width: f32) -> SeriesId {
        let live = self.select.entity(path);
        let id = self.signals.len();
        self.signals.push(Signal { path: path.to_string(), legend: legend.to_string(), color, width, group, live, values: Vec::new() });
        if live {
            let owner = signals::entity_of(path);
            let e = match self.entities.iter().position(|e| e.group == group && (e.path == owner || e.path == format!("{owner}/{}", self.groups[group].label))) {
                Some(e) => e,
                None => {
                    let taken = self.entities.iter().any(|e| e.path == owner);
                    let path = if taken { format!("{owner}/{}", self.groups[group].label) } else { owner };
                    self.entities.push(Entity { path, group, series: Vec::new(), instances: None });
                    self.groups[group].entities.push(self.entities.len() - 1);
                    self.entities.len() - 1
                }
            };
            self.entities[e].series.push(id);
        }
        SeriesId(id)
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

    /// Sets a signal's value in its group's current row.
    #[inline]
    pub fn push(&mut self, id: SeriesId, v: f64) {
        let s = &mut self.signals[id.0];
        if s.live && !self.groups[s.group].skip {
            s.values.push(v);
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

    /// Decides the instances of every entity whose group has rows (a signal never filled in
    /// this mode — a hop in-process — is left out), logs their statics, and sends the blueprint.
    /// An entity whose group has no rows yet keeps every signal, decided at its first send.
    fn freeze(&mut self) -> Result<(), String> {
        for e in 0..self.entities.len() {
            if self.entities[e].instances.is_none() && !self.groups[self.entities[e].group].steps.is_empty() {
                let filled: Vec<usize> = self.entities[e].series.iter().copied().filter(|&s| !self.signals[s].values.is_empty()).collect();
                self.fix(e, filled)?;
            }
        }
        let Some(make) = self.blueprint.take() else { return Ok(()) };
        let mut layout = Layout::default();
        for e in &self.entities {
            let instances = e.instances.as_ref().unwrap_or(&e.series);
            layout.entity(&e.path, instances.iter().map(|&s| {
                let sig = &self.signals[s];
                (sig.path.clone(), Line { legend: sig.legend.clone(), color: sig.color, width: sig.width })
            }));
        }
        make(&layout).send(&self.rec, BlueprintActivation { make_active: true, make_default: true }).map_err(|e| e.to_string())
    }

    /// Fixes entity `e`'s instances and logs its statics.
    fn fix(&mut self, e: usize, instances: Vec<usize>) -> Result<(), String> {
        for &s in &self.entities[e].series {
            if !instances.contains(&s) {
                self.signals[s].live = false;
                self.signals[s].values = Vec::new();
            }
        }
        if !instances.is_empty() {
            let sig = |s: &usize| &self.signals[*s];
            let lines = SeriesLines::new()
                .with_names(instances.iter().map(|s| sig(s).legend.clone()))
                .with_colors(instances.iter().map(|s| Color::from_rgb(sig(s).color[0], sig(s).color[1], sig(s).color[2])))
                .with_widths(instances.iter().map(|s| sig(s).width));
            let names: ArrayRef = Arc::new(StringArray::from_iter_values(instances.iter().map(|s| sig(s).path.as_str())));
            let mut batches = lines.as_serialized_batches();
            batches.push(SerializedComponentBatch::new(names, ComponentDescriptor { archetype: None, component: SERIES_COMPONENT.into(), component_type: None }));
            self.rec.log_serialized_batches(self.entities[e].path.as_str(), true, batches).map_err(|e| e.to_string())?;
            // Logged rows wait in Rerun's batcher while sent columns go straight through: the
            // readers need these statics before the entity's first rows.
            self.rec.flush_blocking().map_err(|e| format!("{}: cannot write: {e}", self.path.display()))?;
        }
        self.entities[e].instances = Some(instances);
        Ok(())
    }

    fn send(&mut self, i: usize) -> Result<(), String> {
        if self.groups[i].steps.is_empty() {
            return Ok(());
        }
        if self.blueprint.is_some() {
            self.freeze()?;
        }
        let rows = self.groups[i].steps.len();
        let g = &mut self.groups[i];
        // Fresh buffers of a whole batch: the per-step pushes never grow them again.
        let step_values = std::mem::replace(&mut g.steps, Vec::with_capacity(FLUSH_STEPS));
        let time_values = std::mem::replace(&mut g.times_ns, Vec::with_capacity(FLUSH_STEPS));
        let (step_values, time_values) = (ScalarBuffer::from(step_values), ScalarBuffer::from(time_values));
        let steps = TimeColumn::new(Some(true), Timeline::new_sequence("step"), step_values.clone());
        let times = TimeColumn::new(Some(true), Timeline::new_duration("sim_time"), time_values.clone());
        for e in self.groups[i].entities.clone() {
            if self.entities[e].instances.is_none() {
                // A group whose first row came after the first send: all its signals.
                let all = self.entities[e].series.clone();
                self.fix(e, all)?;
            }
            let Some(instances) = self.entities[e].instances.clone() else { continue };
            if instances.is_empty() {
                continue;
            }
            // Row-major: row r holds instance j at r·K + j.
            let mut values = Vec::with_capacity(rows * instances.len());
            for &s in &instances {
                let sig = &self.signals[s];
                if sig.values.len() != rows {
                    return Err(format!("{}: {} values for {rows} rows", sig.path, sig.values.len()));
                }
                self.digests.entry(sig.path.clone()).or_default().update(&step_values, Some(&time_values), &sig.values);
            }
            for r in 0..rows {
                values.extend(instances.iter().map(|&s| self.signals[s].values[r]));
            }
            for &s in &instances {
                self.signals[s].values.clear();
            }
            let lists = ListArray::new(self.inner.clone(), OffsetBuffer::<i32>::from_lengths(std::iter::repeat_n(instances.len(), rows)), Arc::new(Float64Array::from(values)), None);
            let column = ListArray::new(self.outer.clone(), OffsetBuffer::<i32>::from_lengths(std::iter::repeat_n(1, rows)), Arc::new(lists), None);
            let column = SerializedComponentColumn::new(column, ComponentDescriptor::partial(VALUES_COMPONENT));
            self.rec.send_columns(self.entities[e].path.as_str(), [steps.clone(), times.clone()], [column]).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// Sends what is left, the number of steps the run completed (a thinned or filtered
    /// recording cannot tell it), and the digest of everything sent; waits until it is on disk,
    /// and closes the file (writing its footer). Returns the digest, signal → 16 hex digits.
    pub fn finish(mut self, steps_completed: u64) -> Result<BTreeMap<String, String>, String> {
        for i in 0..self.groups.len() {
            self.send(i)?;
        }
        if self.blueprint.is_some() {
            self.freeze()?;
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
