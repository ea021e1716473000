//! `launcher design`: every condition with its value and verdict, the design matrices under the
//! papers' names, the observer and closed-loop eigenvalues (continuous and sampled), warnings.

use std::collections::BTreeMap;

use lti::Mat;
use lti::eig::{format_list, sig};
use observer::design::Condition;
use serde::Serialize;
use serde_json::{Value, json};

use scenario::Scenario;

/// The report, in both renderings.
pub struct DesignReport {
    /// The JSON document.
    pub json: Value,
    /// The human-readable text.
    pub text: String,
    /// Whether every design succeeded.
    pub ok: bool,
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

fn conditions_json(c: &[Condition]) -> Value {
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

fn matrix_text(name: &str, m: &Mat) -> String {
    let mut s = format!("    {name} =\n");
    for i in 0..m.nrows() {
        let row: Vec<String> = m
            .row(i)
            .iter()
            .map(|&v| format!("{:>14}", sig(v)))
            .collect();
        s += &format!("      [{} ]\n", row.join(""));
    }
    s
}

fn conditions_text(c: &[Condition]) -> String {
    c.iter()
        .map(|c| {
            format!(
                "    {} {:<52} {}\n",
                if c.ok { "ok  " } else { "FAIL" },
                c.name,
                c.detail
            )
        })
        .collect()
}

/// Designs everything in the scenario and reports it.
pub fn report(s: &Scenario) -> DesignReport {
    let mut ok = true;
    let mut text = format!(
        "{}: {}\n",
        s.name,
        scenario::untrusted::one_line(&s.description)
    );
    let mut observers = Vec::new();
    // Each design made once, then handed to the plan (the controller and the warnings).
    let mut own: Vec<Option<observer::Designed>> = Vec::new();
    for o in &s.observers {
        own.push(None);
        if o.member.is_some() {
            continue;
        }
        text += &format!("\nobserver '{}' ({})\n", o.name, o.kind());
        let Some(spec) = &o.spec else {
            let p = o
                .process
                .as_ref()
                .expect("an observer without a design is a process");
            text += &format!(
                "  external process: {}\n",
                scenario::untrusted::one_line(&p.command.join(" "))
            );
            observers.push(json!({ "name": o.name, "kind": "process", "command": p.command, "params": p.params }));
            continue;
        };
        match crate::plan::design_observer(s, o, spec) {
            Ok(d) => {
                let r = &d.report;
                text += "  conditions:\n";
                text += &conditions_text(&r.conditions);
                text += "  matrices:\n";
                for (n, m) in &r.matrices {
                    text += &matrix_text(n, m);
                }
                // Every list says its domain (issue 30, item 7): s for the continuous poles and
                // fixed modes (ln(z)/dt for a sampled-only design), z for the sampled ones.
                text += &format!("  poles (s):        {}\n", format_list(&r.poles));
                text += &format!(
                    "  poles (z, dt = {}): {}\n",
                    s.dt,
                    format_list(&r.discrete_poles)
                );
                if !r.fixed_modes.is_empty() {
                    text += &format!("  fixed modes (s):  {}\n", format_list(&r.fixed_modes));
                }
                for n in &r.notes {
                    text += &format!("  note: {n}\n");
                }
                let matrices: BTreeMap<&str, Vec<Vec<f64>>> = r
                    .matrices
                    .iter()
                    .map(|(n, m)| (n.as_str(), rows(m)))
                    .collect();
                observers.push(json!({
                    "name": o.name, "kind": o.kind(),
                    "conditions": conditions_json(&r.conditions),
                    "matrices": matrices,
                    "poles": lti::re_im(&r.poles),
                    "discrete_poles": lti::re_im(&r.discrete_poles),
                    "fixed_modes": lti::re_im(&r.fixed_modes),
                    "sampled": sampled_json(&d.runtime, s.dt),
                }));
                *own.last_mut().expect("pushed above") = Some(d);
            }
            Err(e) => {
                ok = false;
                text += "  conditions:\n";
                text += &conditions_text(&e.conditions);
                if !e.conditions.iter().any(|c| !c.ok) {
                    text += &format!("    FAIL {:<52} {}\n", e.condition, e.detail);
                }
                let carried = crate::plan::carried_by(s, &e);
                text += &format!(
                    "  no observer: {} does not hold: {}{carried}\n",
                    e.condition, e.detail
                );
                observers.push(json!({
                    "name": o.name, "kind": o.kind(),
                    "conditions": conditions_json(&e.conditions),
                    "error": format!("{} does not hold: {}{carried}", e.condition, e.detail),
                }));
            }
        }
    }
    let banks = crate::plan::banks(s);
    let (banks_text, diagnosers, banks_ok) = banks_report(s, &banks);
    text += &banks_text;
    ok &= banks_ok;
    let mut controller = Value::Null;
    let mut warnings = Vec::new();
    if let (true, Ok(banks)) = (ok, banks) {
        match crate::plan::complete(s, banks, own) {
            Ok(p) => {
                warnings = p.warnings.clone();
                if let (Some(c), Some(fb)) = (&s.controller, &p.feedback) {
                    let kind =
                        if matches!(c.spec, Some(controller::design::FeedbackSpec::Lqr { .. })) {
                            "lqr"
                        } else {
                            "state-feedback"
                        };
                    let law = match (&fb.integral, c.track.is_some()) {
                        (Some(_), _) => "u = −G x̂ − G_ξ ξ, ξ⁺ = ξ + dt (r − z)",
                        (None, true) => "u = N r − G x̂",
                        (None, false) => "u = r − G x̂",
                    };
                    let ff = if fb.feedforward.is_some() {
                        " − M ŵ"
                    } else {
                        ""
                    };
                    text += &format!(
                        "\ncontroller: {kind}, {law}{ff}, on '{}'\n  G {}\n",
                        c.observer, fb.how
                    );
                    text += &matrix_text("G", &fb.g);
                    let measured: Vec<&str> = fb
                        .measured
                        .iter()
                        .map(|&j| s.names.input[j].name.as_str())
                        .collect();
                    if !measured.is_empty() {
                        text += &format!(
                            "  measured disturbances {}: not commanded, u = r (their [[input]] signals); G, R and the tracked outputs cover the other inputs (designed on their columns Γ_c of Γ_B)\n",
                            measured.join(", ")
                        );
                    }
                    if let Some((gi, ct, m)) = &fb.integral {
                        text += &format!(
                            "  integral action on the tracked outputs z = C_t x, {} (designed on the augmented sampled plant):\n",
                            if m.is_some() {
                                "measured as z = M y"
                            } else {
                                "estimated as z = C_t x̂ (not a combination of the outputs)"
                            }
                        );
                        text += &matrix_text("G_ξ", gi);
                        text += &matrix_text("C_t", ct);
                        if let Some(m) = m {
                            text += &matrix_text("M", m);
                        }
                    } else if c.track.is_some() {
                        text += "  prefilter N = (C_t(I − Φ + Γ_BG)⁻¹Γ_B)⁻¹ (unit DC gain from r to z):\n";
                        text += &matrix_text("N", &fb.n);
                    }
                    if let Some([mw, ..]) = &fb.feedforward {
                        text += "  feedforward: u −= M ŵ_{k−1}, M = Γ_B⁺Γ_E (w enters through the inputs: Γ_E = Γ_B M); ŵ from the observer's estimator, M W:\n";
                        text += &matrix_text("MW", mw);
                    }
                    let closed = if s.discrete
                        || !matches!(
                            c.spec,
                            Some(controller::design::FeedbackSpec::Poles {
                                domain: controller::design::Domain::Continuous,
                                ..
                            }) | Some(controller::design::FeedbackSpec::Gain(_))
                        ) {
                        "ln(z)/dt of the sampled loop"
                    } else {
                        "eig(A − BG)"
                    };
                    text += &format!(
                        "  closed loop, {closed}: {}\n",
                        format_list(&fb.closed_loop)
                    );
                    text += &format!(
                        "  sampled eig(Φ − Γ_BG):       {}\n",
                        format_list(&fb.discrete_closed_loop)
                    );
                    text += &format!("  stable: {}\n", fb.stable());
                    if !fb.stable() {
                        // The run refuses it without --allow-unstable: design says so by its exit code.
                        ok = false;
                        text += "  the run refuses an unstable loop (pass --allow-unstable to run it anyway)\n";
                    }
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
                    controller = json!({
                        "kind": kind,
                        "observer": c.observer,
                        "how": fb.how,
                        "integral": fb.integral.is_some(),
                        "feedforward": fb.feedforward.is_some(),
                        "measured_disturbances": measured,
                        "matrices": matrices,
                        "closed_loop_poles": lti::re_im(&fb.closed_loop),
                        "discrete_closed_loop_poles": lti::re_im(&fb.discrete_closed_loop),
                        "stable": fb.stable(),
                    });
                }
                if let Some((c, p)) = s
                    .controller
                    .as_ref()
                    .and_then(|c| c.process.as_ref().map(|p| (c, p)))
                {
                    text += &format!(
                        "\ncontroller: external process on '{}': {}\n",
                        c.observer,
                        scenario::untrusted::one_line(&p.command.join(" "))
                    );
                    controller = json!({ "kind": "process", "observer": c.observer, "command": p.command, "params": p.params });
                }
            }
            Err(e) => {
                ok = false;
                text += &format!("\ncontroller: {}\n", e.error);
                controller = json!({"kind": "state-feedback", "error": e.error.to_string()});
            }
        }
    }
    if !warnings.is_empty() {
        text += "\nwarnings:\n";
        for w in &warnings {
            text += &format!("  - {w}\n");
        }
    }
    let json = json!({
        "scenario": s.name,
        "observers": observers,
        "controller": controller,
        "diagnosers": diagnosers,
        "warnings": warnings,
    });
    DesignReport { json, text, ok }
}

/// Each bank: its members (role, poles, threshold), and the structure matrix computed from the
/// designs beside the one asked for.
fn banks_report(
    s: &Scenario,
    banks: &Result<Vec<diagnosis::Bank>, crate::plan::PlanError>,
) -> (String, Vec<Value>, bool) {
    let mut text = String::new();
    let mut out = Vec::new();
    if s.diagnosers.is_empty() {
        return (text, out, true);
    }
    match banks {
        Ok(banks) => {
            for b in banks {
                let d = &b.spec;
                text += &format!(
                    "\ndiagnoser '{}' ({} scheme, {} faults, {} members)\n",
                    d.name,
                    d.scheme.name(),
                    d.channels.name(),
                    b.members.len()
                );
                let mut members = Vec::new();
                for (i, m) in b.members.iter().enumerate() {
                    let role = diagnosis::bank::role(d, &b.channels, i);
                    let threshold = match d.threshold {
                        diagnosis::Threshold::Calibrated { runs, margin } => format!(
                            "{margin} × the largest J of {runs} fault-free realisation(s), set when run"
                        ),
                        _ => sig(m.threshold),
                    };
                    text += &format!(
                        "  {} ({role}): {}, sampled poles {}, threshold {threshold}\n",
                        m.name,
                        m.designed.report.kind,
                        format_list(&m.designed.report.discrete_poles)
                    );
                    members.push(json!({
                        "name": m.name, "role": role, "kind": m.designed.report.kind,
                        "outputs": m.outputs.iter().map(|j| j + 1).collect::<Vec<_>>(),
                        "poles": lti::re_im(&m.designed.report.poles),
                        "discrete_poles": lti::re_im(&m.designed.report.discrete_poles),
                        "threshold": m.threshold, "dof": m.dof,
                        "residual_covariance": m.covariance.as_ref().map(rows),
                        "sampled": sampled_json(&m.designed.runtime, s.dt),
                    }));
                }
                text += &format!(
                    "  structure, transient (rows: residuals, columns: {}):\n",
                    b.channels.join(", ")
                );
                for (i, r) in b.structure.iter().enumerate() {
                    text += &format!("    r{} {:?}\n", i + 1, r);
                }
                if d.structure.is_some() {
                    text += "  equals the structure asked for\n";
                }
                match &b.steady {
                    Some(st) => {
                        text += &format!(
                            "  steady-state structure under a constant fault (rows: residuals, columns: {}):\n",
                            b.channels.join(", ")
                        );
                        for (i, r) in st.iter().enumerate() {
                            text += &format!("    r{} {:?}\n", i + 1, r);
                        }
                    }
                    None => {
                        text += "  steady-state structure: not computed (a member's state is not a function of the plant's)\n"
                    }
                }
                out.push(json!({ "name": d.name, "scheme": d.scheme.name(), "faults": d.channels.name(), "channels": b.channels, "structure": b.structure, "steady_state_structure": b.steady, "members": members }));
            }
            (text, out, true)
        }
        Err(e) => {
            text += &format!("\ndiagnoser: {}\n", e.error);
            out.push(json!({ "error": e.error.to_string() }));
            (text, out, false)
        }
    }
}

/// The sampled observer that actually runs, z_{k+1} = F z_k + G u_k + K y_k, x̂_k = P z_k + Q y_k
/// (z_0 = 0), so that a user can check or reuse exactly what the observer process computes.
fn sampled_json(o: &observer::LinearObserver, dt: f64) -> Value {
    let m = |d: &lti::MatData| rows(&Mat::from(d));
    json!({
        "form": "z[k+1] = F z[k] + G u[k] + K y[k], xhat[k] = P z[k] + Q y[k], z[0] = 0",
        "dt": dt,
        "F": m(&o.f), "G": m(&o.g), "K": m(&o.k), "P": m(&o.p), "Q": m(&o.q),
    })
}
