//! The diagnosis figures of a run: when each injected fault was detected, what it was isolated
//! as, and the false alarms.
//!
//! * A fault's window runs from its start to the next fault's start (or the end of the run). It
//!   is detected at the first step of its window with an alarm of any bank, and first isolated as
//!   the first single channel a bank of its class names in its window (`first_isolation_correct`
//!   when that is its own channel).
//! * Isolation over time: every decided step of the window at which the fault acts is counted as
//!   isolated correctly (a bank of its class names its channel), as another channel, as
//!   "unknown" (alarms that match no single channel) or in no alarm. The fault is `correct` when
//!   the correct share of its active time reaches the scenario's `isolated_fraction` (0.9 by
//!   default): a residual that returns to zero under a bias (a UIO's, in steady state) leaves the
//!   fault unisolated for most of its time, however right its first alarm was.
//! * With a GLR test beside the evaluation, the correctly isolated time is split by the test whose
//!   alarms made the decision ([`crate::DecidedBy`]): the evaluation's alone, the GLR's alone,
//!   each alone (both), or only the two together.
//! * Fault-free steps are those before the first fault starts (all of them in a run without
//!   faults) from the bank's first decided step on. An alarm there is false; `false_alarms` counts
//!   the episodes (an alarm switching on), `false_alarm_steps` the steps.
//! * Per residual, the fraction of fault-free steps whose evaluation exceeds its threshold: for a
//!   χ² threshold, the measured false-alarm probability against the one asked for.

use serde::{Deserialize, Serialize};

use crate::decide::{DecidedBy, Isolation, Monitor};
use crate::spec::Channels;

/// An injected fault, as the figures need it.
#[derive(Debug, Clone)]
pub struct FaultInfo {
    /// Its name.
    pub name: String,
    /// The class of its target.
    pub channels: Channels,
    /// Its channel (0-based).
    pub channel: usize,
    /// When it first acts, s.
    pub start: f64,
    /// The [on, off) steps it acts in (off = u64::MAX for no end).
    pub active: Vec<(u64, u64)>,
}

/// One fault's figures.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct FaultFigure {
    /// Name.
    pub name: String,
    /// When it started, s.
    pub start: f64,
    /// The first alarm in its window, s.
    pub detected_at: Option<f64>,
    /// detected_at − start, s.
    pub delay: Option<f64>,
    /// The fault (or channel) the banks named.
    pub isolated_as: Option<String>,
    /// When the isolation was made, s.
    pub isolated_at: Option<f64>,
    /// Whether that first isolation named the fault's own channel.
    pub first_isolation_correct: bool,
    /// Decided time in its window while it acted, s.
    pub active_time: f64,
    /// Of which isolated as its own channel, s.
    pub isolated_correctly_time: f64,
    /// … isolated as another channel, s.
    pub isolated_otherwise_time: f64,
    /// … in alarm matching no single channel ("unknown"), s.
    pub unknown_time: f64,
    /// … in no alarm, s.
    pub no_alarm_time: f64,
    /// isolated_correctly_time / active_time.
    pub isolated_fraction: Option<f64>,
    /// Whether isolated_fraction reached the scenario's `isolated_fraction`.
    pub correct: bool,
    /// With a GLR test: the correctly isolated time by the test that made the decisions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub isolated_by: Option<IsolatedBy>,
}

/// A correctly isolated time split by the test whose alarms made each decision, s.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Default)]
pub struct IsolatedBy {
    /// The evaluation's alarms alone.
    pub evaluation: f64,
    /// The GLR's alarms alone.
    pub glr: f64,
    /// Each test's alarms alone.
    pub both: f64,
    /// Only the two together.
    pub combined: f64,
}

/// One residual's behaviour without faults.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ResidualFigure {
    /// `<diagnoser>-<i>`.
    pub residual: String,
    /// Its threshold.
    pub threshold: f64,
    /// The false-alarm probability asked for (χ² thresholds).
    pub asked_false_alarm: Option<f64>,
    /// Fault-free steps decided.
    pub fault_free_steps: u64,
    /// How many of them exceeded the threshold.
    pub exceedances: u64,
    /// exceedances / fault_free_steps.
    pub exceedance_rate: Option<f64>,
    /// The largest evaluation J on those steps (what a calibrated threshold is made from).
    pub max_fault_free_evaluation: Option<f64>,
}

/// The `diagnosis` of summary.json.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Diagnosis {
    /// Alarm episodes while no fault acted.
    pub false_alarms: u64,
    /// Steps in alarm while no fault acted.
    pub false_alarm_steps: u64,
    /// Fault-free time decided, s.
    pub fault_free_time: f64,
    /// The share of its active time a fault must be isolated correctly for to be `correct`.
    pub required_fraction: f64,
    /// Per injected fault, in start order.
    pub faults: Vec<FaultFigure>,
    /// Per residual.
    pub residuals: Vec<ResidualFigure>,
}

/// How one active, decided step of a fault was isolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    Correct,
    Otherwise,
    Unknown,
    NoAlarm,
}

/// Accumulates the figures step by step.
#[derive(Debug, Clone)]
pub struct Judge {
    dt: f64,
    /// The share of a fault's active time it must be isolated correctly for to count as correct.
    fraction: f64,
    /// Per fault: steps counted as [correct, otherwise, unknown, no alarm].
    verdicts: Vec<[u64; 4]>,
    /// Per fault: correct steps decided by [evaluation, GLR, both, combined]; `None` without a
    /// GLR test in the run.
    decided: Option<Vec<[u64; 4]>>,
    faults: Vec<FaultInfo>,
    /// [start, end) step of each fault's window.
    windows: Vec<(u64, u64)>,
    first_fault: u64,
    figures: Vec<FaultFigure>,
    false_alarms: u64,
    false_alarm_steps: u64,
    fault_free_steps: u64,
    was_alarm: bool,
    /// Per monitor, per member: (fault-free steps, exceedances).
    counts: Vec<Vec<(u64, u64)>>,
    /// Per monitor, per member: the largest J on fault-free decided steps.
    max_eval: Vec<Vec<f64>>,
}

impl Judge {
    /// For a run with these faults and monitors; a fault counts as correctly isolated when it is
    /// for at least `fraction` of its active time.
    pub fn new(mut faults: Vec<FaultInfo>, monitors: &[Monitor], dt: f64, fraction: f64) -> Self {
        faults.sort_by(|a, b| a.start.total_cmp(&b.start));
        let starts: Vec<u64> = faults
            .iter()
            .map(|f| lti::signal::first_sample_from(f.start, dt))
            .collect();
        let windows = starts
            .iter()
            .map(|&s| {
                (
                    s,
                    starts
                        .iter()
                        .copied()
                        .filter(|&t| t > s)
                        .min()
                        .unwrap_or(u64::MAX),
                )
            })
            .collect();
        let figures = faults
            .iter()
            .map(|f| FaultFigure {
                name: f.name.clone(),
                start: f.start,
                detected_at: None,
                delay: None,
                isolated_as: None,
                isolated_at: None,
                first_isolation_correct: false,
                active_time: 0.0,
                isolated_correctly_time: 0.0,
                isolated_otherwise_time: 0.0,
                unknown_time: 0.0,
                no_alarm_time: 0.0,
                isolated_fraction: None,
                correct: false,
                isolated_by: None,
            })
            .collect();
        Judge {
            dt,
            fraction,
            verdicts: vec![[0; 4]; faults.len()],
            decided: monitors
                .iter()
                .any(Monitor::has_glr)
                .then(|| vec![[0; 4]; faults.len()]),
            first_fault: starts.first().copied().unwrap_or(u64::MAX),
            faults,
            windows,
            figures,
            false_alarms: 0,
            false_alarm_steps: 0,
            fault_free_steps: 0,
            was_alarm: false,
            counts: monitors
                .iter()
                .map(|m| vec![(0, 0); m.thresholds.len()])
                .collect(),
            max_eval: monitors
                .iter()
                .map(|m| vec![f64::NEG_INFINITY; m.thresholds.len()])
                .collect(),
        }
    }

    /// Takes step k's decisions.
    pub fn push(&mut self, k: u64, monitors: &[Monitor]) {
        let t = k as f64 * self.dt;
        let any = monitors.iter().any(|m| m.alarms.iter().any(|&a| a));
        if k < self.first_fault {
            let decided = monitors.iter().any(|m| k >= m.start_step);
            if decided {
                self.fault_free_steps += 1;
            }
            if any {
                self.false_alarm_steps += 1;
                if !self.was_alarm {
                    self.false_alarms += 1;
                }
            }
            for ((m, counts), max) in monitors
                .iter()
                .zip(&mut self.counts)
                .zip(&mut self.max_eval)
            {
                if k >= m.start_step {
                    for ((c, &e), (top, &j)) in counts
                        .iter_mut()
                        .zip(&m.exceed)
                        .zip(max.iter_mut().zip(&m.evals))
                    {
                        c.0 += 1;
                        c.1 += u64::from(e);
                        *top = top.max(j);
                    }
                }
            }
        }
        self.was_alarm = any;
        for (i, f) in self.faults.iter().enumerate() {
            let (from, to) = self.windows[i];
            if k < from || k >= to {
                continue;
            }
            let fig = &mut self.figures[i];
            if any && fig.detected_at.is_none() {
                fig.detected_at = Some(t);
                fig.delay = Some(t - f.start);
            }
            let ours = || monitors.iter().filter(|m| m.channels == f.channels);
            if fig.isolated_as.is_none() {
                for m in ours() {
                    if let Isolation::Channel(j) = m.isolation {
                        // Name the fault on that channel: this one if it is, else another fault
                        // of the run there, else the channel itself.
                        let named = if j == f.channel {
                            f.name.clone()
                        } else {
                            self.faults
                                .iter()
                                .find(|g| g.channels == m.channels && g.channel == j)
                                .map_or_else(
                                    || m.label(j).unwrap_or("?").to_string(),
                                    |g| g.name.clone(),
                                )
                        };
                        fig.isolated_as = Some(named);
                        fig.isolated_at = Some(t);
                        fig.first_isolation_correct = j == f.channel;
                        break;
                    }
                }
            }
            // Isolation over the fault's active, decided time: the best any bank of its class says.
            let decided = ours().any(|m| k >= m.start_step);
            if decided && f.active.iter().any(|&(on, off)| k >= on && k < off) {
                let (verdict, by) = ours()
                    .map(|m| {
                        let v = match m.isolation {
                            Isolation::Channel(j) if j == f.channel => Verdict::Correct,
                            Isolation::Channel(_) => Verdict::Otherwise,
                            Isolation::Unknown => Verdict::Unknown,
                            Isolation::None => Verdict::NoAlarm,
                        };
                        (v, m.decided_by)
                    })
                    .min_by_key(|(v, _)| *v as u8)
                    .unwrap_or((Verdict::NoAlarm, DecidedBy::None));
                self.verdicts[i][verdict as usize] += 1;
                if let (Some(decided), Verdict::Correct) = (&mut self.decided, verdict) {
                    match by {
                        DecidedBy::Evaluation => decided[i][0] += 1,
                        DecidedBy::Glr => decided[i][1] += 1,
                        DecidedBy::Both => decided[i][2] += 1,
                        DecidedBy::Combined => decided[i][3] += 1,
                        DecidedBy::None => {}
                    }
                }
            }
        }
    }

    /// The figures.
    pub fn finish(self, monitors: &[Monitor]) -> Diagnosis {
        let residuals = monitors
            .iter()
            .zip(self.counts.iter().zip(&self.max_eval))
            .flat_map(|(m, (counts, max))| {
                let alpha = m.asked_false_alarm;
                counts
                    .iter()
                    .enumerate()
                    .map(move |(i, &(steps, exc))| ResidualFigure {
                        residual: format!("{}-{}", m.name, i + 1),
                        threshold: m.thresholds[i],
                        asked_false_alarm: alpha,
                        fault_free_steps: steps,
                        exceedances: exc,
                        exceedance_rate: (steps > 0).then(|| exc as f64 / steps as f64),
                        max_fault_free_evaluation: (steps > 0).then_some(max[i]),
                    })
            })
            .collect();
        let mut faults = self.figures;
        for (fig, v) in faults.iter_mut().zip(&self.verdicts) {
            let steps: u64 = v.iter().sum();
            fig.active_time = steps as f64 * self.dt;
            fig.isolated_correctly_time = v[0] as f64 * self.dt;
            fig.isolated_otherwise_time = v[1] as f64 * self.dt;
            fig.unknown_time = v[2] as f64 * self.dt;
            fig.no_alarm_time = v[3] as f64 * self.dt;
            fig.isolated_fraction = (steps > 0).then(|| v[0] as f64 / steps as f64);
            fig.correct = fig.isolated_fraction.is_some_and(|x| x >= self.fraction);
        }
        if let Some(decided) = &self.decided {
            for (fig, d) in faults.iter_mut().zip(decided) {
                fig.isolated_by = Some(IsolatedBy {
                    evaluation: d[0] as f64 * self.dt,
                    glr: d[1] as f64 * self.dt,
                    both: d[2] as f64 * self.dt,
                    combined: d[3] as f64 * self.dt,
                });
            }
        }
        Diagnosis {
            false_alarms: self.false_alarms,
            false_alarm_steps: self.false_alarm_steps,
            fault_free_time: self.fault_free_steps as f64 * self.dt,
            required_fraction: self.fraction,
            faults,
            residuals,
        }
    }
}
