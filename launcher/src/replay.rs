//! `uio-launcher replay <run.rrd> [--scenario other.toml]`: observers on a run's recorded plant
//! samples. The scenario (the one recorded in the run, or another with the same plant sizes)
//! is rewritten with its plant replaced by `[plant.replay]` of the recording and without its
//! controller — recorded data cannot react to one, so a closed-loop run is replayed open loop
//! with its recorded u — and then run like any scenario. The rewritten text is what the
//! replay's recording stores, so a replay can itself be replayed.

use std::path::{Path, PathBuf};

use scenario::untrusted::{quoted, read_bounded};
use scenario::{MAX_SCENARIO_BYTES, Scenario};

use crate::error::LaunchError;

/// The scenario a replay of `rrd` runs: `other`'s, or else the one the run recorded.
pub fn scenario(rrd: &Path, other: Option<&Path>) -> Result<Scenario, LaunchError> {
    let data = std::fs::canonicalize(rrd)
        .map_err(|e| LaunchError::BadInput(format!("{}: {e}", rrd.display())))?;
    let (path, text) = match other {
        Some(o) => (
            o.to_path_buf(),
            read_bounded(o, MAX_SCENARIO_BYTES)
                .map_err(|e| LaunchError::BadInput(format!("{}: {e}", o.display())))?,
        ),
        None => {
            let rec = recording::read(&data).map_err(|e| LaunchError::BadInput(e.to_string()))?;
            if let recording::Integrity::Damaged(why) = &rec.integrity {
                return Err(LaunchError::Damaged(format!(
                    "{}: damaged: {why}",
                    rrd.display()
                )));
            }
            let text = recording::tools::recorded_text(&rec).ok_or_else(|| {
                LaunchError::BadInput(format!(
                    "{}: holds no scenario text to replay (give one with --scenario)",
                    rrd.display()
                ))
            })?;
            (data.clone(), text.to_string())
        }
    };
    let text = replayed(&path, &text, &data)?;
    Ok(Scenario::parse(&path, &text)?)
}

/// `text` with `[plant.replay] path = <data>` in place of its plant's process, FMU or replay,
/// its plant's host and its `[controller]`.
fn replayed(path: &Path, text: &str, data: &Path) -> Result<String, LaunchError> {
    let bad = |why: String| LaunchError::BadInput(format!("{}: {why}", path.display()));
    let mut t: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| bad(e.message().to_string()))?;
    let plant = t
        .get_mut("plant")
        .and_then(|p| p.as_table_mut())
        .ok_or_else(|| bad("no [plant] table".into()))?;
    for key in ["process", "fmu", "replay", "host"] {
        plant.remove(key);
    }
    let mut replay = toml::Table::new();
    replay.insert("path".into(), data.display().to_string().into());
    plant.insert("replay".into(), replay.into());
    t.remove("controller");
    toml::to_string(&t).map_err(|e| bad(format!("cannot write the replayed scenario: {e}")))
}

/// The replay's recording must not be the recording it replays (`--out` its folder, same name).
pub fn refuse_overwrite(rrd: &Path, out: &Path, name: &str) -> Result<(), LaunchError> {
    let target: PathBuf = out.join(format!("{name}.rrd"));
    if let (Ok(a), Ok(b)) = (std::fs::canonicalize(rrd), std::fs::canonicalize(&target))
        && a == b
    {
        return Err(LaunchError::BadInput(format!(
            "{}: the replay would overwrite the recording it replays; give another --out",
            quoted(&target.display().to_string())
        )));
    }
    Ok(())
}
