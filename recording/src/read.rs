//! Reading a `.rrd` back: every scalar series by entity path, with its steps, decoded with
//! Rerun's own decoder. A file whose writer was killed (no footer, or a truncated last message)
//! is read as far as it goes and marked incomplete. A finished file is checked against the
//! digest its writer stored ([`crate::digest`]): data that does not match, or that cannot be
//! decoded although the file was finished, makes it [`Integrity::Damaged`].

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use re_log_encoding::DecoderApp;
use rerun::external::re_log_types::LogMsg;
use rerun::log::Chunk;
use rerun::{Scalars, SeriesLines, TextDocument};

use crate::digest::{self, Integrity};

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

/// Decodes `path`, which must be a regular file (a FIFO would block the read).
pub fn read(path: &Path) -> Result<Recording, ReadError> {
    let err = |reason: String| ReadError { path: path.display().to_string(), reason };
    let (mut file, len) = scenario::untrusted::open_regular(path).map_err(err)?;
    let finished = has_stream_footer(&mut file, len);
    let mut messages = DecoderApp::decode_lazy(BufReader::new(file));
    let mut rec = Recording::default();
    let scalars = Scalars::descriptor_scalars().component;
    let text = TextDocument::descriptor_text().component;
    let legend = SeriesLines::descriptor_names().component;
    let mut seen_any = false;
    let mut stored_digest = None;
    // The digest of what is read, per entity, in file order (the order it was written in).
    let mut read_digests: BTreeMap<String, digest::Running> = BTreeMap::new();
    // Data that cannot be decoded: the end of a killed writer's file, or damage in a finished one.
    let mut undecodable = None;
    while let Some(msg) = messages.next() {
        let msg = match msg {
            Ok(m) => m,
            Err(e) => {
                if !seen_any {
                    return Err(err(format!("not a Rerun recording: {e}")));
                }
                undecodable = Some(format!("undecodable after byte {}: {e}", messages.num_bytes_processed()));
                break;
            }
        };
        seen_any = true;
        let LogMsg::ArrowMsg(store, arrow) = msg else { continue };
        if !store.is_recording() {
            continue;
        }
        let chunk = match Chunk::from_arrow_msg(&arrow) {
            Ok(c) => c,
            Err(e) => {
                undecodable = Some(format!("bad chunk after byte {}: {e}", messages.num_bytes_processed()));
                break;
            }
        };
        let path = chunk.entity_path().to_string();
        if chunk.is_static() {
            if let Some(s) = chunk.iter_slices::<String>(text).next().and_then(|v| v.into_iter().next()) {
                if path.starts_with("/__properties") && path.ends_with("/digest") {
                    stored_digest = Some(s.to_string());
                } else if path.starts_with("/__properties") && path.ends_with("/steps") {
                    rec.steps_completed = s.trim().parse().ok();
                } else {
                    rec.scenario = Some(s.to_string());
                }
            }
            if let Some(n) = chunk.iter_slices::<String>(legend).next().and_then(|v| v.into_iter().next()) {
                rec.names.insert(path, n.to_string());
            }
            continue;
        }
        let timeline = |name: &str| chunk.timelines().iter().find(|(n, _)| n.as_str() == name).map(|(_, c)| c.times_raw().to_vec());
        let Some(steps) = timeline("step") else {
            continue;
        };
        let values: Vec<f64> = chunk.iter_slices::<f64>(scalars).map(|s| s.first().copied().unwrap_or(f64::NAN)).collect();
        if values.is_empty() {
            continue;
        }
        let rows = values.len().min(steps.len());
        read_digests.entry(path.clone()).or_default().update(&steps[..rows], timeline("sim_time").as_deref(), &values[..rows]);
        let series = rec.series.entry(path).or_default();
        series.steps.extend_from_slice(&steps[..values.len().min(steps.len())]);
        series.values.extend_from_slice(&values[..values.len().min(steps.len())]);
    }
    if !seen_any && len > 0 {
        return Err(err("not a Rerun recording".into()));
    }
    for s in rec.series.values_mut() {
        if s.steps.windows(2).any(|w| w[1] < w[0]) {
            let mut idx: Vec<usize> = (0..s.steps.len()).collect();
            idx.sort_by_key(|&i| s.steps[i]);
            s.steps = idx.iter().map(|&i| s.steps[i]).collect();
            s.values = idx.iter().map(|&i| s.values[i]).collect();
        }
    }
    rec.integrity = match (&undecodable, &stored_digest) {
        // A finished writer's file decodes to its end: anything else is damage.
        (Some(what), _) if finished => Integrity::Damaged(format!("its data cannot be decoded although its writer finished ({what})")),
        (Some(_), _) | (None, None) => Integrity::Absent,
        (None, Some(d)) => digest::verify(&read_digests, rec.scenario.as_deref(), d),
    };
    rec.problem = match (&undecodable, &rec.integrity) {
        (Some(what), Integrity::Absent) => Some(format!("damaged after the last whole message: {what}")),
        _ => None,
    };
    rec.complete = undecodable.is_none() && messages.rrd_manifests().map(|m| !m.is_empty()).unwrap_or(false);
    Ok(rec)
}

/// Whether the file ends with the stream footer (`RRF2FOOT` and an entry count) that only a
/// finished writer leaves.
fn has_stream_footer(file: &mut File, len: u64) -> bool {
    let mut tail = [0u8; 12];
    let ok = len >= 12 && file.seek(SeekFrom::Start(len - 12)).is_ok() && file.read_exact(&mut tail).is_ok();
    let _ = file.seek(SeekFrom::Start(0));
    ok && &tail[..8] == b"RRF2FOOT"
}

/// Writes series to a new `.rrd` (timeline `step` only) with their digest, e.g. to make a test
/// recording.
pub fn write(path: &Path, rec: &Recording) -> Result<(), String> {
    use rerun::time::Timeline;
    use rerun::TimeColumn;
    let sink = crate::write::UncompressedFileSink::create(path)?;
    let stream = rerun::RecordingStreamBuilder::new("uio-observers").buffered().map_err(|e| e.to_string())?;
    stream.set_sink(Box::new(sink));
    let mut digests = BTreeMap::new();
    for (entity, series) in &rec.series {
        let steps = TimeColumn::new(Some(true), Timeline::new_sequence("step"), series.steps.clone().into());
        let columns = Scalars::new(series.values.iter().copied()).columns_of_unit_batches().map_err(|e| e.to_string())?;
        stream.send_columns(entity.as_str(), [steps], columns).map_err(|e| e.to_string())?;
        let mut d = digest::Running::default();
        d.update(&series.steps, None, &series.values);
        digests.insert(entity.clone(), d.hex());
    }
    stream.send_property("digest", &TextDocument::new(digest::to_json(&digests))).map_err(|e| e.to_string())?;
    stream.flush_blocking().map_err(|e| e.to_string())?;
    drop(stream);
    Ok(())
}
