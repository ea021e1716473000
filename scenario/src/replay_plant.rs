//! `[plant.replay]`: recorded data as the true plant. A CSV log (its columns mapped by header
//! name to u, y and optionally w and x), an MCAP log (the fields of a JSON channel's messages
//! mapped the same way) or a run's own `.rrd` is replayed sample by sample by
//! the `uio-replay-plant` component (crate `replay`), which the launcher also asks to read the file
//! before a run. Here only what the scenario alone can tell is checked: the map's sizes against
//! `[plant]`, the options, and that the file exists. The data is open loop: it cannot react
//! to a controller, so a scenario with one is refused.

use std::path::Path;

use serde_json::json;

use super::plant_file::{self, Sizes};
use super::raw::{RawChannels, RawReplay};
use super::{ProcessSpec, quoted};
use crate::check::{Bad, bad};

/// The program that replays recorded data as the plant (a kit component built beside the launcher).
pub const REPLAY_PLANT_PROGRAM: &str = lockstep::programs::REPLAY_PLANT;

/// The replayed plant as the process that runs it, and the data file's absolute path.
/// `r` is the number of columns of D (the replayed v is zero: D v is in the recorded y).
/// `u_op`: the operating point's known inputs, the u of a log without input columns (else 0).
// one job: `[plant.replay]` validated field by field in the order the docs list them.
pub(crate) fn plant_replay(
    raw: &Option<RawReplay>,
    dir: Option<&Path>,
    z: &Sizes,
    r: usize,
    dt: f64,
    steps: u64,
    u_op: Option<&[f64]>,
) -> Result<Option<(std::path::PathBuf, ProcessSpec)>, Bad> {
    let Some(f) = raw else { return Ok(None) };
    let path = plant_file::path("plant.replay.path", dir, &f.path)?;
    let format = match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("csv") => "csv",
        Some("mcap") => "mcap",
        Some("rrd") => "rrd",
        _ => {
            return Err(bad(
                "plant.replay.path",
                format!("{}: a .csv or .mcap log or a run's .rrd", quoted(&f.path)),
            ));
        }
    };
    let channels = match &f.channel {
        None if format == "mcap" => {
            return Err(bad(
                "plant.replay.channel",
                "missing: the topic of the JSON channel whose messages are the samples",
            ));
        }
        None => Vec::new(),
        Some(_) if format != "mcap" => {
            return Err(bad("plant.replay.channel", "for an .mcap log only"));
        }
        Some(RawChannels::One(t)) => vec![t.clone()],
        Some(RawChannels::Many(ts)) => ts.clone(),
    };
    if channels.is_empty() && format == "mcap" {
        return Err(bad(
            "plant.replay.channel",
            "an empty list: at least one topic",
        ));
    }
    if let Some(i) = channels.iter().position(|t| t.is_empty()) {
        return Err(bad(
            format!("plant.replay.channel[{}]", i + 1),
            "a topic, not empty",
        ));
    }
    let choice = |key: &str, given: &Option<String>, allowed: [&str; 2]| -> Result<String, Bad> {
        match given.as_deref() {
            None => Ok(allowed[0].into()),
            Some(v) if v == allowed[1] => Ok(v.into()),
            Some(v) => Err(bad(
                format!("plant.replay.{key}"),
                format!("{}: the only choice is {}", quoted(v), quoted(allowed[1])),
            )),
        }
    };
    let resample = choice("resample", &f.resample, ["none", "zoh"])?;
    let missing = choice("missing", &f.missing, ["error", "hold"])?;
    let columns = [
        ("time", f.time.is_some()),
        ("inputs", f.inputs.is_some()),
        ("outputs", f.outputs.is_some()),
        ("disturbances", f.disturbances.is_some()),
        ("states", f.states.is_some()),
    ];
    if format == "rrd" {
        if let Some((key, _)) = columns.iter().find(|c| c.1) {
            return Err(bad(
                format!("plant.replay.{key}"),
                "a run's .rrd names its own signals: no column map",
            ));
        }
        if resample != "none" || missing != "error" {
            return Err(bad(
                "plant.replay",
                "a run's .rrd is on the run's grid: resample and missing are for CSV and MCAP logs",
            ));
        }
    }
    // A list of column names: `want` of them, or (when `optional`) none at all.
    let list = |key: &str,
                given: &Option<Vec<String>>,
                want: usize,
                what: &str,
                optional: bool|
     -> Result<Option<Vec<String>>, Bad> {
        let Some(names) = given else {
            return if optional || want == 0 || format == "rrd" {
                Ok(None)
            } else {
                Err(bad(
                    format!("plant.replay.{key}"),
                    format!(
                        "missing: {want} column name{} ({what})",
                        if want == 1 { "" } else { "s" }
                    ),
                ))
            };
        };
        if names.len() != want {
            return Err(bad(
                format!("plant.replay.{key}"),
                format!(
                    "{} name{} given; [plant] has {want} {what}",
                    names.len(),
                    if names.len() == 1 { "" } else { "s" }
                ),
            ));
        }
        if let Some(i) = names.iter().position(|s| s.trim().is_empty()) {
            return Err(bad(
                format!("plant.replay.{key}[{}]", i + 1),
                "a column name, not empty",
            ));
        }
        Ok(Some(names.clone()))
    };
    // Without input columns the inputs held still: u = u_op (or 0) throughout.
    let inputs = list(
        "inputs",
        &f.inputs,
        z.l,
        "known inputs (columns of B)",
        true,
    )?;
    let input_values = (inputs.is_none() && z.l > 0 && format != "rrd")
        .then(|| u_op.map_or_else(|| vec![0.0; z.l], <[f64]>::to_vec));
    let outputs = list("outputs", &f.outputs, z.p, "outputs (rows of C)", false)?;
    let disturbances = list(
        "disturbances",
        &f.disturbances,
        z.q,
        "unknown inputs (columns of E)",
        true,
    )?;
    let states = list("states", &f.states, z.n, "states", true)?;
    let params = json!({
        "path": path.display().to_string(),
        "format": format,
        "channels": channels,
        "time": f.time,
        "inputs": inputs.unwrap_or_default(),
        "input_values": input_values,
        "outputs": outputs.unwrap_or_default(),
        "disturbances": disturbances,
        "states": states,
        "resample": resample,
        "missing": missing,
        "dt": dt,
        "steps": steps,
        "n": z.n, "p": z.p, "l": z.l, "q": z.q, "r": r,
    });
    Ok(Some((
        path,
        ProcessSpec {
            command: vec![REPLAY_PLANT_PROGRAM.into()],
            params,
        },
    )))
}

/// Whether the replayed data carries the true state (a CSV with `states`, or an `.rrd`): without
/// it the plant sample's x is zero and the recorded errors are not errors.
pub fn replay_has_states(spec: &ProcessSpec) -> bool {
    spec.params.get("format").and_then(|f| f.as_str()) == Some("rrd")
        || spec.params.get("states").is_some_and(|s| !s.is_null())
}
