//! Small helpers shared by the commands that read recordings.

use crate::read::Recording;
use scenario::Scenario;

/// The scenario text stored in a recording.
pub fn recorded_text(r: &Recording) -> Option<&str> {
    let text = r.scenario.as_ref()?;
    Some(
        text.trim()
            .strip_prefix("```toml")?
            .strip_suffix("```")?
            .trim_start_matches('\n'),
    )
}

/// The scenario stored in a recording, parsed, if it is there and still valid (a scenario whose
/// matrices are `.npy` files beside it is not: the recording holds its text only).
pub fn recorded_scenario(r: &Recording) -> Option<Scenario> {
    Scenario::parse_recorded(recorded_text(r)?).ok()
}

/// The sample period of a recording: its scenario's `dt`, read alone when the whole scenario
/// cannot be parsed again.
pub fn recorded_dt(r: &Recording) -> Option<f64> {
    recorded_scenario(r).map(|s| s.dt).or_else(|| {
        recorded_text(r)?
            .parse::<toml::Table>()
            .ok()?
            .get("dt")?
            .as_float()
    })
}
