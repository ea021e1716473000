//! From TOML text to a checked [`Scenario`].

use std::collections::BTreeSet;
use std::path::Path;

use controller::design::{Domain, FeedbackSpec};
use lti::place::Method;
use lti::signal::Signal;
use lti::{Mat, Model, PoleSpec, Poles};
use observer::Spec;
use observer::design::Path as HuiZakPath;
use observer::design::{Gain, Weights};

use super::limits::{MAX_FAULTS, MAX_OBSERVERS, MAX_STEPS};
use super::locate::{line_col, offset, one_based, parse_path};
use super::raw::{RawController, RawExpect, RawObserver, RawPole, RawProcess, RawScenario, Rows};
use super::untrusted::quoted;
use super::{
    ControllerEntry, Named, ObserverEntry, ProcessSpec, Scenario, ScenarioError, SignalNames,
};

/// Observer kinds a scenario may name.
pub const KINDS: [&str; 8] = [
    "luenberger",
    "chen-patton-uio",
    "das-ghosal",
    "das-ghosal-uio",
    "gi-full-order",
    "cumming",
    "hui-zak-uio",
    "kalman",
];

/// Field path and reason, before the location is looked up.
pub(crate) type Bad = (String, String);

pub(crate) fn bad(field: impl Into<String>, reason: impl Into<String>) -> Bad {
    (field.into(), reason.into())
}

/// `files`: whether the files `[plant.fmu]` and `[plant.replay]` name are looked for (not for a
/// recorded scenario, see [`Scenario::parse_recorded`]).
pub(super) fn parse(path: &Path, text: &str, files: bool) -> Result<Scenario, ScenarioError> {
    let at = |field: &str| offset(text, &parse_path(field)).map(|o| line_col(text, o));
    let error = |(field, reason): Bad| ScenarioError {
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
    let raw: RawScenario = serde_path_to_error::deserialize(de).map_err(|e| {
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
    super::matrix_file::load_all(&mut raw, dir).map_err(error)?;
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

pub(crate) fn finite(field: &str, v: f64) -> Result<f64, Bad> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(bad(field, format!("{v} is not a finite number")))
    }
}

/// A matrix from rows: not empty, not ragged, finite, and of the required shape.
pub(crate) fn matrix(
    field: &str,
    rows: &Rows,
    shape: (Option<usize>, Option<usize>),
    why: &str,
) -> Result<Mat, Bad> {
    let rows = match rows {
        Rows::Inline(rows) => rows,
        Rows::File(name) => {
            return Err(bad(
                field,
                format!("{}: a matrix file is read before validation", quoted(name)),
            ));
        }
    };
    if rows.is_empty() || rows.iter().all(|r| r.is_empty()) {
        return Err(bad(field, "must not be empty"));
    }
    let cols = rows[0].len();
    for (i, r) in rows.iter().enumerate() {
        if r.len() != cols {
            return Err(bad(
                format!("{field}[{}]", i + 1),
                format!(
                    "ragged: row {} has {} entries, row 1 has {cols}",
                    i + 1,
                    r.len()
                ),
            ));
        }
        for (j, &v) in r.iter().enumerate() {
            if !v.is_finite() {
                return Err(bad(
                    format!("{field}[{}]", i + 1),
                    format!("entry {} is {v}, not a finite number", j + 1),
                ));
            }
        }
    }
    let (want_r, want_c) = shape;
    if want_r.is_some_and(|r| r != rows.len()) || want_c.is_some_and(|c| c != cols) {
        let show = |o: Option<usize>| o.map_or("·".to_string(), |v| v.to_string());
        return Err(bad(
            field,
            format!(
                "is {}×{cols}, must be {}×{} ({why})",
                rows.len(),
                show(want_r),
                show(want_c)
            ),
        ));
    }
    Ok(Mat::from_fn(rows.len(), cols, |i, j| rows[i][j]))
}

fn signals(field: &str, list: &[Signal], count: usize, source: &str) -> Result<Vec<Signal>, Bad> {
    if list.len() != count {
        return Err(bad(
            field,
            format!(
                "{} [[{field}]] entr{} given, {source} needs {count} (one per column, in order)",
                list.len(),
                if list.len() == 1 { "y" } else { "ies" }
            ),
        ));
    }
    for (i, s) in list.iter().enumerate() {
        s.validate()
            .map_err(|(f, reason)| bad(format!("{field}[{}].{f}", i + 1), reason))?;
    }
    Ok(list.to_vec())
}

/// `<prefix>_names` and `<prefix>_units`: one entry per component (`count`, described by `what`
/// with `{}` for the count and `{s}` for its plural), names non-empty; defaults `<letter>1`, `<letter>2`, … and no unit.
fn names(
    prefix: &str,
    names: Option<&Vec<String>>,
    units: Option<&Vec<String>>,
    count: usize,
    what: &str,
    letter: &str,
) -> Result<Vec<Named>, Bad> {
    for (key, list) in [("names", names), ("units", units)] {
        if let Some(list) = list
            && list.len() != count
        {
            let what = what
                .replace("{}", &count.to_string())
                .replace("{s}", if count == 1 { "" } else { "s" });
            return Err(bad(
                format!("{prefix}_{key}"),
                format!(
                    "has {} entr{}, {what}",
                    list.len(),
                    if list.len() == 1 { "y" } else { "ies" }
                ),
            ));
        }
    }
    if let Some(i) = names.and_then(|v| v.iter().position(|s| s.trim().is_empty())) {
        return Err(bad(
            format!("{prefix}_names[{}]", i + 1),
            "must not be empty",
        ));
    }
    // Names and units end up in plot text, view titles and CSV headers: no control characters.
    for (key, list) in [("names", names), ("units", units)] {
        if let Some((i, s)) = list.and_then(|v| {
            v.iter()
                .enumerate()
                .find(|(_, s)| s.chars().any(char::is_control))
        }) {
            return Err(bad(
                format!("{prefix}_{key}[{}]", i + 1),
                format!("{} holds a control character", quoted(s)),
            ));
        }
    }
    Ok((0..count)
        .map(|i| Named {
            name: names.map_or_else(|| format!("{letter}{}", i + 1), |v| v[i].clone()),
            unit: units.map_or_else(String::new, |v| v[i].clone()),
        })
        .collect())
}

pub(crate) fn poles(field: &str, raw: &[RawPole]) -> Result<Poles, Bad> {
    let mut specs = Vec::new();
    for (i, p) in raw.iter().enumerate() {
        let f = format!("{field}[{}]", i + 1);
        match p {
            RawPole::Real(x) => specs.push(PoleSpec::Real(finite(&f, *x)?)),
            RawPole::Pair(v) if v.len() == 2 => {
                let (re, im) = (finite(&f, v[0])?, finite(&f, v[1])?);
                if im != 0.0 && specs.contains(&PoleSpec::Pair(re, -im)) {
                    return Err(bad(
                        f,
                        format!(
                            "[{re}, {im}] is the conjugate of [{re}, {}], which already implies it",
                            -im
                        ),
                    ));
                }
                specs.push(PoleSpec::Pair(re, im));
            }
            RawPole::Pair(v) => {
                return Err(bad(
                    f,
                    format!(
                        "a complex pair is written [re, im]; this has {} numbers",
                        v.len()
                    ),
                ));
            }
        }
    }
    // An empty list is valid: a design whose pair has only fixed modes takes no free poles, and
    // the design itself says how many it needs when the count is wrong.
    Poles::new(specs).map_err(|e| bad(field, e.to_string()))
}

pub(crate) fn placement(field: &str, p: &Option<String>) -> Result<Method, Bad> {
    match p.as_deref() {
        None | Some("robust") | Some("yt") => Ok(Method::YangTits),
        Some("knv0") => Ok(Method::Knv0),
        Some("matlab") => Ok(Method::Matlab),
        Some("ackermann") => Ok(Method::Ackermann),
        Some(other) => Err(bad(
            field,
            format!(
                "{} is not a placement (robust, knv0, matlab, ackermann){}",
                quoted(other),
                crate::suggest::did_you_mean(other, ["robust", "knv0", "matlab", "ackermann"])
            ),
        )),
    }
}

/// Longest scenario or observer name, in characters. Names become file names (the recording,
/// the summary, PNGs, CSVs, component configurations) and iceoryx2 service names: this keeps
/// every one of them far below the file system's 255-byte limit, checked before anything is
/// created.
pub const MAX_NAME_CHARS: usize = 64;

/// A name: 1 to [`MAX_NAME_CHARS`] ASCII letters, digits, '-' or '_'.
pub(crate) fn check_name(field: &str, name: &str, why: &str) -> Result<(), Bad> {
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        return Err(bad(
            field,
            format!(
                "{} must be non-empty letters, digits, '-' or '_' ({why})",
                quoted(name)
            ),
        ));
    }
    if name.len() > MAX_NAME_CHARS {
        return Err(bad(
            field,
            format!(
                "{} is {} characters long, at most {MAX_NAME_CHARS} are allowed ({why})",
                quoted(name),
                name.len()
            ),
        ));
    }
    Ok(())
}

/// `dir`: the scenario's folder, where the files of `[plant.fmu]` and `[plant.replay]` are
/// looked for (`None`: named, not looked for).
fn build(raw: RawScenario, dir: Option<&Path>) -> Result<Scenario, Bad> {
    check_name("name", &raw.name, "it names the recording's files")?;
    let dt = finite("dt", raw.dt)?;
    let duration = finite("duration", raw.duration)?;
    if dt <= 0.0 {
        return Err(bad("dt", format!("{dt} must be > 0")));
    }
    if duration <= 0.0 {
        return Err(bad("duration", format!("{duration} must be > 0")));
    }
    if duration < dt {
        return Err(bad(
            "duration",
            format!("{duration} is shorter than one step (dt = {dt})"),
        ));
    }
    let steps_f = (duration / dt).round();
    if (steps_f * dt - duration).abs() > 1e-9 * duration {
        return Err(bad(
            "duration",
            format!("{duration} is not a whole number of steps of dt = {dt}"),
        ));
    }
    if steps_f > MAX_STEPS as f64 {
        return Err(bad(
            "duration",
            format!("{steps_f} steps is more than {MAX_STEPS} (duration / dt)"),
        ));
    }
    let steps = steps_f as u64;
    let remote = super::hosts::placements(&raw)?;

    // Plant: continuous (A, B, E) or, for an identified model, discrete (Φ, Γ_B, Γ_E per step).
    let p = &raw.plant;
    let discrete = match p.time.as_deref() {
        None | Some("continuous") => false,
        Some("discrete") => true,
        Some(other) => {
            return Err(bad(
                "plant.time",
                format!(
                    "{} is not a time domain (continuous, discrete){}",
                    quoted(other),
                    crate::suggest::did_you_mean(other, ["continuous", "discrete"])
                ),
            ));
        }
    };
    let ([ka, kb, ke], given, other) = if discrete {
        (
            ["Phi", "Gamma_B", "Gamma_E"],
            [&p.phi, &p.gamma_b, &p.gamma_e],
            [
                ("A", p.a.is_some()),
                ("B", p.b.is_some()),
                ("E", p.e.is_some()),
            ],
        )
    } else {
        (
            ["A", "B", "E"],
            [&p.a, &p.b, &p.e],
            [
                ("Phi", p.phi.is_some()),
                ("Gamma_B", p.gamma_b.is_some()),
                ("Gamma_E", p.gamma_e.is_some()),
            ],
        )
    };
    if let Some((key, _)) = other.iter().find(|(_, g)| *g) {
        let why = if discrete {
            "a discrete-time plant (time = \"discrete\") is given per step by Phi, Gamma_B and Gamma_E"
        } else {
            "Phi, Gamma_B and Gamma_E give a discrete-time plant: add time = \"discrete\" (or give A, B and E)"
        };
        return Err(bad(format!("plant.{key}"), why));
    }
    let [a_rows, b_rows, e_rows] = given;
    let required = |rows: &Option<Rows>, key: &str| {
        rows.clone()
            .ok_or_else(|| bad("plant", format!("missing field `{key}`")))
    };
    let a = matrix(
        &format!("plant.{ka}"),
        &required(a_rows, ka)?,
        (None, None),
        "",
    )?;
    let n = a.nrows();
    if a.ncols() != n {
        return Err(bad(
            format!("plant.{ka}"),
            format!("is {}×{}, must be square", n, a.ncols()),
        ));
    }
    let b = matrix(
        &format!("plant.{kb}"),
        &required(b_rows, kb)?,
        (Some(n), None),
        "n rows, one column per known input",
    )?;
    let c = matrix("plant.C", &p.c, (None, Some(n)), "one column per state")?;
    let pn = c.nrows();
    let e = match e_rows {
        Some(rows) => matrix(
            &format!("plant.{ke}"),
            rows,
            (Some(n), None),
            "n rows, one column per unknown input",
        )?,
        None => Mat::zeros(n, 0),
    };
    let d = match &p.d {
        Some(rows) => matrix(
            "plant.D",
            rows,
            (Some(pn), None),
            "one row per output, one column per measurement disturbance",
        )?,
        None => Mat::zeros(pn, 0),
    };
    // x(0): required, but an FMU plant starts from its own start values when it is left out
    // (given, it sets the start values of the FMU's state variables).
    let x0 = match &p.x0 {
        Some(x0) => Some(x0.clone()),
        None if p.fmu.is_some() => None,
        None => {
            return Err(bad(
                "plant.x0",
                "missing: the plant's state at t = 0 (only an FMU plant may leave it out and start from its own start values)",
            ));
        }
    };
    if let Some(x0) = &x0 {
        if x0.len() != n {
            return Err(bad(
                "plant.x0",
                format!("has {} entries, the plant has {n} states", x0.len()),
            ));
        }
        for (i, &v) in x0.iter().enumerate() {
            finite(&format!("plant.x0[{}]", i + 1), v)?;
        }
    }
    let state_bound = finite("plant.state_bound", p.state_bound.unwrap_or(1e9))?;
    if state_bound <= 0.0 {
        return Err(bad("plant.state_bound", "must be > 0"));
    }
    let layout_names = SignalNames {
        state: names(
            "plant.state",
            p.state_names.as_ref(),
            p.state_units.as_ref(),
            n,
            "the plant has {} state{s}",
            "x",
        )?,
        output: names(
            "plant.output",
            p.output_names.as_ref(),
            p.output_units.as_ref(),
            pn,
            "C has {} row{s} (outputs)",
            "y",
        )?,
        input: names(
            "plant.input",
            p.input_names.as_ref(),
            p.input_units.as_ref(),
            b.ncols(),
            "B has {} column{s} (known inputs)",
            "r",
        )?,
        disturbance: names(
            "plant.disturbance",
            p.disturbance_names.as_ref(),
            p.disturbance_units.as_ref(),
            e.ncols(),
            "E has {} column{s} (unknown inputs)",
            "w",
        )?,
        measurement_disturbance: names(
            "plant.measurement_disturbance",
            p.measurement_disturbance_names.as_ref(),
            p.measurement_disturbance_units.as_ref(),
            d.ncols(),
            "D has {} column{s} (measurement disturbances)",
            "v",
        )?,
    };

    // Replayed data holds its own u, w and v: the signals may then be left out (zero).
    let given = |list: &[Signal], count: usize| {
        if p.replay.is_some() && list.is_empty() {
            vec![Signal::Constant { value: 0.0 }; count]
        } else {
            list.to_vec()
        }
    };
    let disturbances = signals(
        "disturbance",
        &given(&raw.disturbance, e.ncols()),
        e.ncols(),
        "plant.E",
    )?;
    let measurement_disturbances = signals(
        "measurement_disturbance",
        &given(&raw.measurement_disturbance, d.ncols()),
        d.ncols(),
        "plant.D",
    )?;
    let inputs = signals("input", &given(&raw.input, b.ncols()), b.ncols(), "plant.B")?;
    let ff = match &p.ff {
        Some(rows) => matrix(
            "plant.Ff",
            rows,
            (Some(n), None),
            "n rows, one column per component fault",
        )?,
        None => Mat::zeros(n, 0),
    };
    let model = Model { a, b, c, e, d };
    if discrete {
        // What needs the continuous A: a continuous noise intensity (Van Loan), an external
        // plant (PROTOCOL.md §3 sends A), the banks' structure from Markov parameters.
        if raw.noise.as_ref().is_some_and(|z| z.process.is_some()) {
            return Err(bad(
                "noise.process",
                "a discrete-time plant takes process_discrete (Q_d per step), not a continuous intensity",
            ));
        }
        if p.process.is_some() {
            return Err(bad(
                "plant.process",
                "time = \"discrete\" is for the built-in plant: an external plant simulates itself",
            ));
        }
        if !raw.diagnoser.is_empty() {
            return Err(bad(
                "diagnoser[1]",
                "diagnosis banks need a continuous-time plant (time = \"discrete\" does not take [[diagnoser]] yet)",
            ));
        }
    }
    let noise = super::fault_diagnosis::noise(&raw.noise, &model, dt)?;
    if raw.fault.len() > MAX_FAULTS {
        return Err(bad(
            format!("fault[{}]", MAX_FAULTS + 1),
            format!(
                "{} faults: at most {MAX_FAULTS} (each adds two values to every plant sample and two recorded signals)",
                raw.fault.len()
            ),
        ));
    }
    let faults = super::fault_diagnosis::faults(&raw.fault, &model, &ff, dt)?;
    if p.process.is_some()
        && let Some(what) = [
            (!raw.fault.is_empty(), "fault"),
            (raw.noise.is_some(), "noise"),
        ]
        .iter()
        .find(|w| w.0)
        .map(|w| w.1)
    {
        return Err(bad(
            what,
            "faults and noise are applied by the built-in plant: an external plant (plant.process) models its own",
        ));
    }
    if p.fmu.is_some() {
        // Actuator faults act on the FMU's inputs and sensor faults and measurement noise on its
        // outputs; what acts inside (F_f, process noise) is the FMU's own.
        if p.process.is_some() {
            return Err(bad(
                "plant.fmu",
                "one true plant: [plant.process] or [plant.fmu], not both",
            ));
        }
        if let Some(i) = faults
            .iter()
            .position(|f| matches!(f.target, plant::fault::Target::Component(_)))
        {
            return Err(bad(
                format!("fault[{}].target", i + 1),
                "a component fault acts through F_f of the built-in plant: an FMU plant takes actuator and sensor faults",
            ));
        }
        if raw
            .noise
            .as_ref()
            .is_some_and(|z| z.process.is_some() || z.process_discrete.is_some())
        {
            return Err(bad(
                "noise.process",
                "process noise enters the state, which an FMU plant keeps to itself: an FMU plant takes measurement noise only",
            ));
        }
    }
    let sizes = super::plant_file::Sizes {
        n,
        p: model.c.nrows(),
        l: model.b.ncols(),
        q: model.e.ncols(),
    };
    let fmu = super::fmu_plant::plant_fmu(&p.fmu, dir, &sizes, x0.as_deref())?;
    if p.replay.is_some() {
        // Recorded data holds its own faults and noise: [[fault]] and [noise] then describe
        // them (for the design and the scoring), and nothing is applied.
        if p.process.is_some() || p.fmu.is_some() {
            return Err(bad(
                "plant.replay",
                "one true plant: [plant.process], [plant.fmu] or [plant.replay]",
            ));
        }
        if raw.controller.is_some() {
            return Err(bad(
                "controller",
                "the plant is replayed from recorded data, which cannot react to a controller: a replay is open loop",
            ));
        }
    }
    let builtin = p.process.is_none() && p.fmu.is_none() && p.replay.is_none();
    let operating_point = super::operating_point::operating_point(
        &p.operating_point,
        &model,
        discrete,
        builtin,
        &layout_names,
    )?;
    let replay = super::replay_plant::plant_replay(
        &p.replay,
        dir,
        &sizes,
        model.d.ncols(),
        dt,
        steps,
        operating_point.as_ref().map(|op| &op.u[..]),
    )?;

    // Observers.
    let mut seen = BTreeSet::new();
    let mut observers = Vec::new();
    for (i, o) in raw.observer.iter().enumerate() {
        let f = format!("observer[{}]", i + 1);
        check_name(
            &format!("{f}.name"),
            &o.name,
            "it names signals, files and a process",
        )?;
        if !seen.insert(o.name.clone()) {
            return Err(bad(
                format!("{f}.name"),
                format!("two observers are named {}", quoted(&o.name)),
            ));
        }
        observers.push(if o.kind == "process" {
            let process = process_spec(&f, &o.command, &o.params)?;
            for (key, given) in [
                ("poles", o.poles.is_some()),
                ("placement", o.placement.is_some()),
                ("H", o.h.is_some()),
                ("decay", o.decay.is_some()),
                ("path", o.path.is_some()),
                ("gain", o.gain.is_some()),
                ("Q", o.q.is_some()),
                ("R", o.r.is_some()),
                ("xhat0", o.xhat0.is_some()),
            ] {
                if given {
                    return Err(bad(
                        format!("{f}.{key}"),
                        "a process observer takes no design keys (only command and params)",
                    ));
                }
            }
            ObserverEntry {
                name: o.name.clone(),
                spec: None,
                process: Some(process),
                member: None,
                xhat0: None,
            }
        } else {
            if o.command.is_some() || o.params.is_some() {
                return Err(bad(
                    format!("{f}.command"),
                    format!(
                        "only kind = \"process\" takes command and params, not {}",
                        quoted(&o.kind)
                    ),
                ));
            }
            let xhat0 = o
                .xhat0
                .as_ref()
                .map(|x| initial_estimate(&format!("{f}.xhat0"), x, model.n()))
                .transpose()?;
            ObserverEntry {
                name: o.name.clone(),
                spec: Some(observer_spec(&f, o, &model, noise.as_ref())?),
                process: None,
                member: None,
                xhat0,
            }
        });
    }
    let isolated_fraction = match raw.isolated_fraction {
        None => 0.9,
        Some(x) if x.is_finite() && x > 0.0 && x <= 1.0 => x,
        Some(x) => {
            return Err(bad(
                "isolated_fraction",
                format!("{x} must be a share of the fault's time, 0 < x ≤ 1"),
            ));
        }
    };
    let stall_timeout = match raw.stall_timeout {
        None => crate::limits::STALL_TIMEOUT,
        Some(v) => crate::limits::stall_timeout(v).map_err(|r| bad("stall_timeout", r))?,
    };
    let mut taken = seen.clone();
    let diagnosers = super::fault_diagnosis::diagnosers(
        &raw.diagnoser,
        &model,
        &ff,
        noise.as_ref(),
        &mut taken,
    )?;
    // Each bank member runs as an observer of its own, after the scenario's observers.
    for (di, d) in diagnosers.iter().enumerate() {
        for j in 0..diagnosis::bank::monitored(d, &model, &ff).0.len() {
            observers.push(ObserverEntry {
                name: format!("{}-{}", d.name, j + 1),
                spec: None,
                process: None,
                member: Some((di, j)),
                xhat0: None,
            });
        }
    }

    observer_cap(raw.observer.len(), &observers, &remote)?;

    let controller = raw
        .controller
        .as_ref()
        .map(|c| controller_entry(c, &model, &seen, &layout_names.input))
        .transpose()?;
    let expect = raw.expect.unwrap_or_default();
    check_expect(&expect, &seen)?;
    for (name, &v) in &expect.detection_delay {
        let f = format!("expect.detection_delay.{name}");
        if !faults.iter().any(|x| &x.name == name) {
            return Err(bad(f, format!("no fault named {}", quoted(name))));
        }
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(f, format!("{v} must be a finite number > 0")));
        }
    }
    let judged = !expect.detection_delay.is_empty()
        || expect.correct_isolation.is_some()
        || expect.first_isolation_correct.is_some()
        || expect.false_alarms.is_some();
    if judged && diagnosers.is_empty() {
        return Err(bad(
            "expect",
            "detection, isolation and false alarms are judged by a [[diagnoser]]; the scenario has none",
        ));
    }
    Ok(Scenario {
        remote,
        path: Default::default(),
        name: raw.name,
        description: raw.description,
        dt,
        duration,
        steps,
        model,
        discrete,
        x0: x0.unwrap_or_else(|| vec![0.0; n]),
        operating_point,
        state_bound,
        names: layout_names,
        disturbances,
        measurement_disturbances,
        inputs,
        observers,
        controller,
        plant_process: match (&fmu, &replay) {
            (Some((_, spec)), _) | (_, Some((_, spec))) => Some(spec.clone()),
            _ => plant_process(&p.process)?,
        },
        plant_fmu: fmu.map(|(path, _)| path),
        plant_replay: replay.map(|(path, _)| path),
        expect,
        source: String::new(),
        seed: raw.seed.unwrap_or(0),
        isolated_fraction,
        stall_timeout,
        noise,
        ff,
        faults,
        diagnosers,
    })
}

/// At most [`MAX_OBSERVERS`] observer processes (a bank's members share one,
/// [`crate::observer_processes`]): each subscribes to the plant's samples. The field named is
/// the `[[observer]]` or `[[diagnoser]]` that goes past the cap.
fn observer_cap(
    own: usize,
    observers: &[ObserverEntry],
    remote: &std::collections::BTreeMap<String, super::Remote>,
) -> Result<(), Bad> {
    let processes = crate::observer_processes(observers, remote);
    if processes.len() <= MAX_OBSERVERS {
        return Ok(());
    }
    let first = processes[MAX_OBSERVERS].observers[0];
    let field = match observers[first].member {
        None => format!("observer[{}]", first + 1),
        Some((d, _)) => format!("diagnoser[{}]", d + 1),
    };
    let banks = processes.len() - own;
    Err(bad(
        field,
        format!(
            "the run would hold {} observer processes ({own} [[observer]] + {banks} for bank members, one per bank); at most {MAX_OBSERVERS}: each subscribes to the plant's samples, and a service allows {} subscribers, one of them the launcher's recorder",
            processes.len(),
            lockstep::settings::MAX_SUBSCRIBERS
        ),
    ))
}

fn observer_spec(
    f: &str,
    o: &RawObserver,
    model: &Model,
    noise: Option<&super::NoiseSpec>,
) -> Result<Spec, Bad> {
    if !KINDS.contains(&o.kind.as_str()) {
        let hint = crate::suggest::did_you_mean(&o.kind, KINDS.iter().copied().chain(["process"]));
        return Err(bad(
            format!("{f}.kind"),
            format!(
                "{} is not an observer kind ({}, process){hint}",
                quoted(&o.kind),
                KINDS.join(", ")
            ),
        ));
    }
    let method = placement(&format!("{f}.placement"), &o.placement)?;
    let refuse = |key: &str, given: bool| {
        if given {
            Err(bad(
                format!("{f}.{key}"),
                format!("a {} observer takes no {key}", o.kind),
            ))
        } else {
            Ok(())
        }
    };
    let (n, p) = (model.n(), model.p());
    if o.kind != "hui-zak-uio" {
        refuse("decay", o.decay.is_some())?;
        refuse("path", o.path.is_some())?;
    }
    if !matches!(o.kind.as_str(), "das-ghosal-uio" | "cumming") {
        refuse("H", o.h.is_some())?;
    }
    if o.kind == "kalman" {
        for (key, given) in [
            ("poles", o.poles.is_some()),
            ("placement", o.placement.is_some()),
            ("gain", o.gain.is_some()),
            ("Q", o.q.is_some()),
            ("R", o.r.is_some()),
        ] {
            refuse(key, given)?;
        }
        let z = noise.ok_or_else(|| {
            bad(
                format!("{f}.kind"),
                "a kalman observer needs [noise]: its covariances are the filter's",
            )
        })?;
        return Ok(Spec::Kalman {
            qd: z.qd.clone(),
            r: z.r.clone(),
        });
    }
    let lqe = lqe_weights(f, o, model, noise)?;
    if lqe.is_some() && o.poles.is_some() {
        return Err(bad(
            format!("{f}.gain"),
            "give poles or gain = \"lqe\", not both (the DARE chooses the poles)",
        ));
    }
    let gain = |required: bool| -> Result<Option<Gain>, Bad> {
        match (&lqe, &o.poles) {
            (Some(w), _) => Ok(Some(Gain::Lqe(w.clone()))),
            (None, Some(ps)) => Ok(Some(Gain::place(poles(&format!("{f}.poles"), ps)?, method))),
            (None, None) if required => Err(bad(
                format!("{f}.poles"),
                format!("a {} observer needs poles (or gain = \"lqe\")", o.kind),
            )),
            (None, None) => Ok(None),
        }
    };
    let needs_gain = || gain(true).map(|g| g.expect("required"));
    Ok(match o.kind.as_str() {
        "luenberger" => Spec::Luenberger {
            gain: needs_gain()?,
        },
        "chen-patton-uio" => Spec::ChenPatton {
            gain: needs_gain()?,
        },
        "das-ghosal" => Spec::DasGhosal {
            gain: needs_gain()?,
        },
        "gi-full-order" => Spec::GiFullOrder {
            gain: needs_gain()?,
        },
        "das-ghosal-uio" => {
            let h =
                o.h.as_ref()
                    .map(|h| {
                        matrix(
                            &format!("{f}.H"),
                            h,
                            (Some(n - p.min(n)), Some(p)),
                            "(n − p)×p, the free matrix of eq. 22",
                        )
                    })
                    .transpose()?;
            if h.is_some() && (o.poles.is_some() || lqe.is_some()) {
                let key = if lqe.is_some() { "gain" } else { "poles" };
                return Err(bad(
                    format!("{f}.{key}"),
                    format!("give H or {key}, not both (H fixes the poles)"),
                ));
            }
            // None given: no free poles (poles = []), right when every mode of the pair is fixed.
            let gain = if h.is_none() {
                Some(
                    gain(false)?
                        .unwrap_or_else(|| Gain::place(Poles::new([]).expect("empty"), method)),
                )
            } else {
                None
            };
            Spec::DasGhosalUio { h, gain }
        }
        "cumming" => {
            let h =
                o.h.as_ref()
                    .map(|h| {
                        matrix(
                            &format!("{f}.H"),
                            h,
                            (Some(n - p.min(n)), Some(n)),
                            "(n − p)×n, completing C to an invertible [C; H]",
                        )
                    })
                    .transpose()?;
            Spec::Cumming {
                gain: needs_gain()?,
                h,
            }
        }
        "hui-zak-uio" => {
            let decay = finite(&format!("{f}.decay"), o.decay.unwrap_or(0.0))?;
            if decay < 0.0 {
                return Err(bad(format!("{f}.decay"), format!("{decay} must be ≥ 0")));
            }
            let path = match o.path.as_deref() {
                None | Some("placement") => HuiZakPath::Placement,
                Some("lmi") => HuiZakPath::Lmi,
                Some(other) => {
                    return Err(bad(
                        format!("{f}.path"),
                        format!(
                            "{} is not a design path (placement, lmi){}",
                            quoted(other),
                            crate::suggest::did_you_mean(other, ["placement", "lmi"])
                        ),
                    ));
                }
            };
            if path == HuiZakPath::Lmi && lqe.is_some() {
                return Err(bad(
                    format!("{f}.path"),
                    "gain = \"lqe\" takes L from a DARE, not from the LMI: drop path = \"lmi\"",
                ));
            }
            Spec::HuiZak {
                decay,
                gain: gain(false)?,
                placement: method,
                path,
            }
        }
        _ => unreachable!("kind checked above"),
    })
}

/// `xhat0`: one finite value per state.
fn initial_estimate(field: &str, x: &[f64], n: usize) -> Result<Vec<f64>, Bad> {
    if x.len() != n {
        return Err(bad(
            field,
            format!("has {} value(s), must have {n} (one per state)", x.len()),
        ));
    }
    for (i, &v) in x.iter().enumerate() {
        finite(&format!("{field}[{}]", i + 1), v)?;
    }
    Ok(x.to_vec())
}

/// `gain = "lqe"` with its weights: Q (n×n, or the reduced order r = n − rank C of a reduced-order
/// family) symmetric ⪰ 0, R (p×p) symmetric ≻ 0. Not given, they default to `[noise]`'s Q_d and R
/// where those are non-zero (the filter's own statistics), else to identities at the design.
fn lqe_weights(
    f: &str,
    o: &RawObserver,
    model: &Model,
    noise: Option<&super::NoiseSpec>,
) -> Result<Option<Weights>, Bad> {
    match o.gain.as_deref() {
        None => {
            for (key, given) in [("Q", o.q.is_some()), ("R", o.r.is_some())] {
                if given {
                    return Err(bad(
                        format!("{f}.{key}"),
                        "weights belong to gain = \"lqe\" (add it, or drop the weight)",
                    ));
                }
            }
            return Ok(None);
        }
        Some("lqe") => {}
        Some(other) => {
            return Err(bad(
                format!("{f}.gain"),
                format!(
                    "{} is not a gain (lqe; or give poles instead)",
                    quoted(other)
                ),
            ));
        }
    }
    if o.placement.is_some() {
        return Err(bad(
            format!("{f}.placement"),
            "gain = \"lqe\" places nothing: drop placement",
        ));
    }
    let (n, p) = (model.n(), model.p());
    let reduced = matches!(o.kind.as_str(), "das-ghosal" | "das-ghosal-uio" | "cumming")
        .then(|| n - lti::pinv::rank(&model.c).min(n));
    let sizes = match reduced {
        Some(r) if r != n => format!("{n}×{n} (the plant's state) or {r}×{r} (the reduced order)"),
        _ => format!("{n}×{n} (the plant's state)"),
    };
    let q =
        o.q.as_ref()
            .map(|rows| {
                let field = format!("{f}.Q");
                let m = matrix(&field, rows, (None, None), "")?;
                if !(m.is_square() && (m.nrows() == n || Some(m.nrows()) == reduced)) {
                    return Err(bad(
                        &field,
                        format!("is {}×{}, must be {sizes}", m.nrows(), m.ncols()),
                    ));
                }
                definite(&field, "Q", &m, lti::dare::Definite::Semi)
            })
            .transpose()?;
    let r =
        o.r.as_ref()
            .map(|rows| {
                let field = format!("{f}.R");
                let m = matrix(
                    &field,
                    rows,
                    (Some(p), Some(p)),
                    "one row and column per output",
                )?;
                definite(&field, "R", &m, lti::dare::Definite::Positive)
            })
            .transpose()?;
    let nonzero = |m: &Mat| m.iter().any(|&v| v != 0.0);
    let q = q.or_else(|| noise.map(|z| z.qd.clone()).filter(nonzero));
    let r = r.or_else(|| {
        noise.map(|z| z.r.clone()).filter(|m| {
            nonzero(m) && lti::dare::symmetric("R", m, lti::dare::Definite::Positive).is_ok()
        })
    });
    Ok(Some(Weights { q, r }))
}

/// A weight or covariance that must be symmetric and (semi-)definite, by the rule the Riccati
/// and Van Loan code applies to its arguments ([`lti::dare::symmetric`]).
pub(crate) fn definite(
    field: &str,
    symbol: &str,
    m: &Mat,
    how: lti::dare::Definite,
) -> Result<Mat, Bad> {
    lti::dare::symmetric(symbol, m, how).map_err(|e| {
        let reason = match e {
            lti::LtiError::InvalidInput(r) => r,
            other => other.to_string(),
        };
        bad(field, reason)
    })
}

/// An external component's command and parameters (PROTOCOL.md §7).
fn process_spec(
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
fn json_safe(field: &str, v: &toml::Value) -> Result<(), Bad> {
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
pub(crate) fn plant_process(p: &Option<RawProcess>) -> Result<Option<ProcessSpec>, Bad> {
    p.as_ref()
        .map(|p| process_spec("plant.process", &Some(p.command.clone()), &p.params))
        .transpose()
}

fn controller_entry(
    c: &RawController,
    model: &Model,
    observers: &BTreeSet<String>,
    inputs: &[Named],
) -> Result<ControllerEntry, Bad> {
    const KINDS: [&str; 3] = ["state-feedback", "lqr", "process"];
    if !KINDS.contains(&c.kind.as_str()) {
        return Err(bad(
            "controller.kind",
            format!(
                "{} is not a controller kind ({}){}",
                quoted(&c.kind),
                KINDS.join(", "),
                crate::suggest::did_you_mean(&c.kind, KINDS)
            ),
        ));
    }
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
            None | Some("sampled") => Domain::Sampled,
            Some("continuous") => Domain::Continuous,
            Some(other) => {
                return Err(bad(
                    "controller.domain",
                    format!(
                        "{} is not a domain (sampled, continuous){}",
                        quoted(other),
                        crate::suggest::did_you_mean(other, ["sampled", "continuous"])
                    ),
                ));
            }
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
fn measured_disturbances(given: Option<&[String]>, inputs: &[Named]) -> Result<Vec<usize>, Bad> {
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

fn check_expect(e: &RawExpect, observers: &BTreeSet<String>) -> Result<(), Bad> {
    let known = |field: &str, name: &str| {
        if observers.contains(name) {
            Ok(())
        } else {
            Err(bad(field, format!("no observer named {}", quoted(name))))
        }
    };
    let positive = |field: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(bad(field, format!("{v} must be a finite number > 0")))
        }
    };
    for (table, map) in [
        ("tail_max_abs_error", &e.tail_max_abs_error),
        ("tail_max_abs_residual", &e.tail_max_abs_residual),
    ] {
        for (name, &v) in map {
            let f = format!("expect.{table}.{name}");
            known(&f, name)?;
            positive(&f, v)?;
        }
    }
    for (table, map) in [
        ("max_abs_difference", &e.max_abs_difference),
        ("tail_error_ratio", &e.tail_error_ratio),
    ] {
        for (pair, &v) in map {
            let f = format!("expect.{table}");
            let Some((a, b)) = pair.split_once('/') else {
                return Err(bad(
                    f,
                    format!("{} must name two observers as \"a/b\"", quoted(pair)),
                ));
            };
            known(&f, a)?;
            known(&f, b)?;
            positive(&f, v)?;
        }
    }
    Ok(())
}
