//! Small helpers shared by the commands that read recordings.

use crate::read::Recording;
use scenario::Scenario;

/// The scenario stored in a recording, parsed, if it is there and still valid.
pub fn recorded_scenario(r: &Recording) -> Option<Scenario> {
    let text = r.scenario.as_ref()?;
    let toml = text.trim().strip_prefix("```toml")?.strip_suffix("```")?;
    Scenario::parse(std::path::Path::new("<recording>"), toml.trim_start_matches('\n')).ok()
}

/// The sample period of a recording (from its scenario).
pub fn recorded_dt(r: &Recording) -> Option<f64> {
    recorded_scenario(r).map(|s| s.dt)
}
