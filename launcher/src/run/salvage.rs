//! What is kept of a recording that could not be written whole (a full disk): the partial
//! file stays as `<name>.rrd.partial` when it can be read (the recording tools read it and say
//! it is incomplete), and is removed when it cannot; the message names the file and says which.

use std::path::Path;

use crate::error::LaunchError;

/// The error of a run whose recording failed after `steps` steps with `error`.
pub fn recording_failed(
    name: &str,
    partial: Option<&Path>,
    error: &str,
    steps: u64,
) -> LaunchError {
    let kept = match partial {
        Some(p) => match recording::read(p).ok().and_then(|r| {
            r.series
                .values()
                .filter_map(|s| s.steps.last().copied())
                .max()
        }) {
            Some(last) => format!(
                "the partial recording was kept as {} (readable up to step {last}, without footer)",
                p.display()
            ),
            None => {
                let _ = std::fs::remove_file(p);
                format!(
                    "the partial recording {} held no readable step and was removed",
                    p.display()
                )
            }
        },
        None => "nothing was recorded".into(),
    };
    LaunchError::Component(format!(
        "{name}: the recording failed after {steps} steps: {error}; {kept}; the components were stopped and no summary was written"
    ))
}
