//! The FMU's own words: the `fmi` crate hands what an FMU logs (its logger callback) to the
//! `log` facade. Here every message is kept (the last [`KEPT`]), warnings and errors are also
//! written to stderr the moment they arrive — so that when the FMU's library kills the
//! process (a segfault inside an embedded interpreter), the launcher still quotes the FMU's
//! last words — and a failed call is reported with what the FMU logged since the last one.

use std::collections::VecDeque;
use std::sync::Mutex;

/// How many of the FMU's messages are kept for the next failure's report.
pub const KEPT: usize = 4;

static LAST: Mutex<VecDeque<String>> = Mutex::new(VecDeque::new());

struct Capture;

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata) -> bool {
        // The FMU's logger messages (fmi-sys logs them with module "logger"); OK-status ones
        // come as Info, a Discard in FMI 2.0 as Trace.
        m.level() <= log::Level::Trace
    }

    fn log(&self, r: &log::Record) {
        if r.module_path() != Some("logger") && r.level() > log::Level::Warn {
            return; // the fmi crate's own tracing
        }
        record(r.target(), r.level(), "", &r.args().to_string());
    }

    fn flush(&self) {}
}

/// Keeps one message of the FMU (instance `instance`); a warning or an error also goes to
/// stderr at once.
pub fn record(instance: &str, level: log::Level, category: &str, text: &str) {
    let line = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" / ");
    if line.is_empty() {
        return;
    }
    // The FMU's text, made one line that cannot forge another (a lone \r, an escape sequence,
    // a bidi control) and at most LINE_CHARS long: it reaches the launcher's messages.
    let line = one_line_capped(&line);
    let (instance, category) = (one_line_capped(instance), one_line_capped(category));
    let (instance, category) = (instance.as_str(), category.as_str());
    if level <= log::Level::Warn {
        let category = if category.is_empty() {
            String::new()
        } else {
            format!(", {category}")
        };
        eprintln!(
            "FMU {instance} ({}{category}): {line}",
            level.as_str().to_lowercase()
        );
    }
    if let Ok(mut last) = LAST.lock() {
        if last.len() == KEPT {
            last.pop_front();
        }
        last.push_back(line);
    }
}

/// Installs the capture (once).
pub fn install() {
    static CAPTURE: Capture = Capture;
    if log::set_logger(&CAPTURE).is_ok() {
        log::set_max_level(log::LevelFilter::Trace);
    }
}

/// Takes what the FMU logged since the last take, if anything: ": <m1> | <m2>", ready to
/// append.
pub fn take() -> String {
    let last: Vec<String> = LAST
        .lock()
        .map(|mut l| l.drain(..).collect())
        .unwrap_or_default();
    if last.is_empty() {
        String::new()
    } else {
        format!(": the FMU logged: {}", last.join(" | "))
    }
}

/// The longest FMU log line kept or shown, characters.
const LINE_CHARS: usize = 1000;

fn one_line_capped(text: &str) -> String {
    let count = text.chars().count();
    let shown: String = text.chars().take(LINE_CHARS).collect();
    let mut line = scenario::untrusted::one_line(&shown);
    if count > LINE_CHARS {
        line += &format!("… ({count} characters)");
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_fmus_log_text_cannot_forge_a_line_or_flood_the_message() {
        record(
            "inst\rfake",
            log::Level::Info,
            "",
            "ok\rerror: forged\x1b[2K\u{202e}x\nsecond line",
        );
        let got = take();
        assert!(!got.contains(['\r', '\n', '\x1b', '\u{202e}']), "{got:?}");
        assert!(
            got.contains("second line") && got.contains("forged"),
            "{got}"
        );
        record("i", log::Level::Info, "", &"y".repeat(5_000_000));
        let got = take();
        assert!(
            got.len() < 1100 && got.ends_with("(5000000 characters)"),
            "{}",
            got.len()
        );
    }
}
