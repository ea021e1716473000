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
use rerun::{Scalars, TextDocument};

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
