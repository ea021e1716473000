//! The monotonic clock every process reads, so send and take times compare across processes.

/// CLOCK_MONOTONIC in nanoseconds.
#[inline]
pub fn now_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes into the timespec we own; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// Sleeps until CLOCK_MONOTONIC reads `t` ns (at once if it has passed): an absolute deadline,
/// so a paced loop does not accumulate the sleeps' overshoot.
pub fn sleep_until_ns(t: u64) {
    let ts = libc::timespec {
        tv_sec: (t / 1_000_000_000) as libc::time_t,
        tv_nsec: (t % 1_000_000_000) as libc::c_long,
    };
    // SAFETY: clock_nanosleep reads the timespec we own; EINTR just ends the sleep early, and
    // the loop around it sleeps again.
    while now_ns() < t
        && unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &ts,
                std::ptr::null_mut(),
            )
        } == libc::EINTR
    {}
}

/// Asks for timers as exact as the kernel gives them (the default slack of 50 µs would be 5 %
/// of a 1 ms step): for paced runs.
pub fn tight_timers() {
    // SAFETY: prctl(PR_SET_TIMERSLACK) only sets a value of the calling thread.
    unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1u64) };
}
