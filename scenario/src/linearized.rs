//! `uio-launcher linearize`: what it needs of a scenario, and the scenario it writes.
//!
//! Its input need not run yet: only `dt`, `[plant.fmu]` (the FMU and its map), and where to
//! linearise — `[plant.operating_point]` x, u, w (u, w default 0; x defaults to `[plant] x0`,
//! and with `--trim` is only the first guess) — are read; `[plant]`'s matrices, if any, are
//! what the output replaces. The output is the same scenario (its comments lost: it is
//! re-serialised) with `[plant]` the sampled model at dt — `time = "discrete"`, Φ, Γ_B, Γ_E
//! and C as `.npy` files beside it — `[plant.operating_point]` the point (x, u, w and y as the
//! FMU gives it), and the FMU's path absolute, so that it runs as is.

use std::path::{Path, PathBuf};

use serde_json::json;

use super::plant_file::Sizes;
use super::raw::{RawFmu, RawOperatingPoint};
use super::{MAX_SCENARIO_BYTES, ScenarioError, untrusted};
use crate::check::{Bad, bad, check_name, finite};

/// What `uio-fmu-plant --linearize` is asked.
#[derive(Debug, Clone)]
pub struct Request {
    /// The scenario's name (the output file's stem).
    pub name: String,
    pub dt: f64,
    /// The FMU plant's `params` (its map), `x0` = x_op or the trim's first guess.
    pub params: serde_json::Value,
    pub u: Vec<f64>,
    pub w: Vec<f64>,
    /// The FMU (absolute).
    pub fmu: PathBuf,
    /// The scenario's text, to be rewritten.
    text: String,
}

impl Request {
    /// The request as `uio-fmu-plant --linearize` reads it.
    pub fn json(&self, trim: bool) -> serde_json::Value {
        json!({ "params": self.params, "u": self.u, "w": self.w, "dt": self.dt, "trim": trim })
    }
}

/// Reads what `uio-launcher linearize` needs from the scenario at `path`.
// one job: the fields `linearize` needs, validated in the scenario's order.
pub fn request(path: &Path) -> Result<Request, ScenarioError> {
    let err = |Bad { field, reason }: Bad| ScenarioError {
        file: path.to_path_buf(),
        at: None,
        field,
        reason,
    };
    let text = untrusted::read_bounded(path, MAX_SCENARIO_BYTES).map_err(|r| err(bad("", r)))?;
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        err(bad(
            "",
            format!(
                "malformed TOML: {}",
                e.message().lines().next().unwrap_or("")
            ),
        ))
    })?;
    let dt = table
        .get("dt")
        .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
        .ok_or_else(|| {
            err(bad(
                "dt",
                "missing: the sample period the model is made for",
            ))
        })?;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(err(bad("dt", format!("{dt}: must be finite and > 0"))));
    }
    let name = table
        .get("name")
        .and_then(|v| v.as_str())
        .unwrap_or("linearized")
        .to_string();
    // It names the scenario file written: a name as a run's (letters, digits, '-', '_').
    check_name("name", &name, "it names the scenario file written").map_err(err)?;
    let plant = table
        .get("plant")
        .and_then(|v| v.as_table())
        .ok_or_else(|| {
            err(bad(
                "plant",
                "missing: [plant.fmu] names the FMU to linearise",
            ))
        })?;
    let fmu: RawFmu = plant
        .get("fmu")
        .ok_or_else(|| {
            err(bad(
                "plant.fmu",
                "missing: `uio-launcher linearize` makes the model of an FMU plant",
            ))
        })?
        .clone()
        .try_into()
        .map_err(|e: toml::de::Error| {
            err(bad(
                "plant.fmu",
                e.message().lines().next().unwrap_or("").to_string(),
            ))
        })?;
    let op: Option<RawOperatingPoint> = match plant.get("operating_point") {
        Some(v) => Some(v.clone().try_into().map_err(|e: toml::de::Error| {
            err(bad(
                "plant.operating_point",
                e.message().lines().next().unwrap_or("").to_string(),
            ))
        })?),
        None => None,
    };
    let x0: Option<Vec<f64>> = match plant.get("x0") {
        Some(v) => Some(
            v.clone()
                .try_into()
                .map_err(|_| err(bad("plant.x0", "a list of numbers")))?,
        ),
        None => None,
    };
    let (n, p) = (fmu.states.len(), fmu.outputs.len());
    let (l, q) = (
        fmu.inputs.as_ref().map_or(0, Vec::len),
        fmu.disturbances.as_ref().map_or(0, Vec::len),
    );
    let vector = |field: &str,
                  v: Option<Vec<f64>>,
                  len: usize,
                  default: Option<Vec<f64>>|
     -> Result<Vec<f64>, Bad> {
        let v = match v.or(default) {
            Some(v) => v,
            None => {
                return Err(bad(
                    field,
                    format!("missing: the operating point's {len} values (or [plant] x0)"),
                ));
            }
        };
        if v.len() != len {
            return Err(bad(
                field,
                format!("has {} entries; the FMU map has {len}", v.len()),
            ));
        }
        for (i, &x) in v.iter().enumerate() {
            finite(&format!("{field}[{}]", i + 1), x)?;
        }
        Ok(v)
    };
    let (ox, ou, ow) = op.map_or((None, None, None), |o| (o.x, o.u, o.w));
    let x = vector("plant.operating_point.x", ox, n, x0).map_err(err)?;
    let u = vector("plant.operating_point.u", ou, l, Some(vec![0.0; l])).map_err(err)?;
    let w = vector("plant.operating_point.w", ow, q, Some(vec![0.0; q])).map_err(err)?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let (fmu_path, spec) =
        super::fmu_plant::plant_fmu(&Some(fmu), Some(dir), &Sizes { n, p, l, q }, Some(&x))
            .map_err(err)?
            .expect("given");
    Ok(Request {
        name,
        dt,
        params: spec.params,
        u,
        w,
        fmu: fmu_path,
        text,
    })
}

/// The model made, as `uio-fmu-plant --linearize` answers.
pub struct Linearized<'a> {
    pub x: &'a [f64],
    pub u: &'a [f64],
    pub w: &'a [f64],
    pub y: &'a [f64],
    pub phi: &'a [Vec<f64>],
    pub gamma_b: &'a [Vec<f64>],
    pub gamma_e: &'a [Vec<f64>],
    pub c: &'a [Vec<f64>],
}

/// Writes Phi.npy, Gamma_B.npy, Gamma_E.npy, C.npy and `<name>.toml` into `out` (made if
/// missing); each file is written beside its name and renamed into place, so that a failure
/// leaves no half-written file. Returns the scenario's path.
pub fn write(req: &Request, m: &Linearized, out: &Path) -> Result<PathBuf, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut table: toml::Table = req
        .text
        .parse()
        .map_err(|e: toml::de::Error| e.to_string())?;
    let plant = table
        .entry("plant")
        .or_insert_with(|| toml::Value::Table(Default::default()));
    let plant = plant.as_table_mut().ok_or("plant: not a table")?;
    for key in ["A", "B", "E", "Phi", "Gamma_B", "Gamma_E", "C", "time"] {
        plant.remove(key);
    }
    let mut files = Vec::new();
    for (key, rows) in [
        ("Phi", m.phi),
        ("Gamma_B", m.gamma_b),
        ("Gamma_E", m.gamma_e),
        ("C", m.c),
    ] {
        let file = format!("{key}.npy");
        files.push((out.join(&file), super::matrix_file::npy_bytes(rows)?));
        plant.insert(key.into(), toml::Value::String(file));
    }
    plant.insert("time".into(), "discrete".into());
    let list = |v: &[f64]| toml::Value::Array(v.iter().map(|&x| toml::Value::Float(x)).collect());
    let mut op = toml::Table::new();
    for (k, v) in [("x", m.x), ("u", m.u), ("w", m.w), ("y", m.y)] {
        if !v.is_empty() {
            op.insert(k.into(), list(v));
        }
    }
    plant.insert("operating_point".into(), toml::Value::Table(op));
    // Without an x0 of its own the run would start from the FMU's start values, away from the
    // point it is linearised at: it starts at rest there instead.
    let at_rest = !plant.contains_key("x0");
    if at_rest {
        plant.insert("x0".into(), list(m.x));
    }
    if let Some(fmu) = plant.get_mut("fmu").and_then(|f| f.as_table_mut()) {
        fmu.insert("path".into(), req.fmu.display().to_string().into());
    }
    let header = format!(
        "# Made by `uio-launcher linearize` from the FMU {}: the sampled model at dt = {} in deviations\n# from [plant.operating_point] (Phi, Gamma_B, Gamma_E, C beside this file, as .npy).\n{}",
        req.fmu.display(),
        req.dt,
        if at_rest {
            "# [plant] x0 is the operating point's x (the scenario gave none): the run starts at rest there.\n"
        } else {
            ""
        }
    );
    let text = header + &toml::to_string(&table).map_err(|e| e.to_string())?;
    let scenario = out.join(format!("{}.toml", req.name));
    files.push((scenario.clone(), text.into_bytes()));
    // Every file staged before any is renamed into place: a failure leaves none half-written.
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in &files {
        let (s, mut w) = outputs::Staged::create(path)?;
        std::io::Write::write_all(&mut w, bytes).map_err(|e| outputs::cannot_write(path, &e))?;
        staged.push((s, w));
    }
    for (s, w) in staged {
        s.commit(w)?;
    }
    Ok(scenario)
}
