//! modelDescription.xml for FMI 2.0 and FMI 3.0 co-simulation, written directly (the schema
//! we need is small, and the crate stays free of XML and FMI dependencies).
//!
//! The observer runs at its design period only: the step size is declared fixed
//! (canHandleVariableCommunicationStepSize = false, FMI 3 fixedInternalStepSize, the
//! DefaultExperiment's stepSize). Outputs are direct feedthrough of y (x̂ = P z + Q y,
//! r = y − C x̂), listed with the inputs they depend on ([`crate::variables::dependencies`]).

use std::fmt::Write;

use crate::resource::ObserverResource;
use crate::variables::{Layout, Role, dependencies};

/// The FMI version of an export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fmi {
    /// FMI 2.0.
    V2,
    /// FMI 3.0.
    V3,
}

impl Fmi {
    /// The folder under `binaries/` for x86-64 Linux.
    pub fn platform(self) -> &'static str {
        match self {
            Fmi::V2 => "linux64",
            Fmi::V3 => "x86_64-linux",
        }
    }
}

/// A signal's name and unit ("" when none), as the scenario's `[plant]` table gives them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Signal {
    /// E.g. "eta".
    pub name: String,
    /// E.g. "rad".
    pub unit: String,
}

impl Signal {
    fn label(&self) -> String {
        if self.unit.is_empty() {
            self.name.clone()
        } else {
            format!("{} [{}]", self.name, self.unit)
        }
    }
}

/// What a modelDescription says beyond the resource.
#[derive(Debug, Clone)]
pub struct Description {
    /// A C identifier: the library's file name in `binaries/<platform>/`.
    pub model_identifier: String,
    /// The model's name.
    pub model_name: String,
    /// One line.
    pub description: String,
    /// Names of x (n), y (p) and u (l).
    pub states: Vec<Signal>,
    /// The measured outputs.
    pub outputs: Vec<Signal>,
    /// The known inputs.
    pub inputs: Vec<Signal>,
    /// The DefaultExperiment's stop time, s.
    pub stop_time: f64,
}

/// The modelDescription.xml text.
pub fn model_description(
    res: &ObserverResource,
    d: &Description,
    fmi: Fmi,
) -> Result<String, String> {
    let dims = res.dims()?;
    let lay = Layout { dims };
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription");
    attr(
        &mut x,
        "fmiVersion",
        if fmi == Fmi::V2 { "2.0" } else { "3.0" },
    );
    attr(&mut x, "modelName", &d.model_name);
    attr(
        &mut x,
        if fmi == Fmi::V2 {
            "guid"
        } else {
            "instantiationToken"
        },
        &res.token,
    );
    attr(&mut x, "description", &d.description);
    attr(
        &mut x,
        "generationTool",
        concat!(
            "uio-observers launcher export-fmu ",
            env!("CARGO_PKG_VERSION")
        ),
    );
    attr(&mut x, "variableNamingConvention", "flat");
    if fmi == Fmi::V2 {
        attr(&mut x, "numberOfEventIndicators", "0");
    }
    x += ">\n  <CoSimulation";
    attr(&mut x, "modelIdentifier", &d.model_identifier);
    attr(&mut x, "canHandleVariableCommunicationStepSize", "false");
    match fmi {
        Fmi::V2 => attr(&mut x, "canNotUseMemoryManagementFunctions", "true"),
        Fmi::V3 => attr(&mut x, "fixedInternalStepSize", &num(res.dt)),
    }
    x += "/>\n";
    let units = units(d);
    if !units.is_empty() {
        x += "  <UnitDefinitions>\n";
        for u in &units {
            x += "    <Unit";
            attr(&mut x, "name", u);
            x += "/>\n";
        }
        x += "  </UnitDefinitions>\n";
    }
    x += "  <DefaultExperiment";
    attr(&mut x, "startTime", "0");
    attr(&mut x, "stopTime", &num(d.stop_time));
    attr(&mut x, "stepSize", &num(res.dt));
    x += "/>\n  <ModelVariables>\n";
    for role in lay.roles() {
        let start = match (role, &res.operating_point) {
            (Role::U(i), Some(op)) => op.u[i],
            (Role::Y(j), Some(op)) => op.y[j],
            _ => 0.0,
        };
        variable(
            &mut x,
            &lay,
            role,
            describe(d, role),
            unit(d, role),
            start,
            fmi,
        );
    }
    x += "  </ModelVariables>\n  <ModelStructure>\n";
    let outputs: Vec<Role> = lay
        .roles()
        .filter(|r| matches!(r, Role::Xhat(_) | Role::R(_)))
        .collect();
    // Both lists hold every output: each is calculated from the inputs in initialization too.
    for (v2, v3) in [("Outputs", "Output"), ("InitialUnknowns", "InitialUnknown")] {
        if fmi == Fmi::V2 {
            let _ = writeln!(x, "    <{v2}>");
        }
        for &role in &outputs {
            let deps = dependencies(role, &res.q, &res.c, res.xhat0.is_some());
            // FMI 2 names inputs by index (value reference + 1), FMI 3 by value reference.
            let base = if fmi == Fmi::V2 { 1 } else { 0 };
            let list: Vec<String> = deps
                .iter()
                .map(|&m| (lay.vr(Role::Y(m)) + base).to_string())
                .collect();
            match fmi {
                Fmi::V2 => x += &format!("      <Unknown index=\"{}\"", lay.vr(role) + 1),
                Fmi::V3 => x += &format!("    <{v3} valueReference=\"{}\"", lay.vr(role)),
            }
            attr(&mut x, "dependencies", &list.join(" "));
            x += "/>\n";
        }
        if fmi == Fmi::V2 {
            let _ = writeln!(x, "    </{v2}>");
        }
    }
    x += "  </ModelStructure>\n</fmiModelDescription>\n";
    Ok(x)
}

/// One `<ScalarVariable>` (FMI 2) or `<Float64>` (FMI 3).
/// Every unit the variables use, once, in order of first use.
fn units(d: &Description) -> Vec<&str> {
    let mut out: Vec<&str> = Vec::new();
    for s in d.inputs.iter().chain(&d.outputs).chain(&d.states) {
        if !s.unit.is_empty() && !out.contains(&s.unit.as_str()) {
            out.push(&s.unit);
        }
    }
    out
}

/// A variable's unit: its signal's (x̂ its state's, r its output's); "" for none.
fn unit(d: &Description, role: Role) -> &str {
    let (list, i) = match role {
        Role::Time => return "",
        Role::U(i) => (&d.inputs, i),
        Role::Y(j) | Role::R(j) => (&d.outputs, j),
        Role::Xhat(i) => (&d.states, i),
    };
    list.get(i).map_or("", |s| s.unit.as_str())
}

fn variable(
    x: &mut String,
    lay: &Layout,
    role: Role,
    description: String,
    unit: &str,
    start: f64,
    fmi: Fmi,
) {
    let (causality, extra) = match role {
        Role::Time => ("independent", ""),
        Role::U(_) | Role::Y(_) => ("input", ""),
        Role::Xhat(_) | Role::R(_) => ("output", "calculated"),
    };
    *x += if fmi == Fmi::V2 {
        "    <ScalarVariable"
    } else {
        "    <Float64"
    };
    attr(x, "name", &lay.name(role));
    attr(x, "valueReference", &lay.vr(role).to_string());
    if !description.is_empty() {
        attr(x, "description", &description);
    }
    attr(x, "causality", causality);
    attr(x, "variability", "continuous");
    if !extra.is_empty() {
        attr(x, "initial", extra);
    }
    let input = causality == "input";
    if fmi == Fmi::V2 {
        *x += "><Real";
    }
    if !unit.is_empty() {
        attr(x, "unit", unit);
    }
    if input {
        attr(x, "start", &num(start));
    }
    *x += if fmi == Fmi::V2 {
        "/></ScalarVariable>\n"
    } else {
        "/>\n"
    };
}

/// A variable's description, with the scenario's names and units.
fn describe(d: &Description, role: Role) -> String {
    let label = |v: &[Signal], i: usize| v.get(i).map_or(String::new(), Signal::label);
    match role {
        Role::Time => String::new(),
        Role::U(i) => format!(
            "the plant's known input {} as applied over [t_k, t_k + dt): in closed loop the controller's output u, not its reference",
            label(&d.inputs, i)
        ),
        Role::Y(j) => format!(
            "the plant's measured output {} at t_k",
            label(&d.outputs, j)
        ),
        Role::Xhat(i) => format!("estimate of {}", label(&d.states, i)),
        Role::R(j) => format!("residual y - C xhat of {}", label(&d.outputs, j)),
    }
}

/// A number as the shortest text that reads back to the same f64.
fn num(v: f64) -> String {
    format!("{v:?}")
}

/// ` name="value"`, escaped; characters XML 1.0 cannot hold become U+FFFD.
fn attr(x: &mut String, name: &str, value: &str) {
    let _ = write!(x, " {name}=\"");
    for c in value.chars() {
        match c {
            '&' => *x += "&amp;",
            '<' => *x += "&lt;",
            '>' => *x += "&gt;",
            '"' => *x += "&quot;",
            '\t' => *x += "&#9;",
            '\n' => *x += "&#10;",
            '\r' => *x += "&#13;",
            c if (c as u32) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => x.push('\u{fffd}'),
            c => x.push(c),
        }
    }
    x.push('"');
}

#[cfg(test)]
mod tests {
    use super::*;
    use lti::MatData;

    fn resource(xhat0: bool) -> ObserverResource {
        let m = |rows: usize, cols: usize, data: &[f64]| MatData {
            rows,
            cols,
            data: data.to_vec(),
        };
        // n = 3, r = 2, l = 1, p = 2; Q has one non-zero, in row 3 column 2.
        ObserverResource::new(
            "uio",
            0.001,
            m(2, 2, &[0.9, 0.0, 0.0, 0.8]),
            m(2, 1, &[1.0, 0.0]),
            m(2, 2, &[0.1, 0.0, 0.0, 0.1]),
            m(3, 2, &[1.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
            m(3, 2, &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
            m(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
            xhat0.then(|| vec![0.0; 3]),
        )
        .unwrap()
    }

    fn description() -> Description {
        let s = |n: &str, u: &str| Signal {
            name: n.into(),
            unit: u.into(),
        };
        Description {
            model_identifier: "uio".into(),
            model_name: "seed & <test>".into(),
            description: "a \"quoted\" line".into(),
            states: vec![s("x1", "m"), s("x2", ""), s("eta", "rad")],
            outputs: vec![s("y1", ""), s("eta", "rad")],
            inputs: vec![s("force", "N")],
            stop_time: 20.0,
        }
    }

    fn count(text: &str, what: &str) -> usize {
        text.matches(what).count()
    }

    #[test]
    fn fmi3_lists_every_variable_by_value_reference() {
        let x = model_description(&resource(false), &description(), Fmi::V3).unwrap();
        assert!(x.contains("fmiVersion=\"3.0\"") && x.contains("instantiationToken=\"{"));
        assert_eq!(count(&x, "<Float64 "), 1 + 1 + 2 + 3 + 2);
        assert_eq!(count(&x, "causality=\"input\""), 3);
        assert_eq!(count(&x, "causality=\"output\""), 5);
        assert!(x.contains("name=\"u_1\" valueReference=\"1\""));
        assert!(x.contains("name=\"y_2\" valueReference=\"3\""));
        assert!(x.contains(
            "name=\"xhat_3\" valueReference=\"6\" description=\"estimate of eta [rad]\""
        ));
        assert!(x.contains("name=\"r_2\" valueReference=\"8\""));
        // x̂_3 = … + y_2 (vr 3); x̂_1 depends on no input; r_2 on y_2 (C picks x̂_3).
        assert!(x.contains("<Output valueReference=\"6\" dependencies=\"3\"/>"));
        assert!(x.contains("<Output valueReference=\"4\" dependencies=\"\"/>"));
        assert!(x.contains("<Output valueReference=\"7\" dependencies=\"2\"/>"));
        assert!(x.contains("<Output valueReference=\"8\" dependencies=\"3\"/>"));
        assert_eq!(count(&x, "<InitialUnknown "), 5);
        assert!(x.contains("fixedInternalStepSize=\"0.001\"") && x.contains("stepSize=\"0.001\""));
        assert!(
            x.contains("modelName=\"seed &amp; &lt;test&gt;\"") && x.contains("&quot;quoted&quot;")
        );
    }

    #[test]
    fn fmi2_lists_every_variable_by_index() {
        let x = model_description(&resource(true), &description(), Fmi::V2).unwrap();
        assert!(x.contains("fmiVersion=\"2.0\"") && x.contains("guid=\"{"));
        assert_eq!(count(&x, "<ScalarVariable "), 9);
        assert_eq!(count(&x, " start=\"0.0\"/>"), 3);
        // Units from the scenario's: declared once each, on u, y, x̂ and r alike.
        assert!(x.contains("<UnitDefinitions>\n    <Unit name=\"N\"/>\n    <Unit name=\"rad\"/>\n    <Unit name=\"m\"/>\n  </UnitDefinitions>"));
        assert!(
            x.contains("<Real unit=\"N\" start=\"0.0\"/>")
                && x.contains("<Real unit=\"rad\" start=\"0.0\"/>")
        );
        assert_eq!(count(&x, "<Real unit=\"rad\"/>"), 2); // x̂_3 (eta) and r_2 (eta)
        assert!(x.contains("canHandleVariableCommunicationStepSize=\"false\""));
        // With x̂₀ every output depends on both y (indices 3 and 4).
        assert_eq!(count(&x, "<Unknown index="), 10);
        assert!(x.contains("<Unknown index=\"5\" dependencies=\"3 4\"/>"));
        assert!(x.contains("<Unknown index=\"9\" dependencies=\"3 4\"/>"));
        assert!(!x.contains("fixedInternalStepSize"));
    }
}
