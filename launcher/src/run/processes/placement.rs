//! Where the lockstep ring's processes run: which CPU each gets.

use super::super::configs::Configs;

/// The CPUs this process may run on.
fn allowed_cpus() -> Vec<usize> {
    // SAFETY: sched_getaffinity fills the set we own.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Vec::new();
        }
        (0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &set))
            .collect()
    }
}

/// Restricts the calling process to one CPU (best effort: a refusal leaves it where it is).
/// Called in the child between fork and exec, so the component starts where it will run.
pub(crate) fn pin_self(cpu: usize) {
    // SAFETY: the set is initialised before use; sched_setaffinity is a plain system call
    // (async-signal-safe) and only reads it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}

/// Which CPU each component runs on (None: wherever the scheduler likes).
///
/// Only the ring — plant, the controller's observer, controller (or, open loop, the plant and
/// its observers) — is placed; followers sleep between batches and float. With a CPU per ring
/// process each gets its own. With two, the plant gets one to itself and the rest of the ring
/// shares the other: only one process switch then lies on each step's critical path (a switch
/// between processes costs ~2.5 µs on the 2-vCPU machines this was measured on). In between,
/// the plant keeps the first CPU and the rest of the ring takes the others in turn.
pub(super) fn placement(
    cfg: &Configs,
    pin: bool,
) -> (Option<usize>, Vec<Option<usize>>, Option<usize>) {
    // Per observer process: in the ring unless every observer it steps is a follower.
    let ring_observers: Vec<bool> = cfg
        .processes
        .iter()
        .map(|p| p.observers.iter().any(|&i| !cfg.followers[i]))
        .collect();
    let ring = 1 + ring_observers.iter().filter(|&&r| r).count() + usize::from(cfg.closed_loop);
    let mut cpus = ring_cpus(ring, pin).into_iter();
    let plant = cpus.next().flatten();
    let observers = ring_observers
        .iter()
        .map(|&r| if r { cpus.next().flatten() } else { None })
        .collect();
    let controller = if cfg.closed_loop {
        cpus.next().flatten()
    } else {
        None
    };
    (plant, observers, controller)
}

/// The CPU of each of a ring's `ring` processes, the plant first, by the rule of [`placement`]
/// (all None without pinning or with fewer than two CPUs).
pub(crate) fn ring_cpus(ring: usize, pin: bool) -> Vec<Option<usize>> {
    let cpus = allowed_cpus();
    if !pin || cpus.len() < 2 {
        return vec![None; ring];
    }
    (0..ring)
        .map(|i| {
            Some(match i {
                0 => cpus[0],
                _ if cpus.len() >= ring => cpus[i],
                _ => cpus[1 + (i - 1) % (cpus.len() - 1)],
            })
        })
        .collect()
}
