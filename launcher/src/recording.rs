//! Reading a `.rrd` back: every scalar series by entity path, with its steps, decoded with
//! Rerun's own decoder. A file whose writer was killed (no footer, or a truncated last message)
//! is read as far as it goes and marked incomplete.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use re_log_encoding::DecoderApp;
use rerun::external::re_log_types::LogMsg;
use rerun::log::Chunk;
use rerun::{Scalars, SeriesLines, TextDocument};

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

/// Decodes `path`.
pub fn read(path: &Path) -> Result<Recording, ReadError> {
    let err = |reason: String| ReadError { path: path.display().to_string(), reason };
    let file = File::open(path).map_err(|e| err(format!("cannot open: {e}")))?;
    let len = file.metadata().map(|m| m.len()).unwrap_or(0);
    let mut messages = DecoderApp::decode_lazy(BufReader::new(file));
    let mut rec = Recording::default();
    let scalars = Scalars::descriptor_scalars().component;
    let text = TextDocument::descriptor_text().component;
    let legend = SeriesLines::descriptor_names().component;
    let mut seen_any = false;
    for msg in messages.by_ref() {
        let msg = match msg {
            Ok(m) => m,
            Err(e) => {
                if !seen_any {
                    return Err(err(format!("not a Rerun recording: {e}")));
                }
                rec.problem = Some(format!("damaged after the last whole message: {e}"));
                break;
            }
        };
        seen_any = true;
        let LogMsg::ArrowMsg(store, arrow) = msg else { continue };
        if !store.is_recording() {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow).map_err(|e| err(format!("bad chunk: {e}")))?;
        let path = chunk.entity_path().to_string();
        if chunk.is_static() {
            if let Some(s) = chunk.iter_slices::<String>(text).next().and_then(|v| v.into_iter().next()) {
                rec.scenario = Some(s.to_string());
            }
            if let Some(n) = chunk.iter_slices::<String>(legend).next().and_then(|v| v.into_iter().next()) {
                rec.names.insert(path, n.to_string());
            }
            continue;
        }
        let Some(steps) = chunk.timelines().iter().find(|(name, _)| name.as_str() == "step").map(|(_, c)| c.times_raw().to_vec()) else {
            continue;
        };
        let values: Vec<f64> = chunk.iter_slices::<f64>(scalars).map(|s| s.first().copied().unwrap_or(f64::NAN)).collect();
        if values.is_empty() {
            continue;
        }
        let series = rec.series.entry(path).or_default();
        series.steps.extend_from_slice(&steps[..values.len().min(steps.len())]);
        series.values.extend_from_slice(&values[..values.len().min(steps.len())]);
    }
    if !seen_any && len > 0 {
        return Err(err("not a Rerun recording".into()));
    }
    rec.complete = rec.problem.is_none() && messages.rrd_manifests().map(|m| !m.is_empty()).unwrap_or(false);
    for s in rec.series.values_mut() {
        if s.steps.windows(2).any(|w| w[1] < w[0]) {
            let mut idx: Vec<usize> = (0..s.steps.len()).collect();
            idx.sort_by_key(|&i| s.steps[i]);
            s.steps = idx.iter().map(|&i| s.steps[i]).collect();
            s.values = idx.iter().map(|&i| s.values[i]).collect();
        }
    }
    Ok(rec)
}

/// Writes series to a new `.rrd` (timeline `step` only), e.g. to make a test recording.
pub fn write(path: &Path, rec: &Recording) -> Result<(), String> {
    use rerun::time::Timeline;
    use rerun::TimeColumn;
    let sink = crate::record::UncompressedFileSink::create(path)?;
    let stream = rerun::RecordingStreamBuilder::new("uio-observers").buffered().map_err(|e| e.to_string())?;
    stream.set_sink(Box::new(sink));
    for (entity, series) in &rec.series {
        let steps = TimeColumn::new(Some(true), Timeline::new_sequence("step"), series.steps.clone().into());
        let columns = Scalars::new(series.values.iter().copied()).columns_of_unit_batches().map_err(|e| e.to_string())?;
        stream.send_columns(entity.as_str(), [steps], columns).map_err(|e| e.to_string())?;
    }
    stream.flush_blocking().map_err(|e| e.to_string())?;
    drop(stream);
    Ok(())
}
