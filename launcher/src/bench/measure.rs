//! One benchmark run: a scenario run quietly (no progress bar, no pacing) into a scratch folder,
//! its outcome kept; a run that stops early is an error.

use std::path::Path;

use lockstep::Wait;
use scenario::Scenario;

use crate::error::LaunchError;
use crate::run::{Mode, Options, Stop, run};

/// One benchmark run of `s` (outputs overwritten in `tmp`, no progress bar, no pacing); a run
/// that stops early is an error.
pub fn measure(
    s: &Scenario,
    p: &crate::plan::Plan,
    tmp: &Path,
    mode: Mode,
    wait: Wait,
    record: bool,
    pin: bool,
) -> Result<crate::run::Outcome, LaunchError> {
    let opts = Options {
        pin,
        ..Options::quiet(tmp, mode, wait, record)
    };
    let o = run(s, p, &opts)?;
    if o.stop != Stop::Completed {
        return Err(LaunchError::Component(format!(
            "{}: benchmark run stopped: {:?}",
            s.name, o.stop
        )));
    }
    Ok(o)
}
