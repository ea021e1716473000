//! The sections of the design report and how they are gathered: every design made once.

use controller::design::{Domain, FeedbackDesign, FeedbackSpec};
use observer::{DesignError, Designed};
use scenario::Scenario;

/// The design of a scenario: each observer's, each bank's, the controller's, the warnings.
pub struct DesignReport {
    /// The scenario's name and (one line of) its description.
    pub scenario: String,
    pub description: String,
    /// The sample period the sampled designs are made for.
    pub dt: f64,
    /// The scenario's own observers, in order (bank members are in `banks`).
    pub observers: Vec<ObserverSection>,
    /// The diagnoser banks: `None` without `[[diagnoser]]`, the error when one cannot be made.
    pub banks: Option<Result<Vec<diagnosis::Bank>, String>>,
    pub controller: ControllerSection,
    pub warnings: Vec<String>,
    /// Whether everything was designed (and the loop is stable): `uio-launcher design` exits 0.
    pub ok: bool,
}

/// One `[[observer]]`.
pub enum ObserverSection {
    /// `kind = "process"`: not designed here.
    Process {
        name: String,
        command: Vec<String>,
        params: serde_json::Value,
    },
    /// Designed: its conditions, matrices, poles and the sampled observer that runs.
    Designed {
        name: String,
        kind: &'static str,
        designed: Box<Designed>,
    },
    /// Refused: the conditions evaluated up to the one that failed, and what carries the
    /// failure (the unseen states' names).
    Refused {
        name: String,
        kind: &'static str,
        error: DesignError,
        carried: String,
    },
}

/// The `[controller]`.
pub enum ControllerSection {
    /// None, or not designed because an observer or bank failed.
    None,
    /// State feedback: the law, the gains, the closed loop.
    Feedback {
        kind: &'static str,
        observer: String,
        feedback: Box<FeedbackDesign>,
        /// The names of the measured disturbances (inputs not commanded).
        measured: Vec<String>,
        /// Whether tracked outputs are given (a prefilter N without integral action).
        track: bool,
        /// Whether the closed loop's poles are eig(A − BG) (continuous placement or a given G
        /// on a continuous plant) rather than ln(z)/dt of the sampled loop.
        continuous: bool,
    },
    /// `kind = "process"`.
    Process {
        observer: String,
        command: Vec<String>,
        params: serde_json::Value,
    },
    /// The controller could not be designed.
    Error(String),
}

/// Designs everything in the scenario, once each, and gathers the report.
pub fn report(s: &Scenario) -> DesignReport {
    let mut ok = true;
    let mut observers = Vec::new();
    // Each design made once, then handed to the plan (the controller and the warnings).
    let mut own: Vec<Option<Designed>> = Vec::new();
    for o in &s.observers {
        own.push(None);
        if o.member.is_some() {
            continue;
        }
        let Some(spec) = &o.spec else {
            let p = o
                .process
                .as_ref()
                .expect("an observer without a design is a process");
            observers.push(ObserverSection::Process {
                name: o.name.clone(),
                command: p.command.clone(),
                params: p.params.clone(),
            });
            continue;
        };
        match crate::plan::design_observer(s, o, spec) {
            Ok(d) => {
                observers.push(ObserverSection::Designed {
                    name: o.name.clone(),
                    kind: o.kind(),
                    designed: Box::new(d.clone()),
                });
                *own.last_mut().expect("pushed above") = Some(d);
            }
            Err(e) => {
                ok = false;
                let carried = crate::plan::carried_by(s, &e);
                observers.push(ObserverSection::Refused {
                    name: o.name.clone(),
                    kind: o.kind(),
                    error: e,
                    carried,
                });
            }
        }
    }
    let banks = crate::plan::banks(s);
    let bank_section = (!s.diagnosers.is_empty()).then(|| match &banks {
        Ok(b) => Ok(b.clone()),
        Err(e) => Err(e.error.to_string()),
    });
    ok &= banks.is_ok() || s.diagnosers.is_empty();
    let mut controller = ControllerSection::None;
    let mut warnings = Vec::new();
    if let (true, Ok(banks)) = (ok, banks) {
        match crate::plan::complete(s, banks, own) {
            Ok(p) => {
                warnings = p.warnings.clone();
                if let (Some(c), Some(fb)) = (&s.controller, &p.feedback) {
                    let continuous = !s.discrete
                        && matches!(
                            c.spec,
                            Some(FeedbackSpec::Poles {
                                domain: Domain::Continuous,
                                ..
                            }) | Some(FeedbackSpec::Gain(_))
                        );
                    // The run refuses an unstable loop without --allow-unstable: design says so
                    // by its exit code.
                    ok &= fb.stable();
                    controller = ControllerSection::Feedback {
                        kind: if matches!(c.spec, Some(FeedbackSpec::Lqr { .. })) {
                            "lqr"
                        } else {
                            "state-feedback"
                        },
                        observer: c.observer.clone(),
                        feedback: Box::new(fb.clone()),
                        measured: fb
                            .measured
                            .iter()
                            .map(|&j| s.names.input[j].name.clone())
                            .collect(),
                        track: c.track.is_some(),
                        continuous,
                    };
                }
                if let Some((c, p)) = s
                    .controller
                    .as_ref()
                    .and_then(|c| c.process.as_ref().map(|p| (c, p)))
                {
                    controller = ControllerSection::Process {
                        observer: c.observer.clone(),
                        command: p.command.clone(),
                        params: p.params.clone(),
                    };
                }
            }
            Err(e) => {
                ok = false;
                controller = ControllerSection::Error(e.error.to_string());
            }
        }
    }
    DesignReport {
        scenario: s.name.clone(),
        description: scenario::untrusted::one_line(&s.description),
        dt: s.dt,
        observers,
        banks: bank_section,
        controller,
        warnings,
        ok,
    }
}
