//! SIGINT, SIGTERM, SIGHUP (the terminal or SSH session closed) and SIGQUIT (Ctrl-\) set a flag
//! the run loops poll, so an interrupted run stops the same clean way as a failed one:
//! components stopped, recording finalised, shared memory and run directory removed. Left to
//! their default action, SIGHUP and SIGQUIT would kill the launcher outright and leave all of
//! that for a later run to clean up.
//!
//! Exit codes follow the shell's 128 + signal number — 129 SIGHUP, 130 SIGINT, 131 SIGQUIT —
//! except SIGTERM, which exits 130 like SIGINT (as it always has here).

use std::sync::atomic::{AtomicI32, Ordering};

static SIGNAL: AtomicI32 = AtomicI32::new(0);

/// The signals that stop a run cleanly.
const HANDLED: [libc::c_int; 4] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP, libc::SIGQUIT];

extern "C" fn on_signal(sig: libc::c_int) {
    // A second signal means the clean stop is not wanted (or is stuck): leave at once. The
    // components die with the launcher, and the next run removes what this one left.
    if SIGNAL.swap(sig, Ordering::SeqCst) != 0 {
        // SAFETY: _exit is async-signal-safe.
        unsafe { libc::_exit(exit_code_of(sig)) };
    }
}

/// Installs the handlers (idempotent).
pub fn install() {
    for sig in HANDLED {
        // SAFETY: the handler only stores to an atomic and may call _exit, both
        // async-signal-safe.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as *const () as usize;
            // Restart interrupted reads (the component stderr collectors) instead of failing them.
            action.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(sig, &action, std::ptr::null_mut());
        }
    }
}

/// The signal received, if any ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT").
pub fn received() -> Option<&'static str> {
    match SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        libc::SIGHUP => Some("SIGHUP"),
        libc::SIGQUIT => Some("SIGQUIT"),
        libc::SIGTERM => Some("SIGTERM"),
        _ => Some("SIGINT"),
    }
}

/// The launcher's exit code after an interruption by the signal received (130 if none).
pub fn exit_code() -> i32 {
    exit_code_of(SIGNAL.load(Ordering::SeqCst))
}

const fn exit_code_of(sig: libc::c_int) -> i32 {
    match sig {
        libc::SIGHUP => 129,
        libc::SIGQUIT => 131,
        _ => 130,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_follow_the_signal() {
        assert_eq!(
            [libc::SIGHUP, libc::SIGINT, libc::SIGQUIT, libc::SIGTERM].map(exit_code_of),
            [129, 130, 131, 130]
        );
    }
}
