//! `uio-launcher inspect`: what a recording holds — its entities with their row counts and time
//! ranges — and the run's figures recomputed from the recorded data alone: per observer the
//! largest |x − x̂| and |y − Cx̂| over the tail (the last quarter of the steps completed), and the latency percentiles.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::read::Recording;
use crate::signals::figure;
use crate::tools::recorded_scenario;
use crate::write::{Latency, Percentiles, histogram, nan_max};

/// One entity.
#[derive(Debug, Clone, Serialize)]
pub struct EntityInfo {
    /// Entity path.
    pub path: String,
    /// Number of values.
    pub rows: usize,
    /// First and last step.
    pub steps: [i64; 2],
    /// First and last sim_time, s (when the sample period is known).
    pub sim_time: Option<[f64; 2]>,
}

/// One observer's figures.
#[derive(Debug, Clone, Serialize)]
pub struct ObserverFigures {
    /// Name.
    pub name: String,
    /// max |x − x̂| over the last quarter of the steps recorded (as the run's summary defines
    /// it, [`crate::write::tail`]); `None` with fewer than 4 steps.
    pub tail_max_abs_error: Option<f64>,
    /// max |y − Cx̂| over the same tail.
    pub tail_max_abs_residual: Option<f64>,
    /// max_k max_j |ŵ_j − w_j| over the same tail, each ŵ_k against the w_k recorded at its
    /// step (`None` for an observer that records no ŵ, or without a tail).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tail_max_abs_input_error: Option<f64>,
}

/// Latency percentiles recomputed from the recording, ns.
#[derive(Debug, Clone, Serialize)]
pub struct LatencyFigures {
    /// The step.
    pub step: Percentiles,
    /// Per hop, by the name the run gave it.
    pub hops: BTreeMap<String, Percentiles>,
}

/// What `inspect` reports.
#[derive(Debug, Clone, Serialize)]
pub struct Inspection {
    /// The file.
    pub file: String,
    /// Whether the writer finished (footer present, nothing truncated).
    pub complete: bool,
    /// Scenario name, if recorded.
    pub scenario: Option<String>,
    /// Steps the scenario asked for, if recorded.
    pub steps_planned: Option<u64>,
    /// Rows of x1 in the recording (fewer than the steps when it was thinned).
    pub steps_recorded: u64,
    /// Steps the run completed.
    pub steps_completed: u64,
    /// Every entity.
    pub entities: Vec<EntityInfo>,
    /// Per observer.
    pub observers: Vec<ObserverFigures>,
    /// Latency.
    pub latency_ns: LatencyFigures,
    /// Incompleteness and the like.
    pub warnings: Vec<String>,
}

/// Inspects a decoded recording.
pub fn inspect(file: &str, r: &Recording) -> Inspection {
    let scenario = recorded_scenario(r);
    let dt = scenario.as_ref().map(|s| s.dt);
    let steps_recorded = r
        .series
        .get(&crate::signals::state(0))
        .map_or(0, |s| s.values.len() as u64);
    // What the run completed: as its writer stored it, else (a killed writer's file) the last
    // step anything was recorded at — a thinned or filtered recording holds fewer rows.
    let last_step = r
        .series
        .values()
        .filter_map(|s| s.steps.last())
        .max()
        .map_or(0, |&k| k.max(-1) + 1) as u64;
    let steps_completed = r.steps_completed.unwrap_or(last_step);
    let steps_planned = scenario.as_ref().map(|s| s.steps);
    let mut warnings = Vec::new();
    if !r.complete {
        warnings.push(match &r.problem {
            Some(p) => format!("incomplete recording: {p}"),
            None => "incomplete recording: its writer did not finish (no footer)".to_string(),
        });
    }
    if let Some(planned) = steps_planned
        && steps_completed < planned
    {
        warnings.push(format!(
            "the run stopped early: {steps_completed} of {planned} steps completed"
        ));
    }
    let entities = r
        .series
        .iter()
        .map(|(path, s)| {
            let steps = [
                s.steps.first().copied().unwrap_or(0),
                s.steps.last().copied().unwrap_or(0),
            ];
            EntityInfo {
                path: path.clone(),
                rows: s.values.len(),
                steps,
                sim_time: dt.map(|dt| [steps[0] as f64 * dt, steps[1] as f64 * dt]),
            }
        })
        .collect();
    // The tail as the run defined it: its `tail`, else the last quarter of the steps it completed.
    let tail_start = crate::write::tail::tail_start(
        steps_completed,
        steps_planned.unwrap_or(steps_completed),
        scenario.as_ref().and_then(|s| s.tail_steps()),
    )
    .map(|s| s as i64);
    let tail_max = |prefix: &str| -> Option<f64> {
        let start = tail_start?;
        Some(
            r.series
                .iter()
                .filter(|(p, _)| p.starts_with(prefix))
                .flat_map(|(_, s)| {
                    s.steps
                        .iter()
                        .zip(&s.values)
                        .filter(|(k, _)| **k >= start)
                        .map(|(_, v)| v.abs())
                })
                .fold(0.0, nan_max),
        )
    };
    let observers = crate::signals::observers_of(r.series.keys(), scenario.as_ref())
        .into_iter()
        .map(|n| ObserverFigures {
            tail_max_abs_error: tail_max(&format!("/observer/{n}/error/")),
            tail_max_abs_residual: tail_max(&format!("/observer/{n}/residual/")),
            tail_max_abs_input_error: input_error(r, &n, tail_start),
            name: n,
        })
        .collect();
    // Back to the ns they were timed in (µs recorded: ns / 1000, exact to round again).
    let per = r.latency_ns_per_value();
    let percentiles = |path: &str| {
        let mut h = histogram();
        if let Some(s) = r.series.get(path) {
            for &v in &s.values {
                h.saturating_record(((v * per).round() as u64).max(1));
            }
        }
        Latency::percentiles(&h)
    };
    let hops = r
        .series
        .keys()
        .filter(|p| p.starts_with("/latency/") && p.as_str() != "/latency/step")
        .map(|p| {
            (
                r.names
                    .get(p)
                    .cloned()
                    .unwrap_or_else(|| p.trim_start_matches("/latency/").to_string()),
                percentiles(p),
            )
        })
        .collect();
    Inspection {
        file: file.to_string(),
        complete: r.complete,
        scenario: scenario.map(|s| s.name),
        steps_planned,
        steps_recorded,
        steps_completed,
        entities,
        observers,
        latency_ns: LatencyFigures {
            step: percentiles("/latency/step"),
            hops,
        },
        warnings,
    }
}

/// max_k max_j |ŵ_j − w_j| of observer `n` over the steps from `tail_start`, each ŵ_k against the
/// w_k recorded at its step; `None` without ŵ, without a tail, or with a ŵ at a step w lacks.
fn input_error(r: &Recording, n: &str, tail_start: Option<i64>) -> Option<f64> {
    let start = tail_start?;
    let mut worst: Option<f64> = None;
    for (j, what) in (1..).map_while(|j| {
        r.series
            .get(&crate::signals::input_estimate(n, j - 1))
            .map(|s| (j, s))
    }) {
        let w = r.series.get(&crate::signals::disturbance(j - 1))?;
        for (k, &v) in what.steps.iter().zip(&what.values) {
            if *k < start {
                continue;
            }
            let i = w.steps.binary_search(k).ok()?;
            worst = Some(nan_max(worst.unwrap_or(0.0), (v - w.values[i]).abs()));
        }
    }
    worst
}

impl Inspection {
    /// The printed report.
    pub fn text(&self) -> String {
        let mut t = format!(
            "{}: {} ({}), {} steps completed{}, {} recorded\n",
            self.file,
            self.scenario.as_deref().unwrap_or("unknown scenario"),
            if self.complete {
                "complete"
            } else {
                "INCOMPLETE"
            },
            self.steps_completed,
            self.steps_planned
                .map_or(String::new(), |p| format!(" of {p}")),
            self.steps_recorded
        );
        for w in &self.warnings {
            t += &format!("warning: {w}\n");
        }
        t += &format!(
            "  {:<42} {:>8} {:>18} {:>22}\n",
            "entity", "rows", "steps", "sim_time [s]"
        );
        for e in &self.entities {
            let time = e
                .sim_time
                .map_or("-".to_string(), |[a, b]| format!("{a} … {b}"));
            t += &format!(
                "  {:<42} {:>8} {:>18} {:>22}\n",
                e.path,
                e.rows,
                format!("{} … {}", e.steps[0], e.steps[1]),
                time
            );
        }
        t += &format!(
            "  {:<14} {:>14} {:>14} {:>14}\n",
            "observer", "tail max|e|", "tail max|r|", "tail max|ŵ−w|"
        );
        for o in &self.observers {
            t += &format!(
                "  {:<14} {:>14} {:>14} {:>14}\n",
                o.name,
                figure(o.tail_max_abs_error),
                figure(o.tail_max_abs_residual),
                figure(o.tail_max_abs_input_error)
            );
        }
        let p = &self.latency_ns.step;
        if p.max > 0 {
            t += &format!(
                "  step latency [ns]: p50 {}  p90 {}  p99 {}  p99.9 {}  max {}\n",
                p.p50, p.p90, p.p99, p.p999, p.max
            );
            for (h, p) in &self.latency_ns.hops {
                t += &format!("    {h:<30} p50 {}  p99 {}  max {}\n", p.p50, p.p99, p.max);
            }
        }
        t
    }
}
