//! What a run will take of the machine, estimated from the scenario before anything starts and
//! checked against what the machine has: the recording against the free space of the output
//! directory's file system, the buffers that grow with the scenario against available memory,
//! and the run's shared memory against the free space of `/dev/shm`. A run that cannot fit is
//! bad input (exit 2) — not a full disk or an abort halfway through.

use std::ffi::CString;
use std::os::unix::ffi::OsStrExt;
use std::path::Path;

use diagnosis::Evaluation;
use recording::signals as sig;
use scenario::Scenario;

use super::{Mode, Options};
use crate::error::LaunchError;
use crate::plan::Plan;

/// Bytes a recorded value takes in the `.rrd` (layout 2): the f64 itself.
pub const BYTES_PER_VALUE: u64 = 8;

/// Bytes a row of an entity takes besides its values: Rerun's row id (16), the step and
/// sim_time stamps (8 + 8) and two list offsets (4 + 4), with its share of the chunks' headers.
/// Measured: 437 bytes a step in-process for seed002-sine's 29 values in 5 entities.
pub const BYTES_PER_ROW: u64 = 41;

/// The entity paths a run records, before `--record` filters them: the series
/// [`super::Session::new`] creates, in no particular order.
pub fn recorded_paths(s: &Scenario, plan: &Plan, paced: bool) -> Vec<String> {
    let m = &s.model;
    let mut p: Vec<String> = Vec::new();
    p.extend((0..m.n()).map(sig::state));
    p.extend((0..m.p()).map(sig::output));
    p.extend((0..m.e.ncols()).map(sig::disturbance));
    p.extend((0..m.d.ncols()).map(sig::measurement_disturbance));
    p.extend((0..m.l()).map(sig::input));
    if s.controller.is_some() {
        p.extend((0..m.l()).map(sig::control));
    }
    for (o, (_, d)) in s
        .observers
        .iter()
        .zip(&plan.observers)
        .filter(|(o, _)| o.member.is_none())
    {
        p.extend((0..m.n()).map(|i| sig::estimate(&o.name, i)));
        p.extend((0..m.n()).map(|i| sig::error(&o.name, i)));
        p.extend((0..m.p()).map(|j| sig::residual(&o.name, j)));
        p.push(sig::log_error(&o.name));
        if d.as_ref().is_some_and(|d| d.what.is_some()) {
            p.extend((0..m.e.ncols()).map(|k| sig::input_estimate(&o.name, k)));
        }
    }
    for b in &plan.banks {
        let d = &b.spec.name;
        for (i, mb) in b.members.iter().enumerate() {
            p.extend(mb.outputs.iter().map(|&j| sig::member_residual(d, i, j)));
            p.extend([
                sig::evaluation(d, i),
                sig::threshold(d, i),
                sig::alarm(d, i),
            ]);
        }
        p.push(sig::isolated(d));
        if b.members.iter().any(|mb| mb.glr.is_some()) {
            for i in 0..b.members.len() {
                p.extend([sig::glr(d, i), sig::glr_threshold(d, i)]);
            }
            p.push(sig::decided_by(d));
        }
    }
    for f in &s.faults {
        p.extend([sig::fault_active(&f.name), sig::fault_value(&f.name)]);
    }
    p.push("/latency/step".into());
    if paced {
        p.push("/latency/overrun".into());
    }
    p.extend(super::hop_names(s).iter().map(|h| super::hop_entity(h)));
    p
}

/// Bytes the run's recording will take, about: recorded steps × (values × [`BYTES_PER_VALUE`] +
/// entity rows × [`BYTES_PER_ROW`]). Returns (steps, values, entity rows, bytes).
pub fn recording_bytes(s: &Scenario, plan: &Plan, opts: &Options) -> (u64, u64, u64, u64) {
    let paths: Vec<String> = recorded_paths(s, plan, opts.realtime.is_some())
        .into_iter()
        .filter(|p| opts.select.entity(p))
        .collect();
    let mut entities: Vec<String> = paths.iter().map(|p| sig::entity_of(p)).collect();
    entities.sort();
    entities.dedup();
    // ŵ is a row of its own (one step late), beside its observer's.
    let late = paths
        .iter()
        .filter(|p| p.contains("/what/"))
        .map(|p| sig::entity_of(p))
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    let (scalars, rows) = (paths.len() as u64, (entities.len() + late) as u64);
    let steps = s.steps.div_ceil(opts.select.every());
    (
        steps,
        scalars,
        rows,
        steps.saturating_mul(scalars * BYTES_PER_VALUE + rows * BYTES_PER_ROW),
    )
}

/// Memory one run's buffers take that grow with the scenario: each `rms` member's window, each
/// GLR test's signatures and sums, and each observer's tail maxima (see `recording::write::tail`).
pub fn memory_bytes(s: &Scenario, plan: &Plan) -> u64 {
    let windows: u64 = plan
        .banks
        .iter()
        .map(|b| match b.spec.evaluation {
            Evaluation::Rms { window } => (window as u64) * b.members.len() as u64 * 8,
            _ => 0,
        })
        .sum();
    // A GLR test keeps, per tested channel, N signatures of d values, N information sums and
    // N correlations.
    let glr: u64 = plan
        .banks
        .iter()
        .flat_map(|b| &b.members)
        .filter_map(|mb| mb.glr.as_ref())
        .map(|g| (g.window * g.channels.len() * (g.dim() + 2)) as u64 * 8)
        .sum();
    let blocks = s
        .steps
        .div_ceil(recording::write::tail::block_len(s.steps))
        .max(1);
    windows + glr + s.observers.len() as u64 * 2 * blocks * 8
}

/// Shared memory of a run across processes, about: every service's data segment, sized by
/// iceoryx2 for its most subscribers, each with the largest buffer (PROTOCOL.md §4).
pub fn shared_memory_bytes(s: &Scenario, plant_len: usize) -> u64 {
    use lockstep::settings::{MAX_SUBSCRIBERS, SUBSCRIBER_MAX_BUFFER};
    let n = s.model.n();
    // An observer process publishes n values per observer it steps (a bank's, all its members').
    let lens = std::iter::once(plant_len)
        .chain(
            s.observer_processes()
                .into_iter()
                .map(|p| p.observers.len() * n),
        )
        .chain(s.controller.as_ref().map(|_| s.model.l()));
    let per_sample = |len: usize| {
        (len as u64 * 8 + std::mem::size_of::<lockstep::WireHeader>() as u64)
            * (MAX_SUBSCRIBERS * SUBSCRIBER_MAX_BUFFER) as u64
    };
    lens.map(per_sample).sum()
}

/// Checks a run's recording, memory and shared memory against the machine; `jobs` runs at once.
pub fn check(
    s: &Scenario,
    plan: &Plan,
    opts: &Options,
    plant_len: usize,
    jobs: u64,
) -> Result<(), LaunchError> {
    if opts.record {
        let (steps, scalars, rows, bytes) = recording_bytes(s, plan, opts);
        if let Some(free) = free_bytes(&opts.out)
            && bytes > free
        {
            return Err(LaunchError::BadInput(format!(
                "{}: the recording would take about {} ({steps} recorded steps × ({scalars} signals × {BYTES_PER_VALUE} bytes + {rows} entity rows × {BYTES_PER_ROW} bytes)), the file system has {} free; thin it with --record-every N or --record GLOB",
                opts.out.display(),
                size(bytes),
                size(free)
            )));
        }
    }
    check_memory(s, plan, jobs)?;
    if opts.mode == Mode::Processes {
        let need = shared_memory_bytes(s, plant_len);
        if let Some(free) = free_bytes(Path::new("/dev/shm"))
            && need > free
        {
            return Err(LaunchError::BadInput(format!(
                "{}: the run's shared memory would take about {} ({} values per plant sample), /dev/shm has {} free",
                s.path.display(),
                size(need),
                plant_len,
                size(free)
            )));
        }
    }
    Ok(())
}

/// Checks the memory of `jobs` runs at once against what the machine has available.
pub fn check_memory(s: &Scenario, plan: &Plan, jobs: u64) -> Result<(), LaunchError> {
    let need = memory_bytes(s, plan).saturating_mul(jobs);
    match available_memory() {
        Some(free) if need > free => Err(LaunchError::BadInput(format!(
            "{}: {jobs} run(s) at once would need about {} for their residual windows and figures, the machine has {} available",
            s.path.display(),
            size(need),
            size(free)
        ))),
        _ => Ok(()),
    }
}

/// Free bytes for an unprivileged user on the file system of `dir`, or of its nearest existing
/// ancestor (the output directory may not exist yet).
pub fn free_bytes(dir: &Path) -> Option<u64> {
    let abs = std::path::absolute(dir).ok()?;
    let existing = abs.ancestors().find(|p| p.exists())?;
    let c = CString::new(existing.as_os_str().as_bytes()).ok()?;
    // SAFETY: statvfs(3) writes into the zeroed struct we own; the path is a valid C string.
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(c.as_ptr(), &mut st) } != 0 {
        return None;
    }
    Some((st.f_bavail as u64).saturating_mul(st.f_frsize as u64))
}

/// `MemAvailable` of /proc/meminfo, bytes.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// "1.6 GB", "430 MB".
fn size(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.0} MB", (b / 1e6).max(1.0))
    }
}
