//! `[controller]`: the kind, the observer it reads, its gain (placed, LQR or given), integral
//! action, feedforward of ŵ and measured disturbances.

use std::collections::BTreeSet;

use controller::design::{Domain, FeedbackSpec};
use lti::Model;

use super::process::process_spec;
use crate::check::{Bad, bad, definite, matrix, one_of, placement, poles};
use crate::raw::RawController;
use crate::untrusted::quoted;
use crate::{ControllerEntry, Named};

// one job: `[controller]` validated field by field in the order the docs list them.
pub(super) fn controller_entry(
    c: &RawController,
    model: &Model,
    observers: &BTreeSet<String>,
    inputs: &[Named],
) -> Result<ControllerEntry, Bad> {
    one_of(
        "controller.kind",
        "controller kind",
        &c.kind,
        &[("state-feedback", ()), ("lqr", ()), ("process", ())],
    )?;
    if !observers.contains(&c.observer) {
        let known: Vec<&str> = observers.iter().map(String::as_str).collect();
        return Err(bad(
            "controller.observer",
            format!(
                "no observer named {} (observers: {}){}",
                quoted(&c.observer),
                known.join(", "),
                crate::suggest::did_you_mean(&c.observer, known.iter().copied())
            ),
        ));
    }
    let given = [
        ("poles", c.poles.is_some()),
        ("gain", c.gain.is_some()),
        ("placement", c.placement.is_some()),
        ("domain", c.domain.is_some()),
        ("Q", c.q.is_some()),
        ("R", c.r.is_some()),
        ("track", c.track.is_some()),
        ("integral", c.integral.is_some()),
        ("feedforward", c.feedforward.is_some()),
        ("measured_disturbances", c.measured_disturbances.is_some()),
    ];
    if c.kind == "process" {
        let process = process_spec("controller", &c.command, &c.params)?;
        if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
            return Err(bad(
                format!("controller.{key}"),
                "a process controller takes no design keys (only command, observer and params)",
            ));
        }
        return Ok(ControllerEntry {
            observer: c.observer.clone(),
            spec: None,
            track: None,
            integral: false,
            feedforward: false,
            measured: Vec::new(),
            process: Some(process),
        });
    }
    if c.command.is_some() || c.params.is_some() {
        return Err(bad(
            "controller.command",
            "only kind = \"process\" takes command and params",
        ));
    }
    let integral = c.integral.unwrap_or(false);
    let measured = measured_disturbances(c.measured_disturbances.as_deref(), inputs)?;
    // The inputs the controller commands: G, R and track have one row per commanded input.
    let l = model.l() - measured.len();
    let per = if measured.is_empty() {
        "input"
    } else {
        "commanded input (the inputs less the measured disturbances)"
    };
    // With integral action G and Q also cover one integrator per commanded input.
    let size = model.n() + if integral { l } else { 0 };
    let states = if integral {
        "one column per state, then one per integrator"
    } else {
        "one column per state"
    };
    let spec = if c.kind == "lqr" {
        for key in ["poles", "gain", "placement", "domain"] {
            if given.iter().any(|(k, g)| *k == key && *g) {
                return Err(bad(
                    format!("controller.{key}"),
                    "kind = \"lqr\" takes Q and R (its gain comes from the DARE), not poles, gain, placement or domain",
                ));
            }
        }
        let q = c.q.as_ref().map(|q| {
            let field = "controller.Q";
            let m = matrix(
                field,
                q,
                (Some(size), Some(size)),
                if integral {
                    "the plant's states, then one integrator per input"
                } else {
                    "one row and column per state"
                },
            )?;
            definite(field, "Q", &m, lti::dare::Definite::Semi)
        });
        let r = c.r.as_ref().map(|r| {
            let field = "controller.R";
            let m = matrix(
                field,
                r,
                (Some(l), Some(l)),
                &format!("one row and column per {per}"),
            )?;
            definite(field, "R", &m, lti::dare::Definite::Positive)
        });
        FeedbackSpec::Lqr {
            q: q.transpose()?,
            r: r.transpose()?,
        }
    } else {
        for key in ["Q", "R"] {
            if given.iter().any(|(k, g)| *k == key && *g) {
                return Err(bad(
                    format!("controller.{key}"),
                    "Q and R are the weights of kind = \"lqr\"; a state-feedback controller takes poles or gain",
                ));
            }
        }
        let method = placement("controller.placement", &c.placement)?;
        let domain = match c.domain.as_deref() {
            None => Domain::Sampled,
            Some(v) => one_of(
                "controller.domain",
                "domain",
                v,
                &[
                    ("sampled", Domain::Sampled),
                    ("continuous", Domain::Continuous),
                ],
            )?,
        };
        match (&c.poles, &c.gain) {
            (Some(p), None) => FeedbackSpec::Poles {
                poles: poles("controller.poles", p)?,
                placement: method,
                domain,
            },
            (None, Some(g)) => {
                if c.domain.is_some() || c.placement.is_some() {
                    return Err(bad(
                        if c.domain.is_some() {
                            "controller.domain"
                        } else {
                            "controller.placement"
                        },
                        "a given gain is not placed: domain and placement go with poles",
                    ));
                }
                FeedbackSpec::Gain(matrix(
                    "controller.gain",
                    g,
                    (Some(l), Some(size)),
                    &format!("one row per {per}, {states}"),
                )?)
            }
            (Some(_), Some(_)) => {
                return Err(bad("controller.gain", "give poles or gain, not both"));
            }
            (None, None) => {
                return Err(bad(
                    "controller.poles",
                    "a state-feedback controller needs poles = […] or gain = [[…]] (or kind = \"lqr\")",
                ));
            }
        }
    };
    let track = c
        .track
        .as_ref()
        .map(|t| {
            matrix(
                "controller.track",
                t,
                (Some(l), Some(model.n())),
                &format!("one row per {per}: the state combination that follows it"),
            )
        })
        .transpose()?;
    if integral && track.is_none() {
        return Err(bad(
            "controller.integral",
            "integral action needs track = [[…]]: the state combinations (one per input) the integrators hold at r",
        ));
    }
    let feedforward = match c.feedforward.as_deref() {
        None => false,
        Some("what") => true,
        Some(other) => {
            return Err(bad(
                "controller.feedforward",
                format!(
                    "{} is not a feedforward (what: cancel the matched unknown input with the observer's ŵ)",
                    quoted(other)
                ),
            ));
        }
    };
    Ok(ControllerEntry {
        observer: c.observer.clone(),
        spec: Some(spec),
        track,
        integral,
        feedforward,
        measured,
        process: None,
    })
}

/// `controller.measured_disturbances`: input names (`plant.input_names`, default r1, r2, …),
/// each once, not every input; their 0-based indices, ascending.
pub(super) fn measured_disturbances(
    given: Option<&[String]>,
    inputs: &[Named],
) -> Result<Vec<usize>, Bad> {
    let field = "controller.measured_disturbances";
    let mut out = Vec::new();
    for name in given.unwrap_or_default() {
        let Some(j) = inputs.iter().position(|r| &r.name == name) else {
            let known: Vec<&str> = inputs.iter().map(|r| r.name.as_str()).collect();
            return Err(bad(
                field,
                format!(
                    "{} is not an input (inputs: {}){}",
                    quoted(name),
                    known.join(", "),
                    crate::suggest::did_you_mean(name, known.iter().copied())
                ),
            ));
        };
        if out.contains(&j) {
            return Err(bad(field, format!("{} is given twice", quoted(name))));
        }
        out.push(j);
    }
    if !inputs.is_empty() && out.len() == inputs.len() {
        return Err(bad(
            field,
            "every input is a measured disturbance: the controller would command none",
        ));
    }
    out.sort_unstable();
    Ok(out)
}
