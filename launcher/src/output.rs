//! Everything the launcher prints goes through here, so that printing never panics and never
//! passes a terminal control sequence through.
//!
//! `println!` panics when stdout is a closed pipe (`uio-launcher list | head -1`) or a terminal
//! that hung up; these functions drop what cannot be written instead, and the command ends
//! with its own exit code. Control characters in the text (which may quote a file's contents
//! or name) are escaped: in stdout's multi-line output all but newlines and tabs, in a
//! message on stderr all of them, so that a message stays one line.

use std::io::Write;

use scenario::untrusted::{one_line, printable};

/// Writes `text` to stdout as it is, newlines included.
pub fn out(text: &str) {
    let mut o = std::io::stdout().lock();
    let _ = o
        .write_all(printable(text).as_bytes())
        .and_then(|_| o.flush());
}

/// Writes one message line to stderr.
pub fn err_line(text: &str) {
    let mut e = std::io::stderr().lock();
    let _ = writeln!(e, "{}", one_line(text));
}

/// `print!` through [`out`].
#[macro_export]
macro_rules! print {
    ($($t:tt)*) => { $crate::output::out(&format!($($t)*)) };
}

/// `println!` through [`out`].
#[macro_export]
macro_rules! println {
    () => { $crate::output::out("\n") };
    ($($t:tt)*) => { $crate::output::out(&format!("{}\n", format_args!($($t)*))) };
}

/// `eprintln!` through [`err_line`].
#[macro_export]
macro_rules! eprintln {
    ($($t:tt)*) => { $crate::output::err_line(&format!($($t)*)) };
}
