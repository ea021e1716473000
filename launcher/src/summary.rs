//! The run summary: what `summary.json` holds and the table the launcher prints.

use std::collections::BTreeMap;
use std::path::Path;

use lti::eig::sig;
use serde::Serialize;

use crate::plan::Plan;
use crate::run::{Options, Stop};
use recording::signals::figure;
use recording::write::{Latency, Metrics, Percentiles};
use scenario::Scenario;

/// One observer's line.
#[derive(Debug, Clone, Serialize)]
pub struct ObserverSummary {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: String,
    /// max |x − x̂| over the last quarter of the steps completed (null: fewer than 4 steps).
    pub tail_max_abs_error: Option<f64>,
    /// max |y − Cx̂| over the last quarter of the steps completed.
    pub tail_max_abs_residual: Option<f64>,
    /// max |x − x̂| over the run (null where the data holds no x: see `Summary::unmeasured`).
    pub max_abs_error: Option<f64>,
    /// max |x − x̂| at the last step.
    pub final_abs_error: Option<f64>,
    /// max |w − ŵ| over the tail, for an observer that estimates the unknown inputs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tail_max_abs_input_error: Option<f64>,
    /// In a run with faults, the figures before the first fault: its effect is in the run's tail.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fault_free: Option<FaultFree>,
    /// Continuous error-dynamics eigenvalues, [re, im].
    pub poles: Vec<[f64; 2]>,
    /// Sampled observer eigenvalues, [re, im].
    pub discrete_poles: Vec<[f64; 2]>,
}

/// An observer's figures over the fault-free stretch before the first fault
/// ([`recording::write::FaultFree`]), the errors null where the data holds no x.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct FaultFree {
    /// How long the stretch is, s.
    pub until: f64,
    /// max |x − x̂| over its last quarter.
    pub tail_max_abs_error: Option<f64>,
    /// max |y − Cx̂| over its last quarter.
    pub tail_max_abs_residual: f64,
    /// max |x − x̂| over the stretch.
    pub max_abs_error: Option<f64>,
}

/// One `[expect]` entry, checked.
#[derive(Debug, Clone, Serialize)]
pub struct Expectation {
    /// What, e.g. "tail_max_abs_error.uio".
    pub what: String,
    /// The bound.
    pub limit: f64,
    /// The value reached (null when the run did not complete or the figure does not exist).
    pub value: Option<f64>,
    /// value ≤ limit, in a run that completed all its steps: a run that stopped early has only
    /// part of its tail, and no expectation can hold for it.
    pub ok: bool,
}

/// Latency percentiles.
#[derive(Debug, Clone, Serialize)]
pub struct LatencySummary {
    /// Full step: plant sends y_k → plant has u_k.
    pub step: Percentiles,
    /// Per hop.
    pub hops: BTreeMap<String, Percentiles>,
}

/// The summary of a run.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// "processes" or "in-process".
    pub mode: String,
    /// Wait strategy (processes mode).
    pub wait: String,
    /// Sample period, s.
    pub dt: f64,
    /// Scenario duration, s.
    pub duration: f64,
    /// Steps completed.
    pub steps: u64,
    /// Steps the scenario asks for.
    pub steps_planned: u64,
    /// The scenario's `tail`, s (null: the default, the last quarter of the steps completed).
    pub tail_s: Option<f64>,
    /// The first step of the tail the figures were taken over (null: fewer than 4 steps).
    pub tail_from_step: Option<u64>,
    /// Wall-clock time of the run, s.
    pub wall_s: f64,
    /// steps / wall_s.
    pub steps_per_s: f64,
    /// Per observer.
    pub observers: Vec<ObserverSummary>,
    /// max |x̂_a − x̂_b| over the run, "a/b" → value.
    pub differences: BTreeMap<String, f64>,
    /// Closed-loop eigenvalues eig(A − BG), [re, im] (with a controller).
    pub closed_loop_poles: Option<Vec<[f64; 2]>>,
    /// Latency, ns.
    pub latency_ns: LatencySummary,
    /// `[expect]`, checked.
    pub expectations: Vec<Expectation>,
    /// Why the run stopped early, if it did.
    pub stopped: Option<String>,
    /// Detection, isolation and false alarms (with a `[[diagnoser]]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diagnosis: Option<diagnosis::Diagnosis>,
    /// The noise generator's seed.
    pub seed: u64,
    /// How a paced run (`--realtime`) kept its schedule.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub realtime: Option<crate::run::RealtimeFigures>,
    /// The recording.
    pub recording: Option<String>,
    /// The recording's digest, entity → XXH64 (see `recording::digest`), also stored in the
    /// recording, against which readers detect a damaged file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recording_digest: Option<BTreeMap<String, String>>,
    /// `[plant.replay]`: the data file, its rows, the grid samples taken from it, those held by
    /// `resample = "zoh"`, the cells held by `missing = "hold"`, and whether x is in the data
    /// (`states: false`: the recorded "errors" are −x̂, not estimation errors).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub replay: Option<serde_json::Value>,
    /// The design's warnings (the ones `uio-launcher design` prints), so the figures carry them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// `[plant.operating_point]`: the point the design model is linearised at; every figure
    /// above is in the plant's own (absolute) units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operating_point: Option<lti::OperatingPoint>,
    /// The figures a replay's data cannot give, each with why (a log without x has no
    /// estimation error: x − x̂ would be −x̂); those figures are null and print as "—".
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unmeasured: Vec<String>,
}

impl Summary {
    /// Gathers the summary of a run.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        s: &Scenario,
        plan: &Plan,
        opts: &Options,
        m: &Metrics,
        lat: &Latency,
        wall_s: f64,
        stop: &Stop,
        rrd: Option<&Path>,
        diagnosis: Option<diagnosis::Diagnosis>,
    ) -> Self {
        let observers: Vec<ObserverSummary> = s
            .observers
            .iter()
            .zip(&m.observers)
            .zip(&plan.observers)
            .map(|((o, f), (_, d))| ObserverSummary {
                name: o.name.clone(),
                kind: o.kind().into(),
                tail_max_abs_error: f.tail_max_abs_error,
                tail_max_abs_residual: f.tail_max_abs_residual,
                max_abs_error: Some(f.max_abs_error),
                final_abs_error: Some(f.final_abs_error),
                tail_max_abs_input_error: f.tail_max_abs_input_error,
                fault_free: f.fault_free.map(|f| FaultFree {
                    until: f.until,
                    tail_max_abs_error: Some(f.tail_max_abs_error),
                    tail_max_abs_residual: f.tail_max_abs_residual,
                    max_abs_error: Some(f.max_abs_error),
                }),
                poles: d
                    .as_ref()
                    .map_or_else(Vec::new, |d| lti::re_im(&d.report.poles)),
                discrete_poles: d
                    .as_ref()
                    .map_or_else(Vec::new, |d| lti::re_im(&d.report.discrete_poles)),
            })
            .collect();
        let names = s.observer_names();
        let differences = m
            .differences
            .iter()
            .map(|((a, b), d)| (format!("{}/{}", names[*a], names[*b]), *d))
            .collect();
        let stopped = match stop {
            Stop::Completed => None,
            Stop::Diverged(w) => Some(format!("diverged: {w}")),
            Stop::Interrupted(sig) => Some(format!("interrupted by {sig}")),
            Stop::Failed(w) => Some(format!("failed: {w}")),
        };
        let mut summary = Summary {
            scenario: s.name.clone(),
            mode: opts.mode.name().into(),
            wait: opts.wait.to_string(),
            dt: s.dt,
            duration: s.duration,
            steps: m.steps,
            steps_planned: s.steps,
            tail_s: s.tail,
            tail_from_step: m.tail_start(),
            wall_s,
            steps_per_s: m.steps as f64 / wall_s.max(1e-9),
            observers,
            differences,
            closed_loop_poles: plan.feedback.as_ref().map(|f| lti::re_im(&f.closed_loop)),
            latency_ns: LatencySummary {
                step: lat.step_percentiles(),
                hops: lat.hop_percentiles().into_iter().collect(),
            },
            expectations: Vec::new(),
            stopped,
            diagnosis,
            seed: s.seed,
            realtime: None,
            recording: rrd.map(|p| p.display().to_string()),
            recording_digest: None,
            replay: None,
            warnings: plan.warnings.clone(),
            operating_point: s.operating_point.clone(),
            unmeasured: Vec::new(),
        };
        summary.expectations = summary.check(s, matches!(stop, Stop::Completed));
        summary
    }

    /// Takes a replay's facts (`uio-replay-plant --check`): where its data holds no x (`states`
    /// false) every state-error figure becomes null, where it holds no w (`disturbances` false)
    /// every |w − ŵ|, each with its reason in `unmeasured`; the expectations are checked again.
    pub fn with_replay(&mut self, s: &Scenario, facts: serde_json::Value, completed: bool) {
        let has = |k: &str| {
            facts
                .get(k)
                .and_then(serde_json::Value::as_bool)
                .unwrap_or(true)
        };
        let file = facts
            .get("file")
            .and_then(serde_json::Value::as_str)
            .unwrap_or("the data")
            .to_string();
        if !has("states") {
            for o in &mut self.observers {
                (o.tail_max_abs_error, o.max_abs_error, o.final_abs_error) = (None, None, None);
                if let Some(f) = &mut o.fault_free {
                    (f.tail_max_abs_error, f.max_abs_error) = (None, None);
                }
            }
            self.unmeasured.push(format!("max|e|: {file} holds no states (plant.replay.states), so x − x̂ would be −x̂, not an estimation error"));
        }
        if !has("disturbances")
            && self
                .observers
                .iter()
                .any(|o| o.tail_max_abs_input_error.is_some())
        {
            for o in &mut self.observers {
                o.tail_max_abs_input_error = None;
            }
            self.unmeasured.push(format!("max|w − ŵ|: {file} holds no unknown inputs (plant.replay.disturbances), so w − ŵ would be −ŵ"));
        }
        self.replay = Some(facts);
        self.expectations = self.check(s, completed);
    }

    fn observer(&self, name: &str) -> Option<&ObserverSummary> {
        self.observers.iter().find(|o| o.name == name)
    }

    /// Checks the scenario's `[expect]` table against this run; none holds unless it `completed`.
    pub fn check(&self, s: &Scenario, completed: bool) -> Vec<Expectation> {
        let e = &s.expect;
        let mut out = Vec::new();
        let mut add = |what: String, limit: f64, value: Option<f64>| {
            let value = value.filter(|_| completed);
            out.push(Expectation {
                what,
                limit,
                value,
                ok: value.is_some_and(|v| v <= limit),
            });
        };
        for (name, &limit) in &e.tail_max_abs_error {
            add(
                format!("tail_max_abs_error.{name}"),
                limit,
                self.observer(name).and_then(|o| o.tail_max_abs_error),
            );
        }
        for (name, &limit) in &e.tail_max_abs_residual {
            add(
                format!("tail_max_abs_residual.{name}"),
                limit,
                self.observer(name).and_then(|o| o.tail_max_abs_residual),
            );
        }
        for (pair, &limit) in &e.max_abs_difference {
            let (a, b) = pair.split_once('/').unwrap_or((pair, pair));
            let v = self
                .differences
                .get(pair)
                .or_else(|| self.differences.get(&format!("{b}/{a}")))
                .copied();
            add(format!("max_abs_difference.{pair}"), limit, v);
        }
        for (pair, &limit) in &e.tail_error_ratio {
            let (a, b) = pair.split_once('/').unwrap_or((pair, pair));
            let v = match (self.observer(a), self.observer(b)) {
                (Some(x), Some(y)) => x
                    .tail_max_abs_error
                    .zip(y.tail_max_abs_error)
                    .map(|(a, b)| a / b),
                _ => None,
            };
            add(format!("tail_error_ratio.{pair}"), limit, v);
        }
        let d = self.diagnosis.as_ref();
        for (name, &limit) in &e.detection_delay {
            let v = d
                .and_then(|d| d.faults.iter().find(|f| &f.name == name))
                .and_then(|f| f.delay);
            add(format!("detection_delay.{name}"), limit, v);
        }
        if e.correct_isolation == Some(true) {
            let wrong = d.map(|d| d.faults.iter().filter(|f| !f.correct).count() as f64);
            add("faults_not_isolated_correctly".into(), 0.0, wrong);
        }
        if e.first_isolation_correct == Some(true) {
            let wrong = d.map(|d| {
                d.faults
                    .iter()
                    .filter(|f| !f.first_isolation_correct)
                    .count() as f64
            });
            add("faults_first_isolated_wrongly".into(), 0.0, wrong);
        }
        if let Some(limit) = e.false_alarms {
            add(
                "false_alarms".into(),
                limit as f64,
                d.map(|d| d.false_alarms as f64),
            );
        }
        out
    }

    /// Whether every expectation holds.
    pub fn expectations_met(&self) -> bool {
        self.expectations.iter().all(|e| e.ok)
    }

    /// Writes the JSON atomically (a temporary file renamed into place, `outputs::write`).
    pub fn write(&self, path: &Path) -> Result<(), String> {
        let text = serde_json::to_string_pretty(self).expect("summary serialises");
        outputs::write_bytes(path, (text + "\n").as_bytes())
    }

    /// The table printed after a run.
    // one job: the table printed after a run, section by section in print order.
    pub fn table(&self) -> String {
        let mut t = String::new();
        let us = |ns: u64| format!("{:.1} µs", ns as f64 / 1000.0);
        t += &format!(
            "{} ({}, {} of {} steps of {} s = {}, {:.2} s wall, {} steps/s)\n",
            self.scenario,
            self.mode,
            self.steps,
            self.steps_planned,
            self.dt,
            lti::units::readable(self.steps as f64 * self.dt),
            self.wall_s,
            sig(self.steps_per_s.round())
        );
        let tail = match (self.steps < self.steps_planned, self.tail_s) {
            (true, None) => "tail: last quarter of the steps completed".to_string(),
            (true, Some(t)) => format!(
                "tail: last {} of the steps completed",
                lti::units::readable(t)
            ),
            (false, None) => "tail: last quarter".to_string(),
            (false, Some(t)) => format!("tail: last {}", lti::units::readable(t)),
        };
        t += &format!(
            "  {:<14} {:<16} {:>14} {:>14}   ({tail})\n",
            "observer", "kind", "tail max|e|", "tail max|r|"
        );
        for o in &self.observers {
            t += &format!(
                "  {:<14} {:<16} {:>14} {:>14}\n",
                o.name,
                o.kind,
                figure(o.tail_max_abs_error),
                figure(o.tail_max_abs_residual)
            );
            let unknown_w = self.unmeasured.iter().any(|u| u.starts_with("max|w"));
            if o.tail_max_abs_input_error.is_some() || unknown_w {
                t += &format!(
                    "  {:<31} {:>14}   (its unknown-input estimate)\n",
                    "",
                    format!("max|w − ŵ| {}", figure(o.tail_max_abs_input_error))
                );
            }
            if let Some(ff) = &o.fault_free {
                t += &format!(
                    "  {:<31} {:>14} {:>14}   (tail of the fault-free {} s before the first fault)\n",
                    "",
                    figure(ff.tail_max_abs_error),
                    figure(Some(ff.tail_max_abs_residual)),
                    sig(ff.until)
                );
            }
        }
        for why in &self.unmeasured {
            t += &format!("  — {why}\n");
        }
        let p = &self.latency_ns.step;
        if p.max > 0 {
            t += &format!(
                "  step latency   p50 {}  p90 {}  p99 {}  p99.9 {}  max {}\n",
                us(p.p50),
                us(p.p90),
                us(p.p99),
                us(p.p999),
                us(p.max)
            );
            for (hop, p) in &self.latency_ns.hops {
                t += &format!(
                    "    {:<30} p50 {}  p99 {}  max {}\n",
                    hop,
                    us(p.p50),
                    us(p.p99),
                    us(p.max)
                );
            }
        }
        if let Some(r) = &self.realtime {
            let off = 100.0 * (r.paced_wall_s / r.scheduled_s.max(1e-12) - 1.0);
            t += &format!(
                "  real time: {} s paced for {} s scheduled ({off:+.2} %), step period {} s\n",
                sig(r.paced_wall_s),
                sig(r.scheduled_s),
                sig(r.period_s)
            );
            t += &if r.overruns == 0 {
                "  every step ended by its deadline\n".to_string()
            } else {
                format!(
                    "  cannot keep up: {} of {} steps ended after their deadline (latest by {:.1} µs)\n",
                    r.overruns, r.steps, r.max_lateness_us
                )
            };
        }
        for w in self.warnings.iter().filter(|w| w.starts_with("diagnoser ")) {
            t += &format!("  note: {w}\n");
        }
        if let Some(d) = &self.diagnosis {
            t += &format!(
                "  diagnosis: {} false alarm(s) over {} s fault-free ({} step(s) in alarm)\n",
                d.false_alarms,
                sig(d.fault_free_time),
                d.false_alarm_steps
            );
            for f in &d.faults {
                let at =
                    |v: Option<f64>| v.map_or_else(|| "—".to_string(), |v| format!("{v:.4} s"));
                t += &format!(
                    "    {:<20} start {:>9}  detected {:>11}  first isolated as {:<16} {}\n",
                    f.name,
                    format!("{} s", f.start),
                    at(f.detected_at),
                    f.isolated_as.as_deref().unwrap_or("—"),
                    if f.isolated_as.is_none() {
                        ""
                    } else if f.first_isolation_correct {
                        "(right)"
                    } else {
                        "(wrong)"
                    }
                );
                let pct = |x: f64| {
                    if f.active_time > 0.0 {
                        format!("{:.1} %", 100.0 * x / f.active_time)
                    } else {
                        "—".into()
                    }
                };
                t += &format!(
                    "    {:<20} over its {} s: isolated correctly {}, as another channel {}, unknown {}, no alarm {}: {}\n",
                    "",
                    sig(f.active_time),
                    pct(f.isolated_correctly_time),
                    pct(f.isolated_otherwise_time),
                    pct(f.unknown_time),
                    pct(f.no_alarm_time),
                    if f.correct {
                        "correct".to_string()
                    } else {
                        format!(
                            "NOT isolated (needs ≥ {} % of its time)",
                            sig(100.0 * d.required_fraction)
                        )
                    }
                );
                if let Some(by) = &f.isolated_by {
                    t += &format!(
                        "    {:<20} isolated correctly by the evaluation's alarms alone {}, the GLR's alone {}, each alone {}, only both together {}\n",
                        "",
                        pct(by.evaluation),
                        pct(by.glr),
                        pct(by.both),
                        pct(by.combined),
                    );
                }
            }
        }
        for e in &self.expectations {
            t += &match e.value {
                Some(v) => format!(
                    "  expect {} ≤ {:.3e}: {:.3e} {}\n",
                    e.what,
                    e.limit,
                    v,
                    if e.ok { "ok" } else { "MISSED" }
                ),
                None if self.stopped.is_some() => format!(
                    "  expect {} ≤ {:.3e}: not checked (the run did not complete)\n",
                    e.what, e.limit
                ),
                None => format!(
                    "  expect {} ≤ {:.3e}: MISSED (no such figure)\n",
                    e.what, e.limit
                ),
            };
        }
        if let Some(why) = &self.stopped {
            t += &format!("  stopped: {why}\n");
        }
        t
    }
}
