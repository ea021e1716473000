//! From TOML text to a checked [`Scenario`]: [`parse`] reads the text (serde, with located
//! errors), [`build`] checks it section by section, one file per section; the toolbox they all
//! use is [`crate::check`].

mod controller;
mod expect;
mod observers;
mod plant;
mod process;
mod run;
mod true_plant;

use std::path::Path;

use crate::check::{Bad, check_name};
use crate::locate::{line_col, offset, one_based, parse_path};
use crate::raw::RawScenario;
use crate::{Scenario, ScenarioError};

use process::plant_process;

/// `files`: whether the files `[plant.fmu]` and `[plant.replay]` name are looked for (not for a
/// recorded scenario, see [`Scenario::parse_recorded`]).
pub(super) fn parse(path: &Path, text: &str, files: bool) -> Result<Scenario, ScenarioError> {
    let at = |field: &str| offset(text, &parse_path(field)).map(|o| line_col(text, o));
    let error = |Bad { field, reason }: Bad| ScenarioError {
        file: path.to_path_buf(),
        at: at(&field),
        field,
        reason,
    };
    let de = toml::de::Deserializer::parse(text).map_err(|e| ScenarioError {
        file: path.to_path_buf(),
        at: e.span().map(|s| line_col(text, s.start)),
        field: String::new(),
        reason: format!("malformed TOML: {}", first_line(e.message())),
    })?;
    // `time_unit` first: it is what every bare time of the rest means.
    #[derive(serde::Deserialize)]
    struct TimeUnit {
        time_unit: Option<toml::Value>,
    }
    let unit = match toml::from_str::<TimeUnit>(text)
        .ok()
        .and_then(|u| u.time_unit)
    {
        None => None,
        Some(toml::Value::String(u)) => Some(u),
        Some(v) => {
            return Err(error(Bad {
                field: "time_unit".into(),
                reason: format!("{v} is not a time unit (a string: \"h\", \"min\", \"days\")"),
            }));
        }
    };
    let read = lti::units::with_bare_unit(unit.as_deref(), || {
        serde_path_to_error::deserialize::<_, RawScenario>(de)
    })
    .map_err(|reason| {
        error(Bad {
            field: "time_unit".into(),
            reason,
        })
    })?;
    let raw: RawScenario = read.map_err(|e| {
        let field = one_based(&e.path().to_string());
        let field = if field == "." { String::new() } else { field };
        let mut reason = first_line(e.inner().message()).to_string();
        if field.contains("poles") && reason.contains("untagged") {
            reason = "each pole is a number, or [re, im] for a complex pair".into();
        }
        let mut loc = e
            .inner()
            .span()
            .map(|s| line_col(text, s.start))
            .or_else(|| at(&field));
        // serde names an unknown key with the table's span (its header): point at the key's own
        // line, and suggest the known key it was likely meant to be.
        if let Some((key, known)) = unknown_key(&reason) {
            let own = if field.is_empty() || field == key || field.ends_with(&format!(".{key}")) {
                if field.is_empty() {
                    key.clone()
                } else {
                    field.clone()
                }
            } else {
                format!("{field}.{key}")
            };
            loc = at(&own).or(loc);
            reason += &crate::suggest::did_you_mean(&key, known.iter().map(String::as_str));
        }
        ScenarioError {
            file: path.to_path_buf(),
            at: loc,
            field,
            reason,
        }
    })?;
    let mut raw = raw;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    crate::matrix_file::load_all(&mut raw, dir).map_err(error)?;
    build(raw, files.then_some(dir))
        .map_err(error)
        .map(|mut s| {
            s.path = path.to_path_buf();
            s.source = text.to_string();
            s
        })
}

/// From serde's "unknown field `poels`, expected one of `kind`, `poles`, …": the key and the
/// keys its table knows.
fn unknown_key(message: &str) -> Option<(String, Vec<String>)> {
    let rest = message.strip_prefix("unknown field `")?;
    let (key, rest) = rest.split_once('`')?;
    let known = rest
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect();
    Some((key.to_string(), known))
}

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or(s).trim()
}

/// `dir`: the scenario's folder, where the files of `[plant.fmu]` and `[plant.replay]` are
/// looked for (`None`: named, not read).
fn build(raw: RawScenario, dir: Option<&Path>) -> Result<Scenario, Bad> {
    check_name("name", &raw.name, "it names the recording's files")?;
    let (dt, duration, steps) = run::timing(&raw)?;
    let remote = crate::hosts::placements(&raw)?;
    let plant = plant::plant(&raw)?;
    let truth = true_plant::true_plant(&raw, &plant, dt, steps, dir)?;
    let (mut observers, seen) = observers::observers(&raw, &plant.model, truth.noise.as_ref())?;
    let (isolated_fraction, stall_timeout) = run::settings(&raw)?;
    let tail = run::tail(&raw, dt, duration)?;
    let mut taken = seen.clone();
    let diagnosers = crate::fault_diagnosis::diagnosers(
        &raw.diagnoser,
        &plant.model,
        &plant.ff,
        truth.noise.as_ref(),
        dt,
        &mut taken,
    )?;
    observers::bank_members(&diagnosers, &plant.model, &plant.ff, &mut observers);
    observers::observer_cap(raw.observer.len(), &observers, &remote)?;
    let controller = raw
        .controller
        .as_ref()
        .map(|c| controller::controller_entry(c, &plant.model, &seen, &plant.names.input))
        .transpose()?;
    let expect = expect::expect(raw.expect, &seen, &truth.faults, !diagnosers.is_empty())?;
    let n = plant.model.n();
    let (fmu, replay) = (truth.fmu, truth.replay);
    Ok(Scenario {
        remote,
        path: Default::default(),
        name: raw.name,
        description: raw.description,
        dt,
        duration,
        steps,
        x0: plant.x0.unwrap_or_else(|| vec![0.0; n]),
        model: plant.model,
        discrete: plant.discrete,
        operating_point: truth.operating_point,
        state_bound: plant.state_bound,
        names: plant.names,
        disturbances: plant.disturbances,
        measurement_disturbances: plant.measurement_disturbances,
        inputs: plant.inputs,
        observers,
        controller,
        plant_process: match (&fmu, &replay) {
            (Some((_, spec)), _) | (_, Some((_, spec))) => Some(spec.clone()),
            _ => plant_process(&raw.plant.process)?,
        },
        plant_fmu: fmu.map(|(path, _)| path),
        plant_replay: replay.map(|(path, _)| path),
        expect,
        source: String::new(),
        seed: raw.seed.unwrap_or(0),
        isolated_fraction,
        stall_timeout,
        tail,
        time_unit: raw.time_unit,
        noise: truth.noise,
        ff: plant.ff,
        faults: truth.faults,
        diagnosers,
    })
}
