//! Decisions per step: alarms from evaluations and thresholds, isolation by the structure matrix.
//!
//! Residual i is in alarm once J_i has exceeded its threshold at `persistence` consecutive
//! samples, and until it no longer does. The alarm pattern a ∈ {0, 1}^m is then matched against
//! the columns of the structure matrix: channel j is isolated when a equals column j, and the
//! fault is "unknown" when a matches no column (or several). Before `ignore_before` nothing is
//! decided: the observers start from zero and their start-up transient is no fault.
//!
//! With a GLR test ([`crate::glr`]) beside the evaluation, a member's alarm is either test's
//! (the GLR confirms a change after the same persistence and holds it until its end is seen or
//! its onset leaves the window), and each decision says which test made it: the evaluation's
//! alarms alone, the GLR's alone, each alone (both), or only the two together.

use crate::bank::Bank;
use crate::evaluate::Evaluator;
use crate::glr::Glr;

/// The decision of one step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Isolation {
    /// No alarm.
    None,
    /// The alarm pattern is channel j's signature (0-based index in its class: u_{j+1}, y_{j+1}…).
    Channel(usize),
    /// Alarms that match no single channel.
    Unknown,
}

impl Isolation {
    /// As recorded: 0 none, j + 1 for channel j, −1 unknown.
    pub fn code(self) -> f64 {
        match self {
            Isolation::None => 0.0,
            Isolation::Channel(j) => (j + 1) as f64,
            Isolation::Unknown => -1.0,
        }
    }
}

/// Which test's alarms made a step's isolation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecidedBy {
    /// No alarm.
    None,
    /// The evaluation's alarms alone give it (and the GLR's alone do not).
    Evaluation,
    /// The GLR's alarms alone give it (and the evaluation's alone do not).
    Glr,
    /// Each test's alarms alone give it.
    Both,
    /// Only the two tests' alarms together give it.
    Combined,
}

impl DecidedBy {
    /// As recorded: 0 none, 1 evaluation, 2 GLR, 3 both, 4 combined.
    pub fn code(self) -> f64 {
        self as u8 as f64
    }
}

/// One bank's decision logic over a run.
#[derive(Debug, Clone)]
pub struct Monitor {
    /// The diagnoser's name.
    pub name: String,
    /// Its channel class.
    pub channels: crate::Channels,
    /// Labels of the channels it watches.
    pub labels: Vec<String>,
    /// Their indices in the class (column j of the structure is channel `ids[j]`).
    pub ids: Vec<usize>,
    /// The structure matrix.
    pub structure: Vec<Vec<u8>>,
    /// Index of each member among the run's observers.
    observers: Vec<usize>,
    outputs: Vec<Vec<usize>>,
    /// The false-alarm probability per sample the χ² thresholds were set for, if they were.
    pub asked_false_alarm: Option<f64>,
    evaluators: Vec<Evaluator>,
    /// Per member.
    pub thresholds: Vec<f64>,
    persistence: u32,
    /// The first step decided.
    pub start_step: u64,
    counts: Vec<u32>,
    /// This step's residual per member (on its outputs).
    pub residuals: Vec<Vec<f64>>,
    /// This step's J per member.
    pub evals: Vec<f64>,
    /// J > threshold, per member, this step.
    pub exceed: Vec<bool>,
    /// Alarm per member, this step.
    pub alarms: Vec<bool>,
    /// This step's isolation.
    pub isolation: Isolation,
    /// Per member, its GLR test, if the bank has one.
    glr: Vec<Option<Glr>>,
    /// Whether any member has one.
    has_glr: bool,
    /// This step's GLR statistic g per member (0 without a GLR test).
    pub glr_stats: Vec<f64>,
    /// The GLR thresholds per member (∞ without a GLR test).
    pub glr_thresholds: Vec<f64>,
    /// The evaluation's alarm per member, this step.
    pub evaluation_alarms: Vec<bool>,
    /// The GLR's alarm per member, this step.
    pub glr_alarms: Vec<bool>,
    /// Which test made this step's isolation.
    pub decided_by: DecidedBy,
}

impl Monitor {
    /// For `bank`, whose member i is observer `observers[i]` of the run.
    pub fn new(bank: &Bank, observers: Vec<usize>, dt: f64) -> Self {
        let m = bank.members.len();
        Monitor {
            name: bank.spec.name.clone(),
            channels: bank.spec.channels,
            labels: bank.channels.clone(),
            ids: bank.ids.clone(),
            structure: bank.structure.clone(),
            observers,
            outputs: bank.members.iter().map(|mb| mb.outputs.clone()).collect(),
            asked_false_alarm: if let crate::Threshold::FalseAlarm(a) = bank.spec.threshold {
                Some(a)
            } else {
                None
            },
            evaluators: bank
                .members
                .iter()
                .map(|mb| Evaluator::new(bank.spec.evaluation, mb.covariance.as_ref()))
                .collect(),
            thresholds: bank.members.iter().map(|mb| mb.threshold).collect(),
            persistence: bank.spec.persistence.max(1),
            start_step: lti::signal::first_sample_from(bank.spec.ignore_before, dt),
            counts: vec![0; m],
            residuals: bank
                .members
                .iter()
                .map(|mb| vec![0.0; mb.outputs.len()])
                .collect(),
            evals: vec![0.0; m],
            exceed: vec![false; m],
            alarms: vec![false; m],
            isolation: Isolation::None,
            glr_thresholds: bank
                .members
                .iter()
                .map(|mb| mb.glr.as_ref().map_or(f64::INFINITY, |g| g.threshold))
                .collect(),
            glr: bank
                .members
                .iter()
                .map(|mb| {
                    let first = lti::signal::first_sample_from(bank.spec.ignore_before, dt);
                    mb.glr
                        .clone()
                        .map(|g| Glr::new(g, first, bank.spec.persistence))
                })
                .collect(),
            has_glr: bank.members.iter().any(|mb| mb.glr.is_some()),
            glr_stats: vec![0.0; m],
            evaluation_alarms: vec![false; m],
            glr_alarms: vec![false; m],
            decided_by: DecidedBy::None,
        }
    }

    /// Whether the bank runs a GLR test beside its evaluation.
    pub fn has_glr(&self) -> bool {
        self.has_glr
    }

    /// Step k, from every observer's residual y_k − Cx̂_k (as the run's figures computed them):
    /// each member's residual on its outputs, evaluations, alarms, isolation.
    pub fn step(&mut self, k: u64, residuals: &[Vec<f64>]) {
        let deciding = k >= self.start_step;
        for i in 0..self.observers.len() {
            let full = &residuals[self.observers[i]];
            for (r, &j) in self.residuals[i].iter_mut().zip(&self.outputs[i]) {
                *r = full[j];
            }
            let j = self.evaluators[i].push(&self.residuals[i]);
            self.evals[i] = j;
            self.exceed[i] = j > self.thresholds[i];
            self.counts[i] = if self.exceed[i] && deciding {
                self.counts[i].saturating_add(1)
            } else {
                0
            };
            self.evaluation_alarms[i] = self.counts[i] >= self.persistence;
            if let Some(glr) = &mut self.glr[i] {
                self.glr_stats[i] = glr.push(k, &self.residuals[i]);
                self.glr_alarms[i] = glr.alarm();
            }
            self.alarms[i] = self.evaluation_alarms[i] || self.glr_alarms[i];
        }
        self.isolation = self.isolate(&self.alarms);
        self.decided_by = if self.isolation == Isolation::None {
            DecidedBy::None
        } else if !self.has_glr {
            DecidedBy::Evaluation
        } else {
            let by_evaluation = self.isolate(&self.evaluation_alarms) == self.isolation;
            let by_glr = self.isolate(&self.glr_alarms) == self.isolation;
            match (by_evaluation, by_glr) {
                (true, true) => DecidedBy::Both,
                (true, false) => DecidedBy::Evaluation,
                (false, true) => DecidedBy::Glr,
                (false, false) => DecidedBy::Combined,
            }
        };
    }

    /// The label of channel `channel` (index in the class), if the bank watches it.
    pub fn label(&self, channel: usize) -> Option<&str> {
        self.ids
            .iter()
            .position(|&j| j == channel)
            .map(|j| self.labels[j].as_str())
    }

    /// The isolation an alarm pattern gives.
    fn isolate(&self, alarms: &[bool]) -> Isolation {
        if !alarms.iter().any(|&a| a) {
            return Isolation::None;
        }
        // The columns the pattern equals, counted without a list (this runs every step).
        let mut matches = (0..self.labels.len()).filter(|&j| {
            self.structure
                .iter()
                .zip(alarms)
                .all(|(row, &a)| (row[j] == 1) == a)
        });
        match (matches.next(), matches.next()) {
            (Some(j), None) => Isolation::Channel(self.ids[j]),
            _ => Isolation::Unknown,
        }
    }
}
