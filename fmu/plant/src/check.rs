//! The scenario's map checked against the FMU: every named variable exists, has the causality
//! and type its role needs; the result is the value references the plant exchanges.
//! `uio-fmu-plant --check` runs this alone (the launcher's pre-flight).

use std::path::Path;

use crate::archive::{self, Causality, Fmu, Type, Var};
use crate::params::Params;

/// A parameter's start value, typed as the FMU declares the parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Start {
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

/// Value references of the map, in the scenario's order.
#[derive(Debug, Clone)]
pub struct Map {
    pub inputs: Vec<u32>,
    pub disturbances: Vec<u32>,
    pub outputs: Vec<u32>,
    pub states: Vec<u32>,
    pub parameters: Vec<(u32, Start)>,
    /// `[plant] x0` as the start values of the state variables (empty: the FMU's own).
    pub x0: Vec<(u32, f64)>,
    /// The Python the FMU's library embeds, found.
    pub python: Option<crate::python::Python>,
}

/// The FMU at `p.path`, its map resolved.
pub fn resolve(p: &Params) -> Result<(Fmu, Map), String> {
    let fmu = archive::read(Path::new(&p.path))?;
    let file = Path::new(&p.path)
        .file_name()
        .map_or(p.path.clone(), |f| f.to_string_lossy().into_owned());
    let find = |field: String, name: &str, ok: &[Causality], role: &str| -> Result<&Var, String> {
        let Some(v) = fmu.vars.get(name) else {
            let hint = scenario::suggest::did_you_mean(name, fmu.vars.keys().map(String::as_str));
            return Err(format!(
                "{field}: {file} has no variable named {}{hint}",
                scenario::untrusted::quoted(name)
            ));
        };
        if !ok.contains(&v.causality) {
            return Err(format!(
                "{field}: '{name}' of {file} is {}, not {role}",
                v.causality.name()
            ));
        }
        if v.array {
            return Err(format!(
                "{field}: '{name}' of {file} is an array variable; the plant exchanges scalars"
            ));
        }
        Ok(v)
    };
    let real = |field: String, name: &str, ok: &[Causality], role: &str| -> Result<u32, String> {
        let v = find(field.clone(), name, ok, role)?;
        if v.ty != Type::Real {
            return Err(format!(
                "{field}: '{name}' of {file} is of type {}, not {}",
                v.ty.name(fmu.version),
                Type::Real.name(fmu.version)
            ));
        }
        Ok(v.vr)
    };
    let list =
        |key: &str, names: &[String], ok: &[Causality], role: &str| -> Result<Vec<u32>, String> {
            names
                .iter()
                .enumerate()
                .map(|(i, n)| real(format!("plant.fmu.{key}[{}]", i + 1), n, ok, role))
                .collect()
        };
    let input = [Causality::Input];
    let inputs = list("inputs", &p.inputs, &input, "an input")?;
    let disturbances = list("disturbances", &p.disturbances, &input, "an input")?;
    let outputs = list("outputs", &p.outputs, &[Causality::Output], "an output")?;
    let states = list(
        "states",
        &p.states,
        &[Causality::Output, Causality::Local],
        "an output or a local variable",
    )?;
    let mut parameters = Vec::new();
    for (name, value) in &p.parameters {
        let field = format!("plant.fmu.parameters.{name}");
        let v = find(field.clone(), name, &[Causality::Parameter], "a parameter")?;
        let start = match (v.ty, value) {
            (Type::Real, serde_json::Value::Number(x)) => x.as_f64().map(Start::Real),
            (Type::Integer, serde_json::Value::Number(x)) => x
                .as_i64()
                .and_then(|i| i32::try_from(i).ok())
                .map(Start::Integer),
            (Type::Boolean, serde_json::Value::Bool(b)) => Some(Start::Boolean(*b)),
            _ => None,
        };
        let Some(start) = start else {
            return Err(format!(
                "{field}: '{name}' of {file} is of type {}; {value} is not a value of it",
                v.ty.name(fmu.version)
            ));
        };
        parameters.push((v.vr, start));
    }
    // x0 sets the states' start values; a state the FMU computes at initialisation cannot be
    // started elsewhere, and x0 is never silently ignored.
    let mut x0 = Vec::new();
    for (i, (name, &value)) in p.states.iter().zip(p.x0.iter().flatten()).enumerate() {
        let v = &fmu.vars[name];
        if !v.settable_start {
            return Err(format!(
                "plant.x0[{}]: the state '{name}' of {file} takes no start value (its initial is calculated): leave x0 out to start from the FMU's own state",
                i + 1
            ));
        }
        x0.push((v.vr, value));
    }
    let python = match &fmu.python {
        Some(symbol) => {
            Some(crate::python::find(symbol).map_err(|e| format!("plant.fmu.path: {file}: {e}"))?)
        }
        None => None,
    };
    Ok((
        fmu,
        Map {
            inputs,
            disturbances,
            outputs,
            states,
            parameters,
            x0,
            python,
        },
    ))
}

/// `uio-fmu-plant --check`: the map (the plant's `params`) on stdin; exit 0, or 2 with one line.
pub fn main() -> std::process::ExitCode {
    crate::request::answer(
        crate::request::read::<Params>("params")
            .and_then(|p| resolve(&p))
            .map(|_| None),
    )
}
