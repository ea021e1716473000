//! `glr = { window, false_alarm }` of a `[[diagnoser]]`: a windowed GLR test beside the
//! evaluation (`diagnosis::glr`).

use diagnosis::GlrSpec;

use super::limits::MAX_GLR_WINDOW;
use super::raw::RawGlr;
use crate::check::{self, Bad, bad, finite};

/// The GLR test of the `i`-th (0-based) diagnoser, if it asks for one.
pub(crate) fn glr(
    i: usize,
    raw: Option<&RawGlr>,
    noise: bool,
    dt: f64,
) -> Result<Option<GlrSpec>, Bad> {
    let Some(raw) = raw else {
        return Ok(None);
    };
    let at = |key: &str| format!("diagnoser[{}].glr.{key}", i + 1);
    let window = finite(&at("window"), raw.window)?;
    if window < dt {
        return Err(bad(
            at("window"),
            format!("{window} s must be at least one sample (dt = {dt} s)"),
        ));
    }
    if window / dt > MAX_GLR_WINDOW {
        return Err(bad(
            at("window"),
            format!(
                "{window} s is {:.0} samples: at most {MAX_GLR_WINDOW} (every onset in the window is tried at every step)",
                window / dt
            ),
        ));
    }
    let false_alarm = check::false_alarm(&at("false_alarm"), raw.false_alarm)?;
    if !noise {
        return Err(bad(
            format!("diagnoser[{}].glr", i + 1),
            "a GLR test whitens the residual by its noise: the scenario has no [noise]",
        ));
    }
    Ok(Some(GlrSpec {
        window,
        false_alarm,
    }))
}
