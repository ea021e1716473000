//! An external component (`[plant.process]`, `kind = "process"` observers and controllers): its
//! command and the parameters passed to it as JSON (PROTOCOL.md §3).

use crate::ProcessSpec;
use crate::check::{Bad, bad};
use crate::raw::RawProcess;

/// An external component's command and parameters (PROTOCOL.md §7).
pub(super) fn process_spec(
    f: &str,
    command: &Option<Vec<String>>,
    params: &Option<toml::Table>,
) -> Result<ProcessSpec, Bad> {
    let command = command.clone().ok_or_else(|| {
        bad(
            format!("{f}.command"),
            "a process needs command = [\"program\", \"arg\", …]",
        )
    })?;
    if command.first().is_none_or(|p| p.trim().is_empty()) {
        return Err(bad(format!("{f}.command"), "must name a program first"));
    }
    if let Some(i) = command.iter().position(|a| a.contains('\0')) {
        return Err(bad(
            format!("{f}.command[{}]", i + 1),
            "holds a NUL character",
        ));
    }
    let params = match params {
        Some(t) => {
            json_safe(&format!("{f}.params"), &toml::Value::Table(t.clone()))?;
            serde_json::to_value(t).map_err(|e| bad(format!("{f}.params"), e.to_string()))?
        }
        None => serde_json::Value::Object(Default::default()),
    };
    Ok(ProcessSpec { command, params })
}

/// Refuses what JSON cannot carry: a non-finite number (it would arrive as `null`) and a
/// date-time (it would arrive as an object of toml's making).
pub(super) fn json_safe(field: &str, v: &toml::Value) -> Result<(), Bad> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Err(bad(
            field,
            format!("{x} is not a finite number (params reach the component as JSON)"),
        )),
        toml::Value::Datetime(_) => Err(bad(
            field,
            "a date-time cannot be given as JSON; write it as a string",
        )),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .try_for_each(|(i, x)| json_safe(&format!("{field}[{}]", i + 1), x)),
        toml::Value::Table(t) => t
            .iter()
            .try_for_each(|(k, x)| json_safe(&format!("{field}.{k}"), x)),
        _ => Ok(()),
    }
}

/// `[plant.process]`, if given.
pub(super) fn plant_process(p: &Option<RawProcess>) -> Result<Option<ProcessSpec>, Bad> {
    p.as_ref()
        .map(|p| process_spec("plant.process", &Some(p.command.clone()), &p.params))
        .transpose()
}
