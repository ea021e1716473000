//! Designing everything a scenario names, before anything runs: the observers, the state
//! feedback, and the warnings an engineer should see.

use controller::design::feedforward::matched_gain;
use controller::design::{FeedbackDesign, FeedbackSpec, Options, design as design_feedback};
use diagnosis::{Bank, design_bank};
use lti::Mat;
use lti::eig::{C64, eigenvalues, format_list, sig};
use observer::{Designed, design};

use scenario::{ObserverEntry, Scenario, ScenarioError};

/// The designs of a scenario.
#[derive(Debug, Clone)]
pub struct Plan {
    /// (name, design) per observer, in scenario order; no design for an external observer.
    pub observers: Vec<(String, Option<Designed>)>,
    /// The state feedback, if any (not for an external controller).
    pub feedback: Option<FeedbackDesign>,
    /// One bank per `[[diagnoser]]` (its members are among `observers`).
    pub banks: Vec<Bank>,
    /// Things worth knowing that do not stop a run.
    pub warnings: Vec<String>,
}

/// A design that could not be made, located in the scenario.
#[derive(Debug, Clone)]
pub struct PlanError {
    /// As a scenario error (file, field, reason).
    pub error: ScenarioError,
    /// The failing observer's evaluated conditions (empty for the controller).
    pub conditions: Vec<observer::design::Condition>,
    /// The observer's index, if an observer failed.
    pub observer: Option<usize>,
}

/// One observer's design, on the continuous plant and its exact sampling or on a discrete-time
/// plant's own (Φ, Γ_B, Γ_E), starting at the observer's `xhat0`, run at the scenario's operating
/// point (its offsets; without `xhat0` it starts there).
pub fn design_observer(
    s: &Scenario,
    o: &ObserverEntry,
    spec: &observer::Spec,
) -> Result<Designed, observer::DesignError> {
    let mut d = if s.discrete {
        observer::design::design_discrete(&s.sampled_model(), spec)
    } else {
        design(&s.model, spec, s.dt)
    }?;
    d.runtime.xhat0 = o.xhat0.clone();
    // The model is in deviations from the operating point; the plant's signals are absolute.
    if let Some(op) = &s.operating_point {
        d.at_operating_point(op);
    }
    Ok(d)
}

/// " (x41 = WO_x_IEEEST_1, …)": the scenario's names of the states a refusal says carry a mode
/// no sensor sees (the design names them x1, x2, … only).
pub fn carried_by(s: &Scenario, e: &observer::DesignError) -> String {
    let names: Vec<String> = e
        .unseen_states
        .iter()
        .filter_map(|&i| {
            s.names
                .state
                .get(i)
                .filter(|n| n.name != format!("x{}", i + 1))
                .map(|n| format!("x{} = {}", i + 1, n.name))
        })
        .collect();
    if names.is_empty() {
        String::new()
    } else {
        format!(" ({})", names.join(", "))
    }
}

/// Observer `i`'s refusal, located at its field.
fn observer_error(
    s: &Scenario,
    i: usize,
    o: &ObserverEntry,
    e: &observer::DesignError,
) -> PlanError {
    let placement = e.condition.ends_with("poles") || e.condition.ends_with("pole placement");
    let (sub, reason) = if placement {
        (
            ".poles",
            format!("{} observer '{}': {}", e.kind, o.name, e.detail),
        )
    } else {
        (
            "",
            format!(
                "{} observer '{}': {} does not hold: {}{}",
                e.kind,
                o.name,
                e.condition,
                e.detail,
                carried_by(s, e)
            ),
        )
    };
    PlanError {
        error: scenario::locate_error(s, &format!("observer[{}]{sub}", i + 1), reason),
        conditions: e.conditions.clone(),
        observer: Some(i),
    }
}

/// Designs every observer and the controller.
#[allow(clippy::result_large_err)] // made once per command, never on a hot path
pub fn plan(s: &Scenario) -> Result<Plan, PlanError> {
    let banks = banks(s)?;
    let mut own = Vec::new();
    for (i, o) in s.observers.iter().enumerate() {
        own.push(match (&o.spec, o.member) {
            (Some(spec), None) => {
                Some(design_observer(s, o, spec).map_err(|e| observer_error(s, i, o, &e))?)
            }
            _ => None,
        });
    }
    complete(s, banks, own)
}

/// The plan from the banks and the scenario's own observers already designed (`None` for an
/// external one and for bank members, which come from their banks): the controller's design
/// and the warnings.
#[allow(clippy::result_large_err)]
pub fn complete(
    s: &Scenario,
    banks: Vec<Bank>,
    own: Vec<Option<Designed>>,
) -> Result<Plan, PlanError> {
    let locate = |field: String, reason: String| scenario::locate_error(s, &field, reason);
    let observers: Vec<(String, Option<Designed>)> = s
        .observers
        .iter()
        .zip(own)
        .map(|(o, d)| {
            (
                o.name.clone(),
                o.member
                    .map_or(d, |(b, j)| Some(banks[b].members[j].designed.clone())),
            )
        })
        .collect();
    let feedback = match s
        .controller
        .as_ref()
        .and_then(|c| c.spec.as_ref().map(|spec| (c, spec)))
    {
        Some((c, spec)) => {
            let model = (!s.discrete).then_some(&s.model);
            let opts = Options {
                track: c.track.as_ref(),
                integral: c.integral,
                measured: &c.measured,
            };
            let designed = design_feedback(model, &s.sampled_model(), spec, &opts);
            let mut fb = designed.map_err(|reason| {
                let field = match spec {
                    FeedbackSpec::Gain(_) => "controller.gain",
                    FeedbackSpec::Lqr { .. } => "controller.kind",
                    FeedbackSpec::Poles { .. } => "controller.poles",
                };
                let field = if reason.starts_with("integral") {
                    "controller.integral"
                } else {
                    field
                };
                PlanError {
                    error: locate(field.into(), reason),
                    conditions: vec![],
                    observer: None,
                }
            })?;
            if c.feedforward {
                fb.feedforward =
                    Some(feedforward(s, c, &observers).map_err(|reason| PlanError {
                        error: locate("controller.feedforward".into(), reason),
                        conditions: vec![],
                        observer: None,
                    })?);
            }
            // A controller that reads the plant's samples (for ŵ, or measured tracked outputs) is
            // one more subscriber to them, beside every observer and the recorder.
            let processes = s.observer_processes().len();
            if fb.reads_plant() && processes >= scenario::limits::MAX_OBSERVERS {
                let field = if c.feedforward {
                    "controller.feedforward"
                } else {
                    "controller.integral"
                };
                let reason = format!(
                    "this controller reads the plant's samples, as every observer does: with {} observer processes (a bank's members share one) they would have more than the {} subscribers a service allows (one is the recorder); at most {} observers here",
                    processes,
                    lockstep::settings::MAX_SUBSCRIBERS,
                    scenario::limits::MAX_OBSERVERS - 1
                );
                return Err(PlanError {
                    error: locate(field.into(), reason),
                    conditions: vec![],
                    observer: None,
                });
            }
            Some(fb)
        }
        None => None,
    };
    let warnings = warnings(s, &observers, feedback.as_ref(), &banks);
    Ok(Plan {
        observers,
        feedback,
        banks,
        warnings,
    })
}

/// M ŵ's matrices (MW, MWCΦ, MWCΓ_B) for `feedforward = "what"`: w must enter through the
/// inputs (Γ_E = Γ_B M), and the controller's observer must estimate it.
///
/// With measured disturbances only the commanded inputs cancel: M = [M_c; 0], Γ_c M_c = Γ_E.
fn feedforward(
    s: &Scenario,
    c: &scenario::ControllerEntry,
    observers: &[(String, Option<Designed>)],
) -> Result<[Mat; 3], String> {
    use controller::design::measured;
    let dm = s.sampled_model();
    let keep = measured::commanded(dm.b.ncols(), &c.measured);
    let m = measured::rows(
        &matched_gain(&measured::sampled(&dm, &keep))?,
        dm.b.ncols(),
        &keep,
    );
    let what = observers
        .iter()
        .find(|(n, _)| *n == c.observer)
        .and_then(|(_, d)| d.as_ref())
        .and_then(|d| d.what.as_ref());
    let what = what.ok_or_else(|| {
        format!(
            "observer '{}' gives no estimate ŵ of the unknown input (an unknown-input observer of ours gives one when CΓ_E has full column rank): feedforward = \"what\" needs it",
            c.observer
        )
    })?;
    Ok([&m * &what.w, &m * &what.w_c_phi, &m * &what.w_c_gamma_b])
}

/// Designs every `[[diagnoser]]` bank; a refusal names the diagnoser, the member and the
/// condition that fails.
#[allow(clippy::result_large_err)]
pub fn banks(s: &Scenario) -> Result<Vec<Bank>, PlanError> {
    let noise = s.noise.as_ref().map(|z| (&z.qd, &z.r));
    s.diagnosers
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let mut bank = design_bank(d, &s.model, &s.ff, s.dt, noise);
            // At an operating point every member runs on the plant's absolute signals, as the
            // scenario's own observers do; its residual is formed in deviations (Metrics).
            if let (Ok(b), Some(op)) = (&mut bank, &s.operating_point) {
                for m in &mut b.members {
                    m.designed.runtime.at_operating_point(op);
                }
            }
            bank.map_err(|e| {
                let field = if e.key.is_empty() {
                    format!("diagnoser[{}]", i + 1)
                } else {
                    format!("diagnoser[{}].{}", i + 1, e.key)
                };
                let labels = diagnosis::bank::channel_labels(d.channels, &s.model, &s.ff);
                let who = e.member.map_or(String::new(), |m| {
                    format!(
                        "member {} ({}): ",
                        m + 1,
                        diagnosis::bank::role(d, &labels, m)
                    )
                });
                PlanError {
                    error: scenario::locate_error(
                        s,
                        &field,
                        format!("diagnoser '{}': {who}{}", d.name, e.reason),
                    ),
                    conditions: vec![],
                    observer: None,
                }
            })
        })
        .collect()
}

/// dt too coarse for the fastest pole, an unstable loop, and the like.
fn warnings(
    s: &Scenario,
    observers: &[(String, Option<Designed>)],
    feedback: Option<&FeedbackDesign>,
    banks: &[Bank],
) -> Vec<String> {
    let observers: Vec<(&String, &Designed)> = observers
        .iter()
        .filter_map(|(n, d)| d.as_ref().map(|d| (n, d)))
        .collect();
    let mut out = Vec::new();
    let fastest = |ev: &[C64]| ev.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let mut check = |what: String, ev: &[C64]| {
        let f = fastest(ev);
        if f * s.dt > 0.2 {
            out.push(format!("dt = {} is coarse for {what}: fastest pole |p| = {}, |p|·dt = {} (keep it below 0.2)", s.dt, sig(f), sig(f * s.dt)));
        }
    };
    // A discrete plant has no continuous poles to compare with dt.
    if !s.discrete
        && let Ok(ev) = eigenvalues(&s.model.a)
    {
        check("the plant".into(), &ev);
    }
    for (name, d) in &observers {
        if !d.report.sampled_only {
            check(format!("observer '{name}'"), &d.report.poles);
        }
    }
    if let Some(fb) = feedback {
        if !s.discrete {
            check("the closed loop".into(), &fb.closed_loop);
        }
        if let Some(why) = fb.instability() {
            out.push(why);
        }
    }
    // Sensor banks of Luenberger or Kalman members do not decouple w: with E ≠ 0 and a
    // disturbance that is not zero, w drives every residual, and the thresholds (set for noise)
    // raise alarms that no fault caused.
    let disturbed =
        s.model.e.iter().any(|&v| v != 0.0) && s.disturbances.iter().any(|w| w.peak() > 0.0);
    for d in s.diagnosers.iter().filter(|_| disturbed) {
        let kind = match d.member {
            diagnosis::spec::MemberKind::Luenberger { .. } => "luenberger",
            diagnosis::spec::MemberKind::Kalman => "kalman",
            diagnosis::spec::MemberKind::ChenPatton { .. } => continue,
        };
        out.push(format!(
            "diagnoser '{}': its {kind} members do not decouple the unknown inputs: with E ≠ 0 and a non-zero disturbance, w drives every residual and can raise alarms no fault caused (a bank of chen-patton-uio members decouples w)",
            d.name
        ));
    }
    // A bias that a bank's residuals forget once the transient has passed.
    for b in banks {
        out.extend(diagnosis::bank::transient_only(b));
    }
    for (name, d) in &observers {
        if !d.report.fixed_modes.is_empty() {
            out.push(format!(
                "observer '{name}': fixed modes {} cannot be moved by any admissible gain",
                format_list(&d.report.fixed_modes)
            ));
        }
    }
    out
}
