//! Reading a `.rrd` back: every scalar series by its signal's path, with its steps, decoded with
//! Rerun's own decoder from frames this module reads and bounds itself ([`frames`]). Layout 2
//! (the recording's property `layout`, [`crate::write::LAYOUT`]) stores a component's signals
//! as the instances of one entity, named by its static [`crate::write::SERIES_COMPONENT`];
//! layout 1 (no property) stored each signal as an entity of its own. Both read alike; a newer
//! layout is refused by its number. A file
//! whose writer was killed (no footer, or a truncated last message) is read as far as it goes
//! and marked incomplete. A finished file (one that ends with a stream footer) is checked
//! against the digest its writer stored ([`crate::digest`]): data that does not match, a frame
//! or footer that is wrong, or data that cannot be decoded, makes it [`Integrity::Damaged`].

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use re_log_encoding::{
    CachingApplicationIdInjector, CrateVersion, MessageKind, ToApplication as _,
};
use rerun::external::re_log_types::LogMsg;
use rerun::log::Chunk;
use rerun::{Scalars, SeriesLines, TextDocument};

use crate::digest::{self, Integrity, Rows};
use frames::{Fault, Frames, Message};

mod frames;
mod payload;
mod unwind;

/// One scalar time series.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Step of each value, ascending.
    pub steps: Vec<i64>,
    /// The values.
    pub values: Vec<f64>,
}

/// A decoded recording.
#[derive(Debug, Clone, Default)]
pub struct Recording {
    /// Entity path → series.
    pub series: BTreeMap<String, Series>,
    /// The scenario text stored in the recording, if any.
    pub scenario: Option<String>,
    /// Legend name of each series (e.g. "plant->observer/uio" for a hop), where recorded.
    pub names: BTreeMap<String, String>,
    /// False when the file ends without the footer a finished writer leaves.
    pub complete: bool,
    /// What went wrong while reading a damaged tail.
    pub problem: Option<String>,
    /// Whether the data matches the digest written with it.
    pub integrity: Integrity,
    /// How many steps the run completed, as its writer stored it when it closed the file (none
    /// for a killed writer's file).
    pub steps_completed: Option<u64>,
    /// The `latency_unit` property: "µs" ([`crate::write::LATENCY_UNIT`]); none in recordings
    /// written before it, whose latencies are ns.
    pub latency_unit: Option<String>,
}

impl Recording {
    /// The unit of the recorded `/latency/…` values, as a label writes it: µs, or the ns of
    /// files written before the property.
    pub fn latency_label_unit(&self) -> &str {
        match self.latency_unit.as_deref() {
            Some("µs") => "µs",
            _ => "ns",
        }
    }

    /// Nanoseconds per recorded `/latency/…` value: 1000 for µs, 1 for ns.
    pub fn latency_ns_per_value(&self) -> f64 {
        match self.latency_label_unit() {
            "µs" => 1000.0,
            _ => 1.0,
        }
    }
}

/// Why a file could not be read at all.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {reason}")]
pub struct ReadError {
    /// The file.
    pub path: String,
    /// Why.
    pub reason: String,
}

/// Decodes `path`, which must be a regular file (a FIFO would block the read). Nothing is
/// allocated beyond what the file holds ([`frames`], [`payload`]) and a panic inside Rerun's
/// decoder is caught ([`unwind`]): any damage gives [`Integrity::Damaged`] for a file its
/// writer finished, or an incomplete recording of what was read for one it did not.
// one job: one .rrd decoded end to end, its bounds checked where its bytes come, and one verdict on
// its integrity.
pub fn read(path: &Path) -> Result<Recording, ReadError> {
    let err = |reason: String| ReadError {
        path: path.display().to_string(),
        reason,
    };
    let (mut file, len) = scenario::untrusted::open_regular(path).map_err(err)?;
    let tail_footer = has_stream_footer(&mut file, len);
    let mut frames = Frames::new(BufReader::new(file), len);
    let mut injector = CachingApplicationIdInjector::default();
    let mut rec = Recording::default();
    let mut stored_digest = None;
    // Layout 2: entity → the signal behind each instance.
    let mut instances: BTreeMap<String, Vec<String>> = BTreeMap::new();
    // The digest of what is read, per entity, in file order (the order it was written in).
    let mut read_digests: BTreeMap<String, digest::Running> = BTreeMap::new();
    // Where reading stopped before the end: a cut (a killed writer) or damage.
    let mut fault = None;
    loop {
        let msg = match frames.next_message() {
            Ok(Some(m)) => m,
            Ok(None) => break,
            Err(f) => {
                fault = Some(f);
                break;
            }
        };
        let item = match unwind::quietly(|| decode(&msg, frames.version(), &mut injector)) {
            Ok(Ok(item)) => item,
            Ok(Err(e)) => {
                fault = Some(Fault::Bad(format!(
                    "the message at byte {} cannot be decoded: {e}",
                    msg.at
                )));
                break;
            }
            Err(panic) => {
                fault = Some(Fault::Bad(format!(
                    "the message at byte {} cannot be decoded (the decoder failed: {panic})",
                    msg.at
                )));
                break;
            }
        };
        match item {
            Some(Item::Static {
                path,
                text,
                legends,
                signals,
            }) => {
                if let Some(s) = text {
                    if path.starts_with("/__properties") && path.ends_with("/digest") {
                        stored_digest = Some(s);
                    } else if path.starts_with("/__properties") && path.ends_with("/steps") {
                        rec.steps_completed = s.trim().parse().ok();
                    } else if path.starts_with("/__properties") && path.ends_with("/latency_unit") {
                        rec.latency_unit = Some(s.trim().to_string());
                    } else if path.starts_with("/__properties") && path.ends_with("/layout") {
                        match s.trim().parse::<u32>() {
                            Ok(v) if (1..=crate::write::LAYOUT).contains(&v) => {}
                            Ok(v) => {
                                return Err(err(format!(
                                    "recording layout {v} is newer than this reader reads (1 to {}): read it with the version of uio-observers that wrote it",
                                    crate::write::LAYOUT
                                )));
                            }
                            // Not a number: the bytes were damaged.
                            Err(_) => {
                                fault = Some(Fault::Bad(format!(
                                    "its layout property '{}' is not a layout number",
                                    shown(&s)
                                )));
                                break;
                            }
                        }
                    } else {
                        rec.scenario = Some(s);
                    }
                }
                let names = if signals.is_empty() {
                    vec![path.clone()]
                } else {
                    signals.clone()
                };
                for (signal, legend) in names.iter().zip(legends) {
                    rec.names.insert(signal.clone(), legend);
                }
                if !signals.is_empty() {
                    instances.insert(path, signals);
                }
            }
            Some(Item::Rows {
                path,
                steps,
                times,
                values,
                width,
            }) => {
                let lone = [path.clone()];
                let signals = instances.get(&path).map_or(&lone[..], |v| &v[..]);
                let mut digest_rows = Rows::new(&steps, times.as_deref());
                for (i, signal) in signals.iter().enumerate().take(width) {
                    let column: Vec<f64> = values.iter().skip(i).step_by(width).copied().collect();
                    read_digests
                        .entry(signal.clone())
                        .or_default()
                        .update_rows(&mut digest_rows, column.iter().copied());
                    let series = rec.series.entry(signal.clone()).or_default();
                    series.steps.extend_from_slice(&steps);
                    series.values.extend(column);
                }
            }
            None => {}
        }
    }
    // A file whose writer finished ends with the stream footer; a damaged footer (whole, but
    // wrong) after the RRD footer only a finishing writer writes counts as finished too.
    let finished = tail_footer || frames.closing() && matches!(fault, Some(Fault::Bad(_)));
    let problem = match fault {
        Some(Fault::NotRrd(e)) if !finished => {
            return Err(err(format!("not a Rerun recording: {e}")));
        }
        Some(Fault::NotRrd(e)) => Some(format!("its stream header is not Rerun's ({e})")),
        Some(Fault::Bad(what)) => Some(what),
        Some(Fault::Cut(what)) if finished => Some(what),
        // A killed writer's file: read as far as it goes, nothing wrong in it.
        Some(Fault::Cut(_)) => None,
        None if finished && !frames.footer_ok() => {
            Some("its stream footer is not where the stream ends".into())
        }
        None => None,
    }
    .map(|p| shown(&p));
    for s in rec.series.values_mut() {
        if s.steps.windows(2).any(|w| w[1] < w[0]) {
            let mut idx: Vec<usize> = (0..s.steps.len()).collect();
            idx.sort_by_key(|&i| s.steps[i]);
            s.steps = idx.iter().map(|&i| s.steps[i]).collect();
            s.values = idx.iter().map(|&i| s.values[i]).collect();
        }
    }
    rec.integrity = match (&problem, &stored_digest) {
        // A finished writer's file decodes to its end: anything else is damage.
        (Some(what), _) if finished => {
            Integrity::Damaged(format!("its writer finished it, but {what}"))
        }
        (Some(_), _) | (None, None) => Integrity::Absent,
        (None, Some(d)) => digest::verify(&read_digests, rec.scenario.as_deref(), d),
    };
    rec.complete = problem.is_none() && frames.footer_ok();
    rec.problem = match &rec.integrity {
        Integrity::Absent => problem.map(|p| format!("damaged after the last whole message: {p}")),
        _ => None,
    };
    Ok(rec)
}

/// Untrusted text from a decoder's error, on one line and at most 300 characters.
fn shown(text: &str) -> String {
    let line = scenario::untrusted::one_line(text);
    match line.char_indices().nth(300) {
        Some((cut, _)) => format!("{}…", &line[..cut]),
        None => line,
    }
}

/// What one message adds to the recording.
enum Item {
    /// A static chunk: a property or the scenario text, and an entity's legends and (layout 2)
    /// the signal behind each instance.
    Static {
        path: String,
        text: Option<String>,
        legends: Vec<String>,
        signals: Vec<String>,
    },
    /// Rows of one entity: steps, sim_time in ns where recorded, and `width` values a row
    /// (row-major; a short row is padded with NaN).
    Rows {
        path: String,
        steps: Vec<i64>,
        times: Option<Vec<i64>>,
        values: Vec<f64>,
        width: usize,
    },
}

/// Decodes one message, its lengths checked first; None for what is not a recording's chunk.
fn decode(
    msg: &Message,
    version: Option<CrateVersion>,
    injector: &mut CachingApplicationIdInjector,
) -> Result<Option<Item>, String> {
    use re_log_encoding::Decodable as _;
    use re_protos::log_msg::v1alpha1 as proto;
    let e = |e: re_log_encoding::CodecError| e.to_string();
    let transport = match msg.kind {
        MessageKind::ArrowMsg => {
            let arrow = proto::ArrowMsg::from_rrd_bytes(&msg.payload).map_err(e)?;
            payload::check(&arrow)?;
            proto::log_msg::Msg::ArrowMsg(arrow)
        }
        MessageKind::SetStoreInfo => proto::log_msg::Msg::SetStoreInfo(
            proto::SetStoreInfo::from_rrd_bytes(&msg.payload).map_err(e)?,
        ),
        MessageKind::BlueprintActivationCommand => proto::log_msg::Msg::BlueprintActivationCommand(
            proto::BlueprintActivationCommand::from_rrd_bytes(&msg.payload).map_err(e)?,
        ),
        MessageKind::End => return Ok(None),
    };
    let LogMsg::ArrowMsg(store, arrow) =
        transport.to_application((injector, version)).map_err(e)?
    else {
        return Ok(None);
    };
    if !store.is_recording() {
        return Ok(None);
    }
    let chunk = Chunk::from_arrow_msg(&arrow).map_err(|e| format!("bad chunk: {e}"))?;
    let path = chunk.entity_path().to_string();
    if chunk.is_static() {
        let all = |c| {
            chunk
                .iter_slices::<String>(c)
                .next()
                .map(|v| v.into_iter().map(|s| s.to_string()).collect::<Vec<_>>())
                .unwrap_or_default()
        };
        let text = all(TextDocument::descriptor_text().component)
            .into_iter()
            .next();
        return Ok(Some(Item::Static {
            path,
            text,
            legends: all(SeriesLines::descriptor_names().component),
            signals: all(crate::write::SERIES_COMPONENT.into()),
        }));
    }
    let timeline = |name: &str| {
        chunk
            .timelines()
            .iter()
            .find(|(n, _)| n.as_str() == name)
            .map(|(_, c)| c.times_raw().to_vec())
    };
    let Some(mut steps) = timeline("step") else {
        return Ok(None);
    };
    let rows: Vec<&[f64]> = match chunk
        .components()
        .get_array(crate::write::VALUES_COMPONENT.into())
    {
        // Layout 2: a list of doubles in each row.
        Some(outer) => lists(outer)?,
        // Layout 1: one scalar in each row.
        None => chunk
            .iter_slices::<f64>(Scalars::descriptor_scalars().component)
            .collect(),
    };
    if rows.is_empty() {
        return Ok(None);
    }
    let n = rows.len().min(steps.len());
    steps.truncate(n);
    let width = rows.iter().map(|r| r.len()).max().unwrap_or(0).max(1);
    let mut values = Vec::with_capacity(n * width);
    for r in &rows[..n] {
        values.extend_from_slice(r);
        values.extend(std::iter::repeat_n(f64::NAN, width - r.len()));
    }
    Ok(Some(Item::Rows {
        path,
        steps,
        times: timeline("sim_time"),
        values,
        width,
    }))
}

/// Each row's list of doubles in a column of layout 2 (its first instance; a row without one is
/// empty).
fn lists(outer: &rerun::external::arrow::array::ListArray) -> Result<Vec<&[f64]>, String> {
    use rerun::external::arrow::array::{Array as _, Float64Array, ListArray};
    let inner = outer
        .values()
        .as_any()
        .downcast_ref::<ListArray>()
        .ok_or("its values are not lists of lists")?;
    let doubles = inner
        .values()
        .as_any()
        .downcast_ref::<Float64Array>()
        .ok_or("its values are not doubles")?
        .values();
    let (outer_at, inner_at) = (outer.value_offsets(), inner.value_offsets());
    let mut rows = Vec::with_capacity(outer.len());
    for r in 0..outer.len() {
        let (a, b) = (outer_at[r] as usize, outer_at[r + 1] as usize);
        if a >= b || a >= inner.len() {
            rows.push(&doubles[..0]);
            continue;
        }
        let (from, to) = (inner_at[a] as usize, inner_at[a + 1] as usize);
        rows.push(
            doubles
                .get(from..to)
                .ok_or("a row's values lie beyond its column")?,
        );
    }
    Ok(rows)
}

/// Whether the file ends with the stream footer (`RRF2FOOT` and an entry count) that only a
/// finished writer leaves.
fn has_stream_footer(file: &mut File, len: u64) -> bool {
    let mut tail = [0u8; 12];
    let ok = len >= 12
        && file.seek(SeekFrom::Start(len - 12)).is_ok()
        && file.read_exact(&mut tail).is_ok();
    let _ = file.seek(SeekFrom::Start(0));
    ok && &tail[..8] == b"RRF2FOOT"
}

/// Writes series to a new `.rrd` (timeline `step` only) with their digest, e.g. to make a test
/// recording; a file already at `path` is replaced (a link there removed, not followed).
pub fn write(path: &Path, rec: &Recording) -> Result<(), String> {
    use rerun::TimeColumn;
    use rerun::time::Timeline;
    if std::fs::symlink_metadata(path).is_ok() {
        std::fs::remove_file(path)
            .map_err(|e| format!("{}: cannot replace: {e}", path.display()))?;
    }
    let sink = crate::write::UncompressedFileSink::create(path)?;
    let stream = rerun::RecordingStreamBuilder::new("uio-observers")
        .buffered()
        .map_err(|e| e.to_string())?;
    stream.set_sink(Box::new(sink));
    let mut digests = BTreeMap::new();
    for (entity, series) in &rec.series {
        let steps = TimeColumn::new(
            Some(true),
            Timeline::new_sequence("step"),
            series.steps.clone().into(),
        );
        let columns = Scalars::new(series.values.iter().copied())
            .columns_of_unit_batches()
            .map_err(|e| e.to_string())?;
        stream
            .send_columns(entity.as_str(), [steps], columns)
            .map_err(|e| e.to_string())?;
        let mut d = digest::Running::default();
        d.update(&series.steps, None, &series.values);
        digests.insert(entity.clone(), d.hex());
    }
    stream
        .send_property("digest", &TextDocument::new(digest::to_json(&digests)))
        .map_err(|e| e.to_string())?;
    stream.flush_blocking().map_err(|e| e.to_string())?;
    drop(stream);
    Ok(())
}
