//! Untrusted input: text that came from a file or a command line is quoted and escaped before
//! it is echoed (a name holding a newline or a terminal escape sequence must not rewrite the
//! user's terminal or forge a second message line), and files are opened only if they are
//! regular files (a FIFO would block the read forever) of a bounded size (a huge file would
//! exhaust memory before the parser could refuse it).

use std::fs::File;
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::Path;

/// Largest scenario file read, bytes (1 MiB; the shipped ones are a few kB).
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;

/// Longest untrusted text quoted whole in a message, in characters; longer text is cut.
const QUOTE_CHARS: usize = 80;

/// Longest list of untrusted names shown in a message, in characters (a 20 MiB
/// header made a 99 MB message line).
const LIST_CHARS: usize = 300;

/// `'a', 'b', …` — each name [`quoted`], the list cut after [`LIST_CHARS`] characters with how
/// many more there are; "none" for an empty list.
pub fn quoted_list<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    let mut out = String::new();
    let mut more = 0usize;
    for name in names {
        if more > 0 || out.chars().count() > LIST_CHARS {
            more += 1;
            continue;
        }
        if !out.is_empty() {
            out += ", ";
        }
        out += &quoted(name);
    }
    if more > 0 {
        out += &format!(", … ({more} more)");
    }
    if out.is_empty() { "none".into() } else { out }
}

/// `'text'` with every control or otherwise unprintable character escaped as Rust does
/// (`\n`, `\u{1b}`), cut after 80 characters: for echoing a name or key the user gave.
pub fn quoted(text: &str) -> String {
    let count = text.chars().count();
    let shown: String = text.chars().take(QUOTE_CHARS).collect();
    let mut out = format!("'{}'", shown.escape_debug());
    if count > QUOTE_CHARS {
        out.insert_str(out.len() - 1, &format!("… ({count} characters)"));
    }
    out
}

/// `text` with control characters (newlines included) escaped, everything else kept: the last
/// line of defence for a one-line message that may embed untrusted text, such as a path.
pub fn one_line(text: &str) -> String {
    escape_controls(text, false)
}

/// Like [`one_line`] but keeps newlines and tabs: for multi-line output such as a table.
pub fn printable(text: &str) -> String {
    escape_controls(text, true)
}

fn escape_controls(text: &str, keep_lines: bool) -> String {
    if !text.chars().any(needs_escape) {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        if keep_lines && (c == '\n' || c == '\t') || !needs_escape(c) {
            out.push(c);
        } else {
            out.extend(c.escape_debug());
        }
    }
    out
}

/// Control characters (C0, DEL, C1) and the invisible bidirectional overrides that can make
/// text read differently from what it is.
/// Controls, bidirectional controls, and the line and paragraph separators (U+2028, U+2029:
/// not controls, but line breaks to some terminals and to spreadsheets).
fn needs_escape(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{2028}' | '\u{2029}')
}

/// Opens `path` for reading if it is a regular file, without blocking on a FIFO; returns the
/// file and its size. The check is made on the opened file, so it cannot be swapped between.
pub fn open_regular(path: &Path) -> Result<(File, u64), String> {
    // O_NONBLOCK: opening a FIFO with no writer returns at once instead of waiting for one; it
    // has no effect on the regular files that pass the check below.
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| format!("cannot read: {e}"))?;
    let meta = file.metadata().map_err(|e| format!("cannot read: {e}"))?;
    let kind = meta.file_type();
    if !kind.is_file() {
        let what = if kind.is_dir() {
            "a directory"
        } else if kind.is_fifo() {
            "a FIFO"
        } else if kind.is_socket() {
            "a socket"
        } else if kind.is_char_device() || kind.is_block_device() {
            "a device"
        } else {
            "a special file"
        };
        return Err(format!("not a regular file ({what})"));
    }
    Ok((file, meta.len()))
}

/// Reads a regular file of at most `max` bytes as UTF-8 text.
pub fn read_bounded(path: &Path, max: u64) -> Result<String, String> {
    let (file, len) = open_regular(path)?;
    let limit = |n: u64| {
        format!(
            "{n} bytes, larger than the {} a scenario file may hold",
            human(max)
        )
    };
    if len > max {
        return Err(limit(len));
    }
    // The file may grow after the check: never read more than the bound.
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read: {e}"))?;
    if bytes.len() as u64 > max {
        return Err(limit(bytes.len() as u64));
    }
    String::from_utf8(bytes)
        .map_err(|e| format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()))
}

fn human(bytes: u64) -> String {
    if bytes.is_multiple_of(1 << 20) {
        format!("{} MiB", bytes >> 20)
    } else {
        format!("{bytes} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_escapes_controls_and_cuts_long_text() {
        assert_eq!(quoted("uio"), "'uio'");
        assert_eq!(quoted("a\nb\u{1b}[31m"), r"'a\nb\u{1b}[31m'");
        let long = quoted(&"n".repeat(250));
        assert!(
            long.ends_with("… (250 characters)'") && long.len() < 110,
            "{long}"
        );
        assert_eq!(one_line("x\ny\u{9b}"), r"x\ny\u{9b}");
        assert_eq!(printable("a\tb\nc\u{7}"), "a\tb\nc\\u{7}");
        assert_eq!(one_line("a\\u{1b}"), "a\\u{1b}");
        assert_eq!(one_line("ab\u{202e}c"), r"ab\u{202e}c");
    }

    #[test]
    fn special_files_are_refused_without_blocking() {
        let dir = std::env::temp_dir().join(format!("uio-untrusted-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo with a valid C path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(read_bounded(&fifo, 10).unwrap_err().contains("FIFO"));
        assert!(read_bounded(&dir, 10).unwrap_err().contains("directory"));
        assert!(
            read_bounded(Path::new("/dev/zero"), 10)
                .unwrap_err()
                .contains("device")
        );
        let big = dir.join("big");
        std::fs::write(&big, vec![b'#'; 11]).unwrap();
        assert!(read_bounded(&big, 10).unwrap_err().contains("11 bytes"));
        std::fs::write(&big, b"ok").unwrap();
        assert_eq!(read_bounded(&big, 10).unwrap(), "ok");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
