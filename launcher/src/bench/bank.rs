//! A bank member's cost, in one process and across processes: the figure of issue 35's table that
//! seed 002 (no bank) cannot give. A 2-state plant read by `m` sensors y_j = x1 + a_j x2 (each
//! alone observes it: a_j ∉ {½, 1}, the zeros of det [c_j; c_j A]), one Luenberger observer, open
//! loop, runs with and without a dedicated bank of `m` Luenberger members; a member's cost per
//! step is the difference of the two runs' seconds per step over `m`:
//!
//!   cost = (1/r_bank − 1/r_plain) / m        (r: steps per second)
//!
//! and its ratio across processes / in one process is the figure (target ≤ 1.5×). The bank's
//! members share one observer process (PROTOCOL.md §4), so across processes a member costs its
//! step plus the launcher's work for its residual (figures, recording) on the same two cores.

use serde::Serialize;

use lockstep::Wait;
use scenario::Scenario;

use crate::error::LaunchError;
use crate::plan::plan;
use crate::run::Mode;

/// Members of the benchmark's bank (as in BENCHMARKS.md's measurements of 2026-11-27).
pub const MEMBERS: usize = 32;

/// One (mode, bank or not) run.
#[derive(Debug, Clone, Serialize)]
pub struct BankRun {
    /// "processes" or "in-process".
    pub mode: String,
    /// Members of the bank: 0 for the run without it.
    pub members: usize,
    /// Whether the .rrd was written.
    pub recording: bool,
    /// Steps per second.
    pub steps_per_s: f64,
}

/// The scenario text: `m` sensors, `steps` steps of 1 ms, with a dedicated bank if `bank`.
pub fn scenario_text(m: usize, steps: u64, bank: bool) -> String {
    let c: Vec<String> = (0..m)
        .map(|j| format!("[1.0, {:?}]", 0.03 * (j + 1) as f64 + 0.01))
        .collect();
    let diagnoser = if bank {
        r#"
[[diagnoser]]
name = "dos"
scheme = "dedicated"
faults = "sensor"
observer = "luenberger"
poles = [-6.0, -7.0]
evaluation = "norm"
threshold = 0.05
persistence = 3
ignore_before = 1.0
"#
    } else {
        ""
    };
    format!(
        r#"name = "bank{m}"
dt = 0.001
duration = {duration:?}

[plant]
A = [[0.0, 1.0], [-2.0, -3.0]]
B = [[0.0], [1.0]]
C = [{c}]
x0 = [1.0, 0.0]

[[input]]
kind = "sine"
amplitude = 1.0
frequency_hz = 0.5

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-4.0, -5.0]
{diagnoser}"#,
        duration = steps as f64 * 0.001,
        c = c.join(", "),
    )
}

/// One repetition: in each of `modes`, the plant without the bank and with it, `steps` steps.
pub fn runs(
    steps: u64,
    wait: Wait,
    pin: bool,
    modes: &[Mode],
    record: bool,
    tmp: &std::path::Path,
) -> Result<Vec<BankRun>, LaunchError> {
    let mut out = Vec::new();
    for &mode in modes {
        for members in [0, MEMBERS] {
            let text = scenario_text(MEMBERS, steps, members > 0);
            let s = Scenario::parse(std::path::Path::new("bank.toml"), &text)?;
            let p = plan(&s).map_err(|e| LaunchError::Scenario(e.error))?;
            let o = super::measure::measure(&s, &p, tmp, mode, wait, record, pin)?;
            out.push(BankRun {
                mode: mode.name().into(),
                members,
                recording: record,
                steps_per_s: o.summary.steps_per_s,
            });
        }
    }
    Ok(out)
}

/// One repetition's runs in `mode`: with the bank and without it.
fn pair<'a>(rep: &'a [BankRun], mode: &str) -> Option<(&'a BankRun, &'a BankRun)> {
    let get = |bank: bool| {
        rep.iter()
            .find(|r| r.mode == mode && (r.members > 0) == bank)
    };
    Some((get(true)?, get(false)?))
}

/// A member's cost per step in `mode`, µs, in one repetition's runs (with and without the bank).
pub fn cost_per_member_us(rep: &[BankRun], mode: &str) -> Option<f64> {
    let (with, without) = pair(rep, mode)?;
    let per_step = |r: &BankRun| 1e6 / r.steps_per_s.max(1e-9);
    Some((per_step(with) - per_step(without)) / with.members as f64)
}

/// Per repetition, each mode's cost per member (µs) and the ratio across processes / in one
/// process, each handed to `add` by name.
pub fn ratios(banks: &[Vec<BankRun>], mut add: impl FnMut(String, f64)) {
    let mut add = |name: &str, v: f64| add(name.into(), v);
    for rep in banks {
        let (i, p) = (
            cost_per_member_us(rep, "in-process"),
            cost_per_member_us(rep, "processes"),
        );
        if let Some(i) = i {
            add("bank member (in-process), µs per step", i);
        }
        if let Some(p) = p {
            add("bank member (processes), µs per step", p);
        }
        if let (Some(i), Some(p)) = (i, p) {
            add("bank member: processes / in-process, cost per step", p / i);
        }
    }
}

/// The bank runs as rows: mode, steps/s with the bank and without, a member's cost.
pub fn table(banks: &[Vec<BankRun>]) -> String {
    let Some(first) = banks.iter().flatten().next() else {
        return String::new();
    };
    let mut t = format!(
        "bank: {MEMBERS} dedicated Luenberger members, 2-state plant, {MEMBERS} sensors, open loop, recording {}\n{:<12} {:>16} {:>14} {:>20}\n",
        if first.recording { "on" } else { "off" },
        "mode",
        "steps/s (bank)",
        "steps/s (none)",
        "µs per member, step"
    );
    for rep in banks {
        for mode in ["in-process", "processes"] {
            if let (Some((w, n)), Some(c)) = (pair(rep, mode), cost_per_member_us(rep, mode)) {
                t += &format!(
                    "{:<12} {:>16.0} {:>14.0} {:>20.3}\n",
                    mode, w.steps_per_s, n.steps_per_s, c
                );
            }
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(mode: &str, members: usize, steps_per_s: f64) -> BankRun {
        BankRun {
            mode: mode.into(),
            members,
            recording: true,
            steps_per_s,
        }
    }

    /// 32 members that take a run from 500 k to 100 k steps/s add 8 µs a step: 0.25 µs each.
    #[test]
    fn a_members_cost_is_the_runs_difference_in_time_per_step_over_the_members() {
        let rep = [
            run("in-process", 0, 500_000.0),
            run("in-process", 32, 100_000.0),
            run("processes", 0, 100_000.0),
        ];
        let c = cost_per_member_us(&rep, "in-process").unwrap();
        assert!((c - 0.25).abs() < 1e-12, "{c}");
        assert_eq!(cost_per_member_us(&rep, "processes"), None);
    }

    /// The benchmark's scenario parses and plans, with the bank and without, and its bank has a
    /// member per sensor.
    #[test]
    fn the_bank_scenario_plans_with_a_member_per_sensor() {
        for bank in [false, true] {
            let text = scenario_text(8, 100, bank);
            let s = Scenario::parse(std::path::Path::new("bank.toml"), &text).unwrap();
            assert_eq!(s.diagnosers.len(), usize::from(bank));
            plan(&s).unwrap();
        }
    }
}
