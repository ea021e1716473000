//! Whether a component that publishes nothing is stopped, blocked, or running but slow.
//!
//! A run with no progress is not always a hung one: under load from other programs a healthy
//! component may wait seconds for a core. The kernel tells them apart. For the component's whole
//! process group (an interpreter's workers, a shell's children) it reports each process's state
//! and CPU time in /proc/<pid>/stat:
//!
//! * stopped (`T`, `t`: SIGSTOP, a debugger): hung, named at once;
//! * runnable (`R`), or CPU time spent since the last look: running or starved — waited for up to
//!   the stall limit (`stall_timeout`, `--stall-timeout`);
//! * asleep with no CPU spent over a whole look: blocked — it waits for something that does not
//!   come, named at once.

use std::time::{Duration, Instant};

/// How often the kernel's view is taken while nothing progresses.
pub const LOOK_EVERY: Duration = Duration::from_millis(1000);

/// One look at a process group.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    /// Some process of the group is stopped.
    pub stopped: bool,
    /// Some process of the group is runnable.
    pub runnable: bool,
    /// CPU time of the group (user + system), clock ticks.
    pub ticks: u64,
}

/// What the group looks like now, or `None` when it is gone.
pub fn look(pgid: u32) -> Option<Look> {
    let mut out = Look {
        stopped: false,
        runnable: false,
        ticks: 0,
    };
    let mut found = false;
    for entry in std::fs::read_dir("/proc").ok()?.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(|n| n.parse::<u32>().ok()) else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
            continue;
        };
        // "pid (comm) S ppid pgrp session tty tpgid flags minflt cminflt majflt cmajflt utime stime …":
        // the fields after the last ')' (comm may hold anything).
        let Some((_, rest)) = stat.rsplit_once(')') else {
            continue;
        };
        let f: Vec<&str> = rest.split_whitespace().collect();
        if f.len() < 13 || f[2].parse::<u32>().ok() != Some(pgid) {
            continue;
        }
        found = true;
        match f[0] {
            "T" | "t" => out.stopped = true,
            "R" => out.runnable = true,
            _ => {}
        }
        out.ticks += f[11].parse::<u64>().unwrap_or(0) + f[12].parse::<u64>().unwrap_or(0);
    }
    found.then_some(out)
}

/// The verdict on a component that has published nothing for a while.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Stopped by a signal or a debugger.
    Stopped,
    /// Asleep, with no CPU spent since the last look.
    Blocked,
    /// Running or waiting for a core: to be waited for, up to the stall limit.
    Busy,
}

/// Looks at components' process groups every [`LOOK_EVERY`], judging each against its last look.
#[derive(Debug)]
pub struct Watch {
    at: Instant,
    last: Vec<Option<Look>>,
}

impl Watch {
    /// A first look at every group.
    pub fn new(pgids: &[u32]) -> Self {
        Watch {
            at: Instant::now(),
            last: pgids.iter().map(|&p| look(p)).collect(),
        }
    }

    /// Every [`LOOK_EVERY`]: the verdict on group `i` against the previous look, and a new look
    /// at every group; `None` between looks.
    pub fn judge(&mut self, pgids: &[u32], i: usize) -> Option<Verdict> {
        if self.at.elapsed() < LOOK_EVERY {
            return None;
        }
        let now: Vec<Option<Look>> = pgids.iter().map(|&p| look(p)).collect();
        let verdict = match (self.last[i], now[i]) {
            (_, Some(n)) if n.stopped => Verdict::Stopped,
            (Some(b), Some(n)) if n.runnable || n.ticks > b.ticks => Verdict::Busy,
            (None, Some(n)) if n.runnable => Verdict::Busy,
            _ => Verdict::Blocked,
        };
        self.at = Instant::now();
        self.last = now;
        Some(verdict)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A child that spins is busy, one that sleeps is blocked, one stopped by SIGSTOP is stopped.
    #[test]
    fn the_kernel_tells_busy_blocked_and_stopped_apart() {
        use std::os::unix::process::CommandExt;
        let spawn = |script: &str| {
            std::process::Command::new("sh")
                .args(["-c", script])
                .process_group(0)
                .spawn()
                .unwrap()
        };
        let mut spin = spawn("while :; do :; done");
        let mut sleep = spawn("sleep 30");
        let mut stop = spawn("sleep 30");
        // SAFETY: kill(2) on a child of this test.
        unsafe { libc::kill(stop.id() as i32, libc::SIGSTOP) };
        let pgids = [spin.id(), sleep.id(), stop.id()];
        let mut w = Watch::new(&pgids);
        std::thread::sleep(LOOK_EVERY + Duration::from_millis(50));
        assert_eq!(w.judge(&pgids, 0), Some(Verdict::Busy));
        std::thread::sleep(LOOK_EVERY + Duration::from_millis(50));
        assert_eq!(w.judge(&pgids, 1), Some(Verdict::Blocked));
        std::thread::sleep(LOOK_EVERY + Duration::from_millis(50));
        assert_eq!(w.judge(&pgids, 2), Some(Verdict::Stopped));
        assert_eq!(w.judge(&pgids, 2), None, "between looks");
        for c in [&mut spin, &mut sleep, &mut stop] {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}
