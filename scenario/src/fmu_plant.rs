//! `[plant.fmu]`: an FMU (FMI 2.0/3.0 co-simulation) as the true plant. The scenario names
//! which FMU variables carry u, w, y and the true x; the FMU itself is read by the `uio-fmu-plant`
//! component (crate `fmu-plant`), which the launcher also asks to check the file before a run.
//! Here only what the scenario alone can tell is checked: the sizes against `[plant]` and that
//! the file exists.

use std::path::Path;

use serde_json::json;

use super::ProcessSpec;
use super::plant_file::{self, Sizes};
use super::raw::RawFmu;
use crate::check::{Bad, bad};

/// The program that runs an FMU plant (a kit component built beside the launcher).
pub const FMU_PLANT_PROGRAM: &str = lockstep::programs::FMU_PLANT;

/// The FMU plant as the process that runs it, and the FMU's absolute path.
/// `x0`, when the scenario gives it, sets the start values of the `states` variables.
pub(crate) fn plant_fmu(
    raw: &Option<RawFmu>,
    dir: Option<&Path>,
    z: &Sizes,
    x0: Option<&[f64]>,
) -> Result<Option<(std::path::PathBuf, ProcessSpec)>, Bad> {
    let Some(f) = raw else { return Ok(None) };
    let path = plant_file::path("plant.fmu.path", dir, &f.path)?;
    let list = |key: &str,
                given: &Option<Vec<String>>,
                want: usize,
                what: &str|
     -> Result<Vec<String>, Bad> {
        let names = given.clone().unwrap_or_default();
        if names.len() != want {
            return Err(bad(
                format!("plant.fmu.{key}"),
                format!(
                    "{} name{} given; [plant] has {want} {what}",
                    names.len(),
                    if names.len() == 1 { "" } else { "s" }
                ),
            ));
        }
        if let Some(i) = names.iter().position(|s| s.is_empty() || s.contains('\0')) {
            return Err(bad(
                format!("plant.fmu.{key}[{}]", i + 1),
                "an FMU variable name, not empty",
            ));
        }
        Ok(names)
    };
    let inputs = list("inputs", &f.inputs, z.l, "known inputs (columns of B)")?;
    let disturbances = list(
        "disturbances",
        &f.disturbances,
        z.q,
        "unknown inputs (columns of E)",
    )?;
    let outputs = list(
        "outputs",
        &Some(f.outputs.clone()),
        z.p,
        "outputs (rows of C)",
    )?;
    let states = list("states", &Some(f.states.clone()), z.n, "states")?;
    let substeps = f.substeps.unwrap_or(1);
    if substeps == 0 {
        return Err(bad(
            "plant.fmu.substeps",
            "0: at least one doStep per sample",
        ));
    }
    let mut parameters = serde_json::Map::new();
    for (name, v) in f.parameters.iter().flatten() {
        let field = format!("plant.fmu.parameters.{name}");
        let value = match v {
            toml::Value::Float(x) if x.is_finite() => json!(x),
            toml::Value::Integer(i) => json!(i),
            toml::Value::Boolean(b) => json!(b),
            _ => return Err(bad(field, "a start value is a finite number or a boolean")),
        };
        parameters.insert(name.clone(), value);
    }
    let params = json!({
        "path": path.display().to_string(),
        "inputs": inputs,
        "disturbances": disturbances,
        "outputs": outputs,
        "states": states,
        "parameters": parameters,
        "substeps": substeps,
        "x0": x0,
    });
    Ok(Some((
        path,
        ProcessSpec {
            command: vec![FMU_PLANT_PROGRAM.into()],
            params,
        },
    )))
}
