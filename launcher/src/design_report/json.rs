//! The design report as JSON: the same sections as the text, matrices as arrays of rows, poles
//! as [re, im] pairs, and for every observer the sampled form that runs.

use std::collections::BTreeMap;

use lti::Mat;
use observer::design::Condition;
use serde::Serialize;
use serde_json::{Value, json};

use super::sections::{ControllerSection, DesignReport, ObserverSection};

impl DesignReport {
    /// The JSON document.
    pub fn json(&self) -> Value {
        render(self)
    }
}

fn render(r: &DesignReport) -> Value {
    let observers: Vec<Value> = r.observers.iter().map(|o| observer(o, r.dt)).collect();
    let diagnosers: Vec<Value> = match &r.banks {
        None => Vec::new(),
        Some(Ok(banks)) => banks.iter().map(|b| bank(b, r.dt)).collect(),
        Some(Err(e)) => vec![json!({ "error": e })],
    };
    json!({
        "scenario": r.scenario,
        "observers": observers,
        "controller": controller(&r.controller),
        "diagnosers": diagnosers,
        "warnings": r.warnings,
    })
}

fn rows(m: &Mat) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect()
}

#[derive(Serialize)]
struct JsonCondition<'a> {
    name: &'a str,
    ok: bool,
    detail: &'a str,
}

fn conditions(c: &[Condition]) -> Value {
    json!(
        c.iter()
            .map(|c| JsonCondition {
                name: &c.name,
                ok: c.ok,
                detail: &c.detail
            })
            .collect::<Vec<_>>()
    )
}

/// The sampled observer that actually runs, z_{k+1} = F z_k + G u_k + K y_k, x̂_k = P z_k + Q y_k
/// (z_0 = 0), so that a user can check or reuse exactly what the observer process computes.
fn sampled(o: &observer::LinearObserver, dt: f64) -> Value {
    let m = |d: &lti::MatData| rows(&Mat::from(d));
    json!({
        "form": "z[k+1] = F z[k] + G u[k] + K y[k], xhat[k] = P z[k] + Q y[k], z[0] = 0",
        "dt": dt,
        "F": m(&o.f), "G": m(&o.g), "K": m(&o.k), "P": m(&o.p), "Q": m(&o.q),
    })
}

fn observer(o: &ObserverSection, dt: f64) -> Value {
    match o {
        ObserverSection::Process {
            name,
            command,
            params,
        } => json!({ "name": name, "kind": "process", "command": command, "params": params }),
        ObserverSection::Designed {
            name,
            kind,
            designed,
        } => {
            let r = &designed.report;
            let matrices: BTreeMap<&str, Vec<Vec<f64>>> = r
                .matrices
                .iter()
                .map(|(n, m)| (n.as_str(), rows(m)))
                .collect();
            json!({
                "name": name, "kind": kind,
                "conditions": conditions(&r.conditions),
                "matrices": matrices,
                "poles": lti::re_im(&r.poles),
                "discrete_poles": lti::re_im(&r.discrete_poles),
                "fixed_modes": lti::re_im(&r.fixed_modes),
                "sampled": sampled(&designed.runtime, dt),
            })
        }
        ObserverSection::Refused {
            name,
            kind,
            error: e,
            carried,
        } => json!({
            "name": name, "kind": kind,
            "conditions": conditions(&e.conditions),
            "error": format!("{} does not hold: {}{carried}", e.condition, e.detail),
        }),
    }
}

fn bank(b: &diagnosis::Bank, dt: f64) -> Value {
    let d = &b.spec;
    let members: Vec<Value> = b
        .members
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let mut member = json!({
                "name": m.name, "role": diagnosis::bank::role(d, &b.channels, i),
                "kind": m.designed.report.kind,
                "outputs": m.outputs.iter().map(|j| j + 1).collect::<Vec<_>>(),
                "poles": lti::re_im(&m.designed.report.poles),
                "discrete_poles": lti::re_im(&m.designed.report.discrete_poles),
                "threshold": m.threshold, "dof": m.dof,
                "residual_covariance": m.covariance.as_ref().map(rows),
                "sampled": sampled(&m.designed.runtime, dt),
            });
            // Only a bank with a GLR test has the key (the others' JSON as before).
            if let Some(g) = &m.glr {
                member["glr"] = json!({
                    "window": g.window, "threshold": g.threshold,
                    "channels": g.channels.iter().map(|&j| &b.channels[j]).collect::<Vec<_>>(),
                    "innovation_covariance": rows(&g.innovation),
                    "predictor_gain": rows(&g.gain),
                });
            }
            member
        })
        .collect();
    json!({
        "name": d.name, "scheme": d.scheme.name(), "faults": d.channels.name(),
        "channels": b.channels, "structure": b.structure,
        "steady_state_structure": b.steady, "members": members,
    })
}

fn controller(c: &ControllerSection) -> Value {
    match c {
        ControllerSection::None => Value::Null,
        ControllerSection::Error(e) => json!({ "kind": "state-feedback", "error": e }),
        ControllerSection::Process {
            observer,
            command,
            params,
        } => {
            json!({ "kind": "process", "observer": observer, "command": command, "params": params })
        }
        ControllerSection::Feedback {
            kind,
            observer,
            feedback: fb,
            measured,
            ..
        } => {
            let mut matrices = json!({"G": rows(&fb.g), "N": rows(&fb.n)});
            if let Some((gi, ct, m)) = &fb.integral {
                matrices["G_xi"] = json!(rows(gi));
                matrices["C_t"] = json!(rows(ct));
                if let Some(m) = m {
                    matrices["M"] = json!(rows(m));
                }
            }
            if let Some([mw, a, b]) = &fb.feedforward {
                matrices["MW"] = json!(rows(mw));
                matrices["MWCPhi"] = json!(rows(a));
                matrices["MWCGamma_B"] = json!(rows(b));
            }
            json!({
                "kind": kind,
                "observer": observer,
                "how": fb.how,
                "integral": fb.integral.is_some(),
                "feedforward": fb.feedforward.is_some(),
                "measured_disturbances": measured,
                "matrices": matrices,
                "closed_loop_poles": lti::re_im(&fb.closed_loop),
                "discrete_closed_loop_poles": lti::re_im(&fb.discrete_closed_loop),
                "stable": fb.stable(),
            })
        }
    }
}
