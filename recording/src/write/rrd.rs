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
//! buffered row-major and handed every [`FLUSH_STEPS`] steps (fewer for a group of more than
//! [`FLUSH_VALUES`] / [`FLUSH_STEPS`] values a row) to the recorder's own thread
//! ([`super::columns`]), which digests them and sends them with `send_columns`. Timelines: `step`
//! (sequence) and `sim_time` (seconds). What is sent is thinned and filtered by a
//! [`Selection`] and digested per signal ([`crate::digest`]); the digest is written when the
//! recording is closed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use rerun::blueprint::{Blueprint, BlueprintActivation};
use rerun::external::arrow::array::{ArrayRef, StringArray};
use rerun::{
    AsComponents as _, Color, ComponentDescriptor, RecordingStream, RecordingStreamBuilder,
    SerializedComponentBatch, SeriesLines, TextDocument,
};

use super::columns::{self, Batch, Columns};
use super::file_sink::UncompressedFileSink;
use super::layout::{LAYOUT, Layout, Line, SERIES_COMPONENT};
use super::select::Selection;
use crate::digest;
use crate::palette::Rgb;
use crate::signals;

/// Steps buffered before a group is sent.
pub const FLUSH_STEPS: usize = 4096;

/// Values buffered before a group is sent, whatever its steps (8 MB): a wide model's batch
/// (n = 1000 holds ≈ 10⁴ values a step) stays small, with the few that wait for the recorder's
/// thread.
pub const FLUSH_VALUES: usize = 1 << 20;

/// Makes the blueprint once the layout is known.
type MakeBlueprint = Box<dyn FnOnce(&Layout) -> Blueprint + Send>;

struct Group {
    /// Names the entities of this group whose component also has entities in an earlier group.
    label: String,
    steps: Vec<i64>,
    /// sim_time in nanoseconds (Rerun's duration unit).
    times_ns: Vec<i64>,
    entities: Vec<usize>,
    /// Values a row of the group holds (all its entities').
    width: usize,
    /// The current row is not recorded (thinned out): its values are dropped.
    skip: bool,
}

impl Group {
    /// Rows buffered before the group is sent: [`FLUSH_STEPS`], fewer for a wide group.
    fn batch(&self) -> usize {
        FLUSH_STEPS.min(FLUSH_VALUES / self.width.max(1)).max(1)
    }
}

struct Entity {
    path: String,
    group: usize,
    /// Its signals, in element order.
    series: Vec<usize>,
    /// The rows since the last send, row-major: row r holds signal j at r·K + j (K signals).
    /// A row starts as NaN, so a signal not set in a row reads as NaN.
    values: Vec<f64>,
    /// Its statics have been logged.
    announced: bool,
}

struct Signal {
    path: String,
    legend: String,
    color: Rgb,
    width: f32,
    group: usize,
    /// Selected: recorded.
    live: bool,
    /// Its entity and its element there.
    entity: usize,
    slot: usize,
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
    /// The file, for messages.
    path: PathBuf,
    /// The first write error of the file sink (which writes on Rerun's thread).
    error: Arc<Mutex<Option<String>>>,
    select: Selection,
    blueprint: Option<MakeBlueprint>,
    /// The thread that digests and sends the batches (from the first send).
    columns: Option<Columns>,
    /// The scenario text's digest.
    scenario_digest: String,
}

impl RrdSink {
    /// Opens `path` for writing, with the scenario text as a document and the layout version
    /// as a property; `blueprint` is made and sent when the layout is known (the first send).
    /// `select` says what is written, and whether compressed.
    pub fn create(
        path: &Path,
        name: &str,
        blueprint: impl FnOnce(&Layout) -> Blueprint + Send + 'static,
        scenario_toml: &str,
        select: Selection,
    ) -> Result<Self, String> {
        let sink = UncompressedFileSink::create_with(path, select.compress())?;
        let error = sink.error_slot();
        let rec = RecordingStreamBuilder::new("uio-observers")
            .recording_name(name)
            .buffered()
            .map_err(|e| format!("{}: cannot record: {e}", path.display()))?;
        rec.set_sink(Box::new(sink));
        rec.send_property("layout", &TextDocument::new(LAYOUT.to_string()))
            .map_err(|e| e.to_string())?;
        rec.send_property(
            "latency_unit",
            &TextDocument::new(super::LATENCY_UNIT.to_string()),
        )
        .map_err(|e| e.to_string())?;
        let scenario_text = format!("```toml\n{scenario_toml}\n```");
        let scenario_digest = digest::of_text(&scenario_text);
        rec.log_static("scenario", &TextDocument::from_markdown(scenario_text))
            .map_err(|e| e.to_string())?;
        Ok(RrdSink {
            rec,
            groups: Vec::new(),
            entities: Vec::new(),
            signals: Vec::new(),
            path: path.to_path_buf(),
            error,
            select,
            blueprint: Some(Box::new(blueprint)),
            columns: None,
            scenario_digest,
        })
    }

    /// A new group of signals sharing time stamps; returns its index. `label` names its
    /// entities where their component already has one in an earlier group
    /// (`/observer/uio/what` beside `/observer/uio`).
    pub fn group(&mut self, label: &str) -> usize {
        self.groups.push(Group {
            label: label.to_string(),
            steps: Vec::new(),
            times_ns: Vec::new(),
            entities: Vec::new(),
            width: 0,
            skip: false,
        });
        self.groups.len() - 1
    }

    /// Registers signal `path` in `group` with its legend name, colour and line width (points).
    /// Every signal is registered before the first row: an entity's rows hold them all.
    pub fn series(
        &mut self,
        group: usize,
        path: &str,
        legend: &str,
        color: Rgb,
        width: f32,
    ) -> SeriesId {
        let live = self.select.entity(path);
        let id = self.signals.len();
        let (mut entity, mut slot) = (usize::MAX, 0);
        if live {
            let owner = signals::entity_of(path);
            let labelled = format!("{owner}/{}", self.groups[group].label);
            entity = match self
                .entities
                .iter()
                .position(|e| e.group == group && (e.path == owner || e.path == labelled))
            {
                Some(e) => e,
                None => {
                    let taken = self.entities.iter().any(|e| e.path == owner);
                    self.entities.push(Entity {
                        path: if taken { labelled } else { owner },
                        group,
                        series: Vec::new(),
                        values: Vec::new(),
                        announced: false,
                    });
                    self.groups[group].entities.push(self.entities.len() - 1);
                    self.entities.len() - 1
                }
            };
            slot = self.entities[entity].series.len();
            self.entities[entity].series.push(id);
            self.groups[group].width += 1;
        }
        self.signals.push(Signal {
            path: path.to_string(),
            legend: legend.to_string(),
            color,
            width,
            group,
            live,
            entity,
            slot,
        });
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
            for &e in &g.entities {
                let e = &mut self.entities[e];
                e.values.resize(e.values.len() + e.series.len(), f64::NAN);
            }
        }
    }

    /// Sets a signal's value in its group's current row.
    #[inline]
    pub fn push(&mut self, id: SeriesId, v: f64) {
        let s = &self.signals[id.0];
        if s.live && !self.groups[s.group].skip {
            let e = &mut self.entities[s.entity];
            let at = e.values.len() - e.series.len() + s.slot;
            e.values[at] = v;
        }
    }

    /// Sends every group holding a batch ([`FLUSH_STEPS`] rows, or [`FLUSH_VALUES`] values);
    /// fails once the file could not be written (a full disk), naming it.
    pub fn flush_full(&mut self) -> Result<(), String> {
        let mut sent = false;
        for i in 0..self.groups.len() {
            if self.groups[i].steps.len() >= self.groups[i].batch() {
                self.send(i)?;
                sent = true;
            }
        }
        // The sink's error is looked at when something was written (a lock per step is not free).
        if sent { self.write_error() } else { Ok(()) }
    }

    /// The file sink's first write error, if any.
    fn write_error(&self) -> Result<(), String> {
        match self.error.lock().ok().and_then(|e| e.clone()) {
            Some(e) => Err(format!("{}: cannot write: {e}", self.path.display())),
            None => Ok(()),
        }
    }

    /// The layout (every entity and its signals), sent once as the blueprint.
    fn send_blueprint(&mut self) -> Result<(), String> {
        let Some(make) = self.blueprint.take() else {
            return Ok(());
        };
        let mut layout = Layout::default();
        for e in &self.entities {
            layout.entity(
                &e.path,
                e.series.iter().map(|&s| {
                    let sig = &self.signals[s];
                    (
                        sig.path.clone(),
                        Line {
                            legend: sig.legend.clone(),
                            color: sig.color,
                            width: sig.width,
                        },
                    )
                }),
            );
        }
        super::whole_run::send(
            &make(&layout),
            &self.rec,
            BlueprintActivation {
                make_active: true,
                make_default: true,
            },
        )
    }

    /// Logs entity `e`'s statics: the signal behind each element, and its line.
    fn announce(&mut self, e: usize) -> Result<(), String> {
        let entity = &self.entities[e];
        let sig = |s: &usize| &self.signals[*s];
        let lines = SeriesLines::new()
            .with_names(entity.series.iter().map(|s| sig(s).legend.clone()))
            .with_colors(
                entity
                    .series
                    .iter()
                    .map(|s| Color::from_rgb(sig(s).color[0], sig(s).color[1], sig(s).color[2])),
            )
            .with_widths(entity.series.iter().map(|s| sig(s).width));
        let names: ArrayRef = Arc::new(StringArray::from_iter_values(
            entity.series.iter().map(|s| sig(s).path.as_str()),
        ));
        let mut batches = lines.as_serialized_batches();
        batches.push(SerializedComponentBatch::new(
            names,
            ComponentDescriptor {
                archetype: None,
                component: SERIES_COMPONENT.into(),
                component_type: None,
            },
        ));
        self.rec
            .log_serialized_batches(entity.path.as_str(), true, batches)
            .map_err(|e| e.to_string())?;
        self.entities[e].announced = true;
        Ok(())
    }

    fn send(&mut self, i: usize) -> Result<(), String> {
        if self.groups[i].steps.is_empty() {
            return Ok(());
        }
        self.send_blueprint()?;
        let fresh: Vec<usize> = self.groups[i]
            .entities
            .iter()
            .copied()
            .filter(|&e| !self.entities[e].announced)
            .collect();
        for &e in &fresh {
            self.announce(e)?;
        }
        if !fresh.is_empty() {
            // Logged rows wait in Rerun's batcher while sent columns go straight through: the
            // readers need these statics before the entity's first rows.
            self.rec
                .flush_blocking()
                .map_err(|e| format!("{}: cannot write: {e}", self.path.display()))?;
        }
        if self.columns.is_none() {
            let entities = self
                .entities
                .iter()
                .map(|e| columns::Entity {
                    path: e.path.clone(),
                    signals: e
                        .series
                        .iter()
                        .map(|&s| self.signals[s].path.clone())
                        .collect(),
                })
                .collect();
            self.columns = Some(Columns::start(self.rec.clone(), entities)?);
        }
        let g = &mut self.groups[i];
        let rows = g.batch();
        // Fresh buffers of a whole batch: the per-step pushes never grow them again.
        let batch = Batch {
            steps: std::mem::replace(&mut g.steps, Vec::with_capacity(rows)),
            times_ns: std::mem::replace(&mut g.times_ns, Vec::with_capacity(rows)),
            values: g
                .entities
                .iter()
                .map(|&e| {
                    let e_ = &mut self.entities[e];
                    (
                        e,
                        std::mem::replace(
                            &mut e_.values,
                            Vec::with_capacity(rows * e_.series.len()),
                        ),
                    )
                })
                .collect(),
        };
        self.columns.as_mut().expect("started above").send(batch)
    }

    /// Sends what is left, the number of steps the run completed (a thinned or filtered
    /// recording cannot tell it), and the digest of everything sent; waits until it is on disk,
    /// and closes the file (writing its footer). Returns the digest, signal → 16 hex digits.
    pub fn finish(mut self, steps_completed: u64) -> Result<BTreeMap<String, String>, String> {
        for i in 0..self.groups.len() {
            self.send(i)?;
        }
        self.send_blueprint()?;
        let written = match self.columns.take() {
            Some(mut c) => c.finish()?,
            None => BTreeMap::new(),
        };
        self.rec
            .send_property("steps", &TextDocument::new(steps_completed.to_string()))
            .map_err(|e| e.to_string())?;
        let mut digests: BTreeMap<String, String> =
            written.iter().map(|(k, d)| (k.clone(), d.hex())).collect();
        digests.insert(digest::SCENARIO_KEY.into(), self.scenario_digest.clone());
        self.rec
            .send_property("digest", &TextDocument::new(digest::to_json(&digests)))
            .map_err(|e| e.to_string())?;
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
