//! `uio-launcher bench`: the seed-002 closed loop (plant, two observers, controller) for N steps,
//! in one process and across processes, with and without recording — and, in the same session,
//! its floor: a bare ring of three processes over the same transport ([`floor`]), against which
//! the multi-process figures are given as ratios. Every repetition runs the floor and then each
//! configuration, so that the machine's drift falls on both sides of a ratio alike. With
//! recording, each repetition also measures the disk's own write rate into the recordings'
//! folder ([`disk`]), and each recorded run its bytes per step and write rate against it. With
//! `bank`, each repetition ends with a bank member's cost in each mode ([`bank`]).

pub mod bank;
pub mod disk;
pub mod floor;
pub mod measure;
pub mod states;

use std::path::Path;

use lockstep::Wait;
use serde::Serialize;

use crate::error::LaunchError;
use crate::plan::plan;
use crate::run::Mode;
use measure::measure;
use recording::write::Percentiles;
use scenario::Scenario;

/// One benchmark run.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRun {
    /// "processes" or "in-process".
    pub mode: String,
    /// Whether the .rrd was written.
    pub recording: bool,
    /// Steps run.
    pub steps: u64,
    /// Steps per second of wall time.
    pub steps_per_s: f64,
    /// Full-step latency, ns.
    pub step_ns: Percentiles,
    /// A recorded run: the recording's bytes per step.
    pub bytes_per_step: Option<f64>,
    /// A recorded run: its recording's bytes over the run's whole time, the recording closed and
    /// synced; the "disk" row: what a synced `dd`-like write into the same folder makes.
    pub write_bytes_per_s: Option<f64>,
}

/// The benchmark's runs: seed 002's, and per repetition the bank's ([`bank`]).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Bench {
    /// Seed 002's runs, each repetition opening with its floor (or disk) run.
    pub runs: Vec<BenchRun>,
    /// Per repetition, the bank runs (empty without `bank`).
    pub banks: Vec<Vec<bank::BankRun>>,
}

/// Runs the benchmark on `scenario` (seed002-sine) for `steps` steps, `repeat` times over; with
/// `with_bank`, each repetition also measures a bank member's cost (recorded if any run is).
#[allow(clippy::too_many_arguments)]
pub fn bench(
    scenario: &Path,
    steps: u64,
    wait: Wait,
    pin: bool,
    modes: &[Mode],
    recording: &[bool],
    repeat: usize,
    with_bank: bool,
) -> Result<Bench, LaunchError> {
    let mut s = Scenario::load(scenario)?;
    s.steps = steps;
    s.duration = steps as f64 * s.dt;
    s.expect = Default::default();
    let p = plan(&s).map_err(|e| LaunchError::Scenario(e.error))?;
    let tmp = std::env::temp_dir().join(format!("uio-bench-{}", std::process::id()));
    let lay = crate::run::configs(&s, &p).layout;
    let mut out = Vec::new();
    let mut banks = Vec::new();
    // Every repetition's files go into `tmp`, removed whether the runs end or fail.
    let result = (|| {
        for _ in 0..repeat.max(1) {
            if modes.contains(&Mode::Processes) {
                let f = floor::floor(steps, [lay.len(), lay.n, lay.l], wait, pin)?;
                out.push(BenchRun {
                    mode: "floor".into(),
                    recording: false,
                    steps,
                    steps_per_s: f.steps_per_s,
                    step_ns: f.inner.step_ns,
                    bytes_per_step: None,
                    write_bytes_per_s: None,
                });
            }
            if recording.contains(&true) {
                out.push(BenchRun {
                    mode: "disk".into(),
                    recording: false,
                    steps: 0,
                    steps_per_s: 0.0,
                    step_ns: Percentiles::default(),
                    bytes_per_step: None,
                    write_bytes_per_s: Some(disk::write_rate(&tmp)?),
                });
            }
            for &mode in modes {
                for &record in recording {
                    let start = std::time::Instant::now();
                    let o = measure(&s, &p, &tmp, mode, wait, record, pin)?;
                    if let Some(rrd) = &o.rrd {
                        disk::sync(rrd)?;
                    }
                    let whole = start.elapsed().as_secs_f64();
                    let bytes = o
                        .rrd
                        .as_ref()
                        .and_then(|r| std::fs::metadata(r).ok())
                        .map(|m| m.len() as f64);
                    out.push(BenchRun {
                        mode: mode.name().into(),
                        recording: record,
                        steps: o.summary.steps,
                        steps_per_s: o.summary.steps_per_s,
                        step_ns: o.summary.latency_ns.step,
                        bytes_per_step: bytes.map(|b| b / o.summary.steps.max(1) as f64),
                        write_bytes_per_s: bytes.map(|b| b / whole.max(1e-9)),
                    });
                }
            }
            if with_bank {
                let record = recording.contains(&true);
                banks.push(bank::runs(steps, wait, pin, modes, record, &tmp)?);
            }
        }
        Ok(())
    })();
    let _ = std::fs::remove_dir_all(&tmp);
    result.map(|()| Bench { runs: out, banks })
}

/// The printed table: seed 002's runs, the bank's, and every ratio as a sentence.
pub fn table(bench: &Bench, wait: Wait) -> String {
    let runs = &bench.runs;
    let mut t = format!(
        "seed002 closed loop (plant, 2 observers, controller), wait = {wait}; floor: bare 3-process ring, same transport and payloads\n"
    );
    t += &format!(
        "{:<12} {:<10} {:>10} {:>14} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8}\n",
        "mode",
        "recording",
        "steps",
        "steps/s",
        "p50 µs",
        "p90 µs",
        "p99 µs",
        "p99.9 µs",
        "max µs",
        "MB/s",
        "B/step"
    );
    for r in runs {
        let us = |ns: u64| format!("{:.2}", ns as f64 / 1000.0);
        let opt =
            |v: Option<f64>, scale: f64| v.map_or("—".into(), |v| format!("{:.0}", v / scale));
        if r.mode == "disk" {
            t += &format!(
                "{:<12} {:<10} {:>10} {:>14} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8}\n",
                "disk (dd)",
                "—",
                "—",
                "—",
                "—",
                "—",
                "—",
                "—",
                "—",
                opt(r.write_bytes_per_s, 1e6),
                "—"
            );
            continue;
        }
        t += &format!(
            "{:<12} {:<10} {:>10} {:>14.0} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8}\n",
            r.mode,
            r.recording,
            r.steps,
            r.steps_per_s,
            us(r.step_ns.p50),
            us(r.step_ns.p90),
            us(r.step_ns.p99),
            us(r.step_ns.p999),
            us(r.step_ns.max),
            opt(r.write_bytes_per_s, 1e6),
            opt(r.bytes_per_step, 1.0)
        );
    }
    t += &bank::table(&bench.banks);
    for (name, v) in ratios(bench) {
        t += &sentence(&name, v);
    }
    t
}

/// A ratio of [`ratios`] as a sentence a reader understands: what is compared with what, its
/// median over the repetitions and their range.
fn sentence(name: &str, (min, median, max, n): (f64, f64, f64, usize)) -> String {
    let pct = |x: f64| format!("{:.1} %", 100.0 * x);
    let over = format!(
        "(median of {n} repetition(s); range {} – {})",
        pct(min),
        pct(max)
    );
    let times = format!("(median of {n} repetition(s); range {min:.2} – {max:.2}×)");
    // Which mode a ratio's name speaks of, as the sentence says it.
    let m = if name.starts_with("in-process") {
        "in one process"
    } else {
        "across processes"
    };
    let rec = |with: bool| {
        if with {
            "with recording"
        } else {
            "without recording"
        }
    };
    match name {
        "processes (no recording) / floor, steps/s" | "processes (recording) / floor, steps/s" => {
            let with = name.contains("(recording)");
            format!(
                "across processes {}, the lockstep ring makes {} of the steps per second of a bare iceoryx2 ring (the floor) {over}\n",
                rec(with),
                pct(median)
            )
        }
        "processes (no recording) / floor, step p50"
        | "processes (recording) / floor, step p50" => {
            let with = name.contains("(recording)");
            format!(
                "across processes {}, a step's median time is {median:.2}× the floor's {times}\n",
                rec(with)
            )
        }
        "processes / in-process, steps/s (no recording)" => {
            format!(
                "without recording, running across processes makes {} of the steps per second of running in one process {over}\n",
                pct(median)
            )
        }
        "in-process: share of steps/s recording costs"
        | "processes: share of steps/s recording costs" => {
            format!(
                "{m}, recording costs {} of the steps per second a run makes without it {over}\n",
                pct(median)
            )
        }
        "processes (no recording) / floor, step p99.9"
        | "processes (recording) / floor, step p99.9" => {
            let with = name.contains("(recording)");
            format!(
                "across processes {}, a step's p99.9 is {median:.2}× the floor's {times}\n",
                rec(with)
            )
        }
        "in-process (recording): write rate / disk's"
        | "processes (recording): write rate / disk's" => {
            format!(
                "{m}, the recording is written at {} of the rate a dd-like write makes into the same folder {over}\n",
                pct(median)
            )
        }
        "bank member: processes / in-process, cost per step" => {
            format!(
                "a bank member's step costs {median:.2}× across processes what it costs in one process {times}\n"
            )
        }
        "in-process (recording): GB per 10^7 steps"
        | "processes (recording): GB per 10^7 steps" => {
            format!(
                "{m}, a 10⁷-step run of this loop writes {median:.2} GB at this run's bytes per step (median of {n} repetition(s); range {min:.2} – {max:.2} GB)\n"
            )
        }
        _ => format!("{name}: median {median:.3} [{min:.3} – {max:.3}] over {n} repetition(s)\n"),
    }
}

/// Ratios per repetition (a repetition starts at each floor run — without one at each disk run —
/// or is the whole list), and the bank's, as (name, (min, median, max, count)).
pub fn ratios(bench: &Bench) -> Vec<(String, (f64, f64, f64, usize))> {
    let runs = &bench.runs[..];
    let mut reps: Vec<&[BenchRun]> = Vec::new();
    // A repetition opens with its floor run, or (one mode in one process) its disk run.
    let opening = |mode: &str| -> Vec<usize> {
        runs.iter()
            .enumerate()
            .filter(|(_, r)| r.mode == mode)
            .map(|(i, _)| i)
            .collect()
    };
    let mut starts = opening("floor");
    if starts.is_empty() {
        starts = opening("disk");
    }
    if starts.is_empty() {
        reps.push(runs);
    } else {
        for (j, &s) in starts.iter().enumerate() {
            reps.push(&runs[s..starts.get(j + 1).copied().unwrap_or(runs.len())]);
        }
    }
    let mut named: Vec<(String, Vec<f64>)> = Vec::new();
    let mut add = |name: String, v: f64| match named.iter_mut().find(|(n, _)| *n == name) {
        Some((_, list)) => list.push(v),
        None => named.push((name, vec![v])),
    };
    for rep in reps {
        let get = |m: &str, rec: bool| rep.iter().find(|r| r.mode == m && r.recording == rec);
        if let Some(f) = get("floor", false) {
            for rec in [false, true] {
                if let Some(p) = get("processes", rec) {
                    let what = if rec { "recording" } else { "no recording" };
                    add(
                        format!("processes ({what}) / floor, steps/s"),
                        p.steps_per_s / f.steps_per_s,
                    );
                    add(
                        format!("processes ({what}) / floor, step p50"),
                        p.step_ns.p50 as f64 / f.step_ns.p50.max(1) as f64,
                    );
                    add(
                        format!("processes ({what}) / floor, step p99.9"),
                        p.step_ns.p999 as f64 / f.step_ns.p999.max(1) as f64,
                    );
                }
            }
        }
        if let (Some(p), Some(i)) = (get("processes", false), get("in-process", false)) {
            add(
                "processes / in-process, steps/s (no recording)".into(),
                p.steps_per_s / i.steps_per_s,
            );
        }
        let disk = rep
            .iter()
            .find(|r| r.mode == "disk")
            .and_then(|d| d.write_bytes_per_s);
        for m in ["in-process", "processes"] {
            let Some(r) = get(m, true) else { continue };
            if let (Some(w), Some(d)) = (r.write_bytes_per_s, disk) {
                add(format!("{m} (recording): write rate / disk's"), w / d);
            }
            if let Some(b) = r.bytes_per_step {
                add(format!("{m} (recording): GB per 10^7 steps"), b * 1e7 / 1e9);
            }
        }
        for m in ["in-process", "processes"] {
            if let (Some(a), Some(b)) = (get(m, true), get(m, false)) {
                add(
                    format!("{m}: share of steps/s recording costs"),
                    1.0 - a.steps_per_s / b.steps_per_s,
                );
            }
        }
    }
    bank::ratios(&bench.banks, &mut add);
    named
        .into_iter()
        .map(|(n, mut v)| {
            v.sort_by(f64::total_cmp);
            (n, (v[0], v[(v.len() - 1) / 2], v[v.len() - 1], v.len()))
        })
        .collect()
}

#[cfg(test)]
mod sentence_tests {
    use super::{BenchRun, Percentiles, ratios, sentence};

    fn run(mode: &str, recording: bool, steps_per_s: f64, write: Option<f64>) -> BenchRun {
        BenchRun {
            mode: mode.into(),
            recording,
            steps: 100,
            steps_per_s,
            step_ns: Percentiles::default(),
            bytes_per_step: recording.then_some(400.0),
            write_bytes_per_s: write,
        }
    }

    /// In one mode without a floor, each disk run opens a repetition: the write rates are
    /// shares of their own repetition's disk rate, the size is bytes per step × 10⁷.
    #[test]
    fn a_recordings_write_rate_is_a_share_of_its_own_repetitions_disk_rate() {
        let runs = [
            run("disk", false, 0.0, Some(1000.0)),
            run("in-process", false, 10.0, None),
            run("in-process", true, 5.0, Some(300.0)),
            run("disk", false, 0.0, Some(2000.0)),
            run("in-process", false, 10.0, None),
            run("in-process", true, 5.0, Some(400.0)),
        ];
        let r = ratios(&super::Bench {
            runs: runs.to_vec(),
            banks: Vec::new(),
        });
        let get = |name: &str| r.iter().find(|(n, _)| n == name).unwrap().1;
        assert_eq!(
            get("in-process (recording): write rate / disk's"),
            (0.2, 0.2, 0.3, 2)
        );
        assert_eq!(
            get("in-process (recording): GB per 10^7 steps"),
            (4.0, 4.0, 4.0, 2)
        );
        assert_eq!(
            get("in-process: share of steps/s recording costs"),
            (0.5, 0.5, 0.5, 2)
        );
    }

    /// Each ratio reads as a sentence with its median and range, not as an algebraic name.
    #[test]
    fn ratios_read_as_sentences() {
        let s = sentence(
            "in-process: share of steps/s recording costs",
            (0.78, 0.791, 0.80, 3),
        );
        assert_eq!(
            s,
            "in one process, recording costs 79.1 % of the steps per second a run makes without it (median of 3 repetition(s); range 78.0 % – 80.0 %)\n"
        );
        let s = sentence(
            "processes (recording) / floor, steps/s",
            (0.5, 0.52, 0.55, 3),
        );
        assert!(s.starts_with("across processes with recording, the lockstep ring makes 52.0 % of the steps per second of a bare iceoryx2 ring"), "{s}");
        let s = sentence(
            "processes (no recording) / floor, step p50",
            (1.1, 1.25, 1.4, 2),
        );
        assert!(
            s.contains("a step's median time is 1.25× the floor's"),
            "{s}"
        );
    }
}
