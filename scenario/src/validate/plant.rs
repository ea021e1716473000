//! `[plant]`: the model (continuous A, B, C, E, D or discrete Φ, Γ_B, Γ_E per step), x(0), the
//! state bound, the signals' names and units, the inputs' signals and the fault matrix F_f.

use lti::signal::Signal;
use lti::{Mat, Model};

use crate::check::{Bad, bad, finite, matrix, one_of};
use crate::raw::{RawScenario, Rows};
use crate::untrusted::quoted;
use crate::{Named, SignalNames};

/// The checked `[plant]` model and the signals that drive it.
pub(super) struct Plant {
    pub discrete: bool,
    pub model: Model,
    pub x0: Option<Vec<f64>>,
    pub state_bound: f64,
    pub names: SignalNames,
    pub disturbances: Vec<Signal>,
    pub measurement_disturbances: Vec<Signal>,
    pub inputs: Vec<Signal>,
    pub ff: Mat,
}

// one job: `[plant]` validated field by field in the order the docs list them (continuous or
// discrete model, names, signals).
pub(super) fn plant(raw: &RawScenario) -> Result<Plant, Bad> {
    // Plant: continuous (A, B, E) or, for an identified model, discrete (Φ, Γ_B, Γ_E per step).
    let p = &raw.plant;
    let discrete = match p.time.as_deref() {
        None => false,
        Some(v) => one_of(
            "plant.time",
            "time domain",
            v,
            &[("continuous", false), ("discrete", true)],
        )?,
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
    Ok(Plant {
        discrete,
        model,
        x0,
        state_bound,
        names: layout_names,
        disturbances,
        measurement_disturbances,
        inputs,
        ff,
    })
}

pub(super) fn signals(
    field: &str,
    list: &[Signal],
    count: usize,
    source: &str,
) -> Result<Vec<Signal>, Bad> {
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
pub(super) fn names(
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
