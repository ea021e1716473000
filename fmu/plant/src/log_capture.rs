//! The FMU's own words: the `fmi` crate hands what an FMU logs (its logger callback) to the
//! `log` facade. The last warning or error is kept, so that a failed call is reported with the
//! reason the FMU gave.

use std::sync::Mutex;

static LAST: Mutex<String> = Mutex::new(String::new());

struct Capture;

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }

    fn log(&self, r: &log::Record) {
        if self.enabled(r.metadata())
            && let Ok(mut last) = LAST.lock()
        {
            *last = r.args().to_string().lines().next().unwrap_or("").trim().to_string();
        }
    }

    fn flush(&self) {}
}

/// Installs the capture (once).
pub fn install() {
    static CAPTURE: Capture = Capture;
    if log::set_logger(&CAPTURE).is_ok() {
        log::set_max_level(log::LevelFilter::Warn);
    }
}

/// Takes the last message the FMU logged, if any: ": <message>", ready to append.
pub fn take() -> String {
    let last = LAST.lock().map(|mut l| std::mem::take(&mut *l)).unwrap_or_default();
    if last.is_empty() { String::new() } else { format!(": {last}") }
}
