//! What both run modes do with each completed step: figures, latency, recording.

use std::path::Path;

use lockstep::PlantLayout;

use super::channels::{self, Channels};
use super::progress::Progress;
use crate::error::LaunchError;
use diagnosis::{Diagnosis, FaultInfo, Judge, Monitor};
use observer::design::InputEstimator;

use crate::plan::Plan;
use recording::signals as sig;
use recording::write::Selection;
use recording::write::{Latency, Metrics, RrdSink, SeriesId, StepRow};
use scenario::Scenario;

/// The recording side of a run.
pub struct Session {
    layout: PlantLayout,
    /// Figures of merit so far.
    pub metrics: Metrics,
    /// Latency histograms so far.
    pub latency: Latency,
    sink: Option<(RrdSink, Channels)>,
    /// Index of the observer the controller reads.
    controller_observer: Option<usize>,
    /// (plant sent_ns, controller sent_ns) of the previous step.
    prev: Option<(u64, u64)>,
    /// Steps recorded.
    pub steps: u64,
    dt: f64,
    /// The progress bar, when the run shows one.
    pub progress: Option<Progress>,
    /// The hops a row completes, reused from step to step (no allocation per step).
    hop_values: Vec<(usize, u64)>,
    /// The hops of the previous step measured with its own row (plant→observers,
    /// observer→controller), recorded with the row that completes that step's latencies.
    pending_hops: Vec<(usize, u64)>,
    /// The hops of a step whose latencies a row completes (reused).
    done_hops: Vec<(usize, u64)>,
    /// One per diagnoser bank: its decisions step by step.
    monitors: Vec<Monitor>,
    /// The diagnosis figures (with any bank).
    judge: Option<Judge>,
    /// Real-time pacing, with `--realtime`.
    pace: Option<Pace>,
    /// `/latency/overrun`'s group and series (paced runs).
    overrun: Option<(usize, SeriesId)>,
    /// Each observer's name, and the plant's state bound that its estimate is held to.
    observer_names: Vec<String>,
    state_bound: f64,
    /// The first observer estimate that left the state bound or became non-finite, in words:
    /// the run stops there as it does when the plant's state diverges (exit 4).
    pub diverged: Option<String>,
}

/// An observer whose error left the plant's state bound (or is not finite) at this row, in
/// words. An observer designed wrongly diverges while every condition it printed read "ok"
/// (a rank-deficient reduced basis reached an error of 1.8e12 and the run exited 0):
/// its error x̂ᵢ − xᵢ is held to the rule the plant's state is, |·| ≤ `state_bound` (default
/// 1e9). The error, not the estimate: an observer that follows a diverging plant is not the one
/// to name, the plant's own check stops that run.
fn estimate_divergence(row: &StepRow, x: &[f64], names: &[String], bound: f64) -> Option<String> {
    for (xhat, name) in row.xhat.iter().zip(names) {
        let bad = xhat
            .iter()
            .zip(x)
            .enumerate()
            .find(|(_, (e, x))| !e.is_finite() || (*e - *x).abs() > bound);
        if let Some((i, (&e, &xi))) = bad {
            let value = if e.is_finite() {
                format!(
                    "x̂{n} − x{n} = {:.6e} left the bound ±{bound:.3e}",
                    e - xi,
                    n = i + 1
                )
            } else {
                format!("x̂{} = {e}", i + 1)
            };
            return Some(format!(
                "observer '{name}': its error grows without bound: {value} at step {}",
                row.k
            ));
        }
    }
    None
}

/// How a paced run kept its schedule: step k is due to end at t₀ + (k + 1)·period.
#[derive(Debug, Clone, Copy)]
struct Pace {
    period_ns: u64,
    t0: Option<u64>,
    steps: u64,
    overruns: u64,
    max_late_ns: u64,
    last_end: u64,
}

/// What a session leaves when it is closed.
pub struct Finished {
    /// The figures of merit.
    pub metrics: Metrics,
    /// The latency histograms.
    pub latency: Latency,
    /// The recording's digest, if one was written.
    pub digest: Option<Digest>,
    /// Detection, isolation and false alarms (with a diagnoser).
    pub diagnosis: Option<Diagnosis>,
    /// How a paced run kept its schedule.
    pub realtime: Option<RealtimeFigures>,
}

/// A paced run's figures (summary.json → `realtime`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct RealtimeFigures {
    /// Wall time per step, s (dt / speed).
    pub period_s: f64,
    /// Steps whose end was timed.
    pub steps: u64,
    /// Steps that ended after their deadline t₀ + (k + 1)·period.
    pub overruns: u64,
    /// The latest a step ended past its deadline, µs.
    pub max_lateness_us: f64,
    /// From sample 0 to the end of the last step, s.
    pub paced_wall_s: f64,
    /// steps × period, s.
    pub scheduled_s: f64,
}

/// The faults of a scenario as the figures see them.
fn fault_infos(s: &Scenario) -> Vec<FaultInfo> {
    use plant::fault::Target;
    s.faults
        .iter()
        .map(|f| {
            let (channels, channel) = match f.target {
                Target::Actuator(i) => (diagnosis::Channels::Actuator, i),
                Target::Sensor(j) => (diagnosis::Channels::Sensor, j),
                Target::Component(j) => (diagnosis::Channels::Component, j),
            };
            FaultInfo {
                name: f.name.clone(),
                channels,
                channel,
                start: f.profile.start(),
                active: f.active_steps(s.dt),
            }
        })
        .collect()
}

/// A recording's digest: entity → 16 hex digits.
pub type Digest = std::collections::BTreeMap<String, String>;

/// The figures' accumulator of a run: residuals about the operating point's output, false
/// alarms counted until the first fault, ŵ compared where an observer estimates w.
fn metrics_for(
    s: &Scenario,
    layout: PlantLayout,
    estimates: &[Option<&InputEstimator>],
) -> Metrics {
    let mut metrics = Metrics::new(
        layout,
        s.model.c.clone(),
        s.observers.len(),
        s.steps,
        s.tail_steps(),
    );
    if let Some(op) = &s.operating_point {
        metrics.residual_offset(op.output_offset(&s.model.c));
    }
    if let Some(first) = s
        .faults
        .iter()
        .flat_map(|f| f.active_steps(s.dt))
        .map(|(on, _)| on)
        .min()
    {
        metrics.fault_free_until(first, s.dt);
    }
    for (o, e) in estimates.iter().enumerate() {
        if let Some(e) = e {
            metrics.estimate_inputs(o, e.w.clone(), &e.w_c_phi, &e.w_c_gamma_b, e.offset.clone());
        }
    }
    metrics
}

/// Hop names of a run, in the order [`Session`] records them.
pub fn hop_names(s: &Scenario) -> Vec<String> {
    let mut hops: Vec<String> = s
        .observers
        .iter()
        .map(|o| format!("plant->observer/{}", o.name))
        .collect();
    if let Some(c) = &s.controller {
        hops.push(format!("observer/{}->controller", c.observer));
        hops.push("controller->plant".into());
    }
    hops
}

impl Session {
    /// Starts a session; with `rrd`, opens the recording there.
    /// `select` thins and filters what is written; the figures see every step.
    /// `measures_hops`: the run measures hop latencies (across processes; in one process there
    /// are none).
    pub fn new(
        s: &Scenario,
        layout: PlantLayout,
        plan: &Plan,
        rrd: Option<&Path>,
        select: &Selection,
        pace_s: Option<f64>,
        measures_hops: bool,
    ) -> Result<Self, LaunchError> {
        let banks = &plan.banks[..];
        // ŵ of the scenario's own observers (a bank member's model widens E with its blind
        // channels: its estimator is not of the plant's w).
        let estimates: Vec<Option<&InputEstimator>> = plan
            .observers
            .iter()
            .zip(&s.observers)
            .map(|((_, d), o)| {
                d.as_ref()
                    .and_then(|d| d.what.as_ref())
                    .filter(|_| o.member.is_none())
            })
            .collect();
        let pace = pace_s.map(|p| Pace {
            period_ns: (p * 1e9).round() as u64,
            t0: None,
            steps: 0,
            overruns: 0,
            max_late_ns: 0,
            last_end: 0,
        });
        let monitors: Vec<Monitor> = banks
            .iter()
            .map(|b| {
                let index = b
                    .members
                    .iter()
                    .map(|mb| {
                        s.observers
                            .iter()
                            .position(|o| o.name == mb.name)
                            .expect("members are observers")
                    })
                    .collect();
                Monitor::new(b, index, s.dt)
            })
            .collect();
        let judge = (!banks.is_empty())
            .then(|| Judge::new(fault_infos(s), &monitors, s.dt, s.isolated_fraction));
        let controller_observer = s
            .controller
            .as_ref()
            .and_then(|c| s.observers.iter().position(|o| o.name == c.observer));
        let hops = hop_names(s);
        let (sink, overrun) = match rrd {
            Some(path) => {
                let want = channels::Wanted {
                    layout,
                    banks,
                    estimates: &estimates,
                    select,
                    hops: if measures_hops { &hops } else { &[] },
                    paced: pace.is_some(),
                };
                let opened = channels::open(path, s, &want)?;
                (Some((opened.sink, opened.channels)), opened.overrun)
            }
            None => (None, None),
        };
        let metrics = metrics_for(s, layout, &estimates);
        Ok(Session {
            layout,
            metrics,
            latency: Latency::new(hops),
            sink,
            controller_observer,
            prev: None,
            steps: 0,
            dt: s.dt,
            progress: None,
            hop_values: Vec::with_capacity(s.observers.len() + 2),
            pending_hops: Vec::with_capacity(s.observers.len() + 2),
            done_hops: Vec::with_capacity(s.observers.len() + 2),
            monitors,
            judge,
            pace,
            overrun,
            observer_names: s.observers.iter().map(|o| o.name.clone()).collect(),
            state_bound: s.state_bound,
            diverged: None,
        })
    }

    /// Records one step whose samples carry the components' timestamps (processes mode).
    pub fn record(&mut self, row: &StepRow) -> Result<(), LaunchError> {
        // Hops completed by this row.
        let nobs = row.xhat.len();
        let mut hop_values = std::mem::take(&mut self.hop_values);
        hop_values.clear();
        for i in 0..nobs {
            hop_values.push((
                i,
                row.xhat_hdr[i]
                    .taken_ns
                    .saturating_sub(row.plant_hdr.sent_ns),
            ));
        }
        if let Some(c) = self.controller_observer {
            hop_values.push((
                nobs,
                row.u_hdr.taken_ns.saturating_sub(row.xhat_hdr[c].sent_ns),
            ));
        }
        // The previous step ends when this row's plant sample says when it had u_{k−1}.
        let mut step_ns = None;
        if let Some((plant_sent, ctrl_sent)) = self.prev {
            step_ns = Some(row.plant_hdr.taken_ns.saturating_sub(plant_sent));
            if self.controller_observer.is_some() {
                hop_values.push((nobs + 1, row.plant_hdr.taken_ns.saturating_sub(ctrl_sent)));
            }
        }
        if row.k == 0
            && let Some(p) = &mut self.pace
        {
            p.t0 = Some(row.plant_hdr.sent_ns);
        }
        if row.k > 0 {
            self.step_ended(row.k - 1, row.plant_hdr.taken_ns)?;
        }
        self.prev = Some((row.plant_hdr.sent_ns, row.u_hdr.sent_ns));
        for &(i, ns) in &hop_values {
            self.latency.hop(i, ns);
        }
        if let Some(ns) = step_ns {
            self.latency.step(ns);
        }
        // Step k − 1's latencies complete now: its hops from the last row, and controller→plant.
        let mut done = std::mem::take(&mut self.done_hops);
        done.clear();
        done.extend_from_slice(&self.pending_hops);
        done.extend(hop_values.iter().filter(|&&(i, _)| i > nobs));
        self.pending_hops.clear();
        self.pending_hops
            .extend(hop_values.iter().filter(|&&(i, _)| i <= nobs));
        let pushed = self.push(row, step_ns.map(|ns| (row.k - 1, ns)), &done);
        self.hop_values = hop_values;
        self.done_hops = done;
        pushed
    }

    /// Closes the timing of the last step K − 1 with the plant's end sample (step K, published
    /// after the run, carrying when the plant had u_{K−1}): its step time and controller→plant hop.
    pub fn close_last(&mut self, end: &lockstep::Header) -> Result<(), LaunchError> {
        let Some((plant_sent, ctrl_sent)) = self.prev.take() else {
            return Ok(());
        };
        self.step_ended(end.step.saturating_sub(1), end.taken_ns)?;
        let step_ns = end.taken_ns.saturating_sub(plant_sent);
        self.latency.step(step_ns);
        let late = self.controller_observer.map(|_| {
            (
                self.metrics.observers.len() + 1,
                end.taken_ns.saturating_sub(ctrl_sent),
            )
        });
        if let Some((i, ns)) = late {
            self.latency.hop(i, ns);
        }
        let Some((sink, ch)) = &mut self.sink else {
            return Ok(());
        };
        let k = end.step.saturating_sub(1);
        sink.row(ch.latency, k, k as f64 * self.dt);
        sink.push(ch.step_latency, us(step_ns));
        for &(i, ns) in self.pending_hops.iter().chain(late.as_ref()) {
            sink.push(ch.hops[i], us(ns));
        }
        sink.flush_full().map_err(LaunchError::Component)
    }

    /// Step k of a paced run ended at `end_ns` (CLOCK_MONOTONIC): late if after its deadline
    /// t₀ + (k + 1)·period. In-process, the loop sets t₀ with [`Session::pace_start`].
    pub fn step_ended(&mut self, k: u64, end_ns: u64) -> Result<(), LaunchError> {
        let Some(p) = &mut self.pace else {
            return Ok(());
        };
        let Some(t0) = p.t0 else { return Ok(()) };
        let late = end_ns.saturating_sub(t0 + (k + 1) * p.period_ns);
        p.steps += 1;
        p.last_end = p.last_end.max(end_ns);
        if late > 0 {
            p.overruns += 1;
            p.max_late_ns = p.max_late_ns.max(late);
        }
        if let (Some((sink, _)), Some((g, id))) = (&mut self.sink, self.overrun) {
            sink.row(g, k, k as f64 * self.dt);
            sink.push(id, us(late));
        }
        Ok(())
    }

    /// When sample 0 went out in a paced in-process run.
    pub fn pace_start(&mut self, t0: u64) {
        if let Some(p) = &mut self.pace {
            p.t0 = Some(t0);
        }
    }

    /// Records one step of the in-process loop, with its step time when it was measured.
    pub fn record_in_process(
        &mut self,
        row: &StepRow,
        step_ns: Option<u64>,
    ) -> Result<(), LaunchError> {
        if let Some(ns) = step_ns {
            self.latency.step(ns);
        }
        self.push(row, step_ns.map(|ns| (row.k, ns)), &[])
    }

    fn push(
        &mut self,
        row: &StepRow,
        step_ns: Option<(u64, u64)>,
        hops: &[(usize, u64)],
    ) -> Result<(), LaunchError> {
        self.metrics.push(row);
        // The metrics hold each observer's max |x − x̂| of this step (NaN for a non-finite x̂):
        // the estimates are looked at only when one of those is not within the bound.
        let suspect = (0..self.observer_names.len()).any(|o| {
            let e = self.metrics.last_max_abs_error(o);
            e.is_nan() || e > self.state_bound
        });
        if suspect && self.diverged.is_none() {
            self.diverged = estimate_divergence(
                row,
                &row.plant[self.layout.x()],
                &self.observer_names,
                self.state_bound,
            );
        }
        let lay = self.layout;
        for m in &mut self.monitors {
            m.step(row.k, &self.metrics.residual);
        }
        if let Some(j) = &mut self.judge {
            j.push(row.k, &self.monitors);
        }
        self.steps += 1;
        if let Some(p) = &mut self.progress {
            p.tick(self.steps);
        }
        let Some((sink, ch)) = &mut self.sink else {
            return Ok(());
        };
        let (k, t) = (row.k, row.t);
        sink.row(ch.signals, k, t);
        let put = |sink: &mut RrdSink, ids: &[SeriesId], vals: &[f64]| {
            for (&id, &v) in ids.iter().zip(vals) {
                sink.push(id, v);
            }
        };
        put(sink, &ch.x, &row.plant[lay.x()]);
        put(sink, &ch.y, &row.plant[lay.y()]);
        put(sink, &ch.w, &row.plant[lay.w()]);
        put(sink, &ch.v, &row.plant[lay.v()]);
        put(sink, &ch.r, &row.plant[lay.r()]);
        put(sink, &ch.u, &row.u);
        for (o, oc) in ch.observers.iter().enumerate() {
            let Some(oc) = oc else { continue };
            put(sink, &oc.xhat, &row.xhat[o]);
            put(sink, &oc.error, &self.metrics.error[o]);
            put(sink, &oc.residual, &self.metrics.residual[o]);
            // max_i |e_i| of this step, as the figures took it.
            sink.push(
                oc.log_error,
                sig::log10_floored(self.metrics.observers[o].final_abs_error),
            );
        }
        // ŵ_{k−1}, completed by this row, at the step it estimates.
        if let Some(g) = ch.estimates_late
            && self
                .metrics
                .what
                .iter()
                .any(|w| w.as_ref().is_some_and(|w| w.ready))
        {
            sink.row(g, k - 1, (k - 1) as f64 * self.dt);
            for (oc, what) in ch.observers.iter().zip(&self.metrics.what) {
                if let (Some(oc), Some(what)) = (oc, what) {
                    put(sink, &oc.what, what.value());
                }
            }
        }
        for ((m, members), (decisions, isolated)) in
            self.monitors.iter().zip(&ch.members).zip(&ch.decisions)
        {
            for (i, ids) in members.iter().enumerate() {
                put(sink, ids, &m.residuals[i]);
                let [e, th, al] = decisions[i];
                sink.push(e, m.evals[i]);
                sink.push(th, m.thresholds[i]);
                sink.push(al, if m.alarms[i] { 1.0 } else { 0.0 });
            }
            sink.push(*isolated, m.isolation.code());
        }
        for (m, glr) in self.monitors.iter().zip(&ch.glr) {
            if let Some((per, by)) = glr {
                for (i, [g, th]) in per.iter().enumerate() {
                    sink.push(*g, m.glr_stats[i]);
                    sink.push(*th, m.glr_thresholds[i]);
                }
                sink.push(*by, m.decided_by.code());
            }
        }
        for (i, [active, value]) in ch.faults.iter().enumerate() {
            let f = &row.plant[lay.fault(i)];
            sink.push(*active, f[0]);
            sink.push(*value, f[1]);
        }
        // Latencies are recorded at the step they belong to: those of step k−1 complete with
        // row k (in-process: step k itself, which has no hops).
        if let Some((ks, ns)) = step_ns {
            sink.row(ch.latency, ks, ks as f64 * self.dt);
            sink.push(ch.step_latency, us(ns));
            for &(i, ns) in hops {
                sink.push(ch.hops[i], us(ns));
            }
        }
        sink.flush_full().map_err(LaunchError::Component)
    }

    /// Closes the recording (footer written); returns what the run leaves ([`Finished`]).
    /// Fails, naming the file, when the recording could not be written whole.
    pub fn finish(self) -> Result<Finished, LaunchError> {
        if let Some(p) = self.progress {
            p.finish();
        }
        let digest = match self.sink {
            Some((sink, _)) => Some(sink.finish(self.steps).map_err(LaunchError::Component)?),
            None => None,
        };
        let diagnosis = self.judge.map(|j| j.finish(&self.monitors));
        let realtime = self.pace.map(|p| RealtimeFigures {
            period_s: p.period_ns as f64 * 1e-9,
            steps: p.steps,
            overruns: p.overruns,
            max_lateness_us: p.max_late_ns as f64 / 1000.0,
            paced_wall_s: p
                .t0
                .map_or(0.0, |t0| p.last_end.saturating_sub(t0) as f64 * 1e-9),
            scheduled_s: p.steps as f64 * p.period_ns as f64 * 1e-9,
        });
        Ok(Finished {
            metrics: self.metrics,
            latency: self.latency,
            digest,
            diagnosis,
            realtime,
        })
    }
}

/// A latency as recorded: µs ([`recording::write::LATENCY_UNIT`]), from the ns it was timed in.
#[inline]
fn us(ns: u64) -> f64 {
    ns as f64 / 1000.0
}
