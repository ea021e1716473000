//! How this process ends, whatever the FMU loaded.

use crate::{fmi2, python};

/// Ends the process with `code`. After an FMU that embeds Python or returned fmi2Fatal, the
/// libraries it loaded do not run their exit handlers (`_exit`): numpy's bundled libgfortran
/// freed corrupted memory at exit after pythonfmu instances were freed or failed (glibc's
/// "free(): corrupted unsorted chunks", SIGABRT, after an otherwise finished run).
pub fn end(code: i32) -> std::process::ExitCode {
    if fmi2::fatal() || python::loaded() {
        use std::io::Write as _;
        let _ = std::io::stdout().flush();
        let _ = std::io::stderr().flush();
        // SAFETY: ends the process at once; what is ours is flushed, the run left behind.
        unsafe { libc::_exit(code) };
    }
    std::process::ExitCode::from(code as u8)
}
