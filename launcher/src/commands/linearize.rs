//! `uio-launcher linearize <scenario> [--trim] --out DIR`: the sampled model of a scenario's FMU
//! plant at its operating point, made from the FMU itself.
//!
//! Orchestration only: crate `scenario` reads what is needed and writes the result
//! (`scenario::linearized`), the FMU plant program computes it (`uio-fmu-plant --linearize`, its
//! module `linearize`: trim by Newton's method, central differences with Richardson's
//! extrapolation). This prints the report: the trim, the point, each matrix's estimated
//! difference error, and a direct feedthrough the sampled model has no place for.

use std::path::{Path, PathBuf};

use launcher::{LaunchError, println};
use std::process::ExitCode;

use crate::cli::LinearizeArgs;
use scenario::linearized::{self, Linearized};
use serde_json::Value;

const PROGRAM: &str = lockstep::programs::FMU_PLANT;

fn rows(v: &Value) -> Vec<Vec<f64>> {
    v["rows"]
        .as_array()
        .map(|r| {
            r.iter()
                .map(|row| {
                    row.as_array()
                        .map(|x| x.iter().filter_map(Value::as_f64).collect())
                        .unwrap_or_default()
                })
                .collect()
        })
        .unwrap_or_default()
}

fn list(v: &Value) -> Vec<f64> {
    v.as_array()
        .map(|x| x.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default()
}

fn fmt(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter()
            .map(|x| format!("{x:.6e}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

pub fn command(a: LinearizeArgs) -> Result<ExitCode, LaunchError> {
    let path = linearize(&a.scenario, a.trim, &a.out)?;
    println!("wrote {}", path.display());
    Ok(ExitCode::SUCCESS)
}

/// Runs `uio-launcher linearize`; the scenario written.
pub fn linearize(path: &Path, trim: bool, out: &Path) -> Result<PathBuf, LaunchError> {
    let req = linearized::request(path)?;
    let answer = launcher::run::preflight::sibling(
        path,
        ["plant.fmu: "; 2],
        PROGRAM,
        "--linearize",
        "fmu-plant",
        &req.json(trim),
        launcher::run::preflight::LINEARIZE_TIMEOUT,
    )?;
    let a: Value = serde_json::from_slice(&answer).map_err(|e| {
        LaunchError::BadInput(format!(
            "{}: {PROGRAM} --linearize: its answer: {e}",
            path.display()
        ))
    })?;
    let (x, y) = (list(&a["x"]), list(&a["y"]));
    let (phi, gb, ge, c) = (
        rows(&a["Phi"]),
        rows(&a["Gamma_B"]),
        rows(&a["Gamma_E"]),
        rows(&a["C"]),
    );
    let file = req
        .fmu
        .file_name()
        .map_or(String::new(), |f| f.to_string_lossy().into_owned());
    println!(
        "{file} at dt = {} ({} FMU instances)",
        req.dt, a["instances"]
    );
    if let Some(t) = a.get("trim").filter(|t| !t.is_null()) {
        let free: Vec<usize> = t["free"]
            .as_array()
            .map(|f| {
                f.iter()
                    .filter_map(Value::as_u64)
                    .map(|i| i as usize)
                    .collect()
            })
            .unwrap_or_default();
        let names = |ix: &[usize]| {
            ix.iter()
                .map(|&i| req.params["states"][i].as_str().unwrap_or("?").to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        println!(
            "  trim: {} Newton iteration(s), max|x⁺ − x| = {:.3e}",
            t["iterations"],
            t["residual"].as_f64().unwrap_or(f64::NAN)
        );
        if !free.is_empty() {
            let r = list(&t["step_residual"]);
            let drift: Vec<String> = free
                .iter()
                .map(|&i| {
                    format!(
                        "{} {:+.3e}",
                        req.params["states"][i].as_str().unwrap_or("?"),
                        r[i]
                    )
                })
                .collect();
            println!(
                "  trim: the equilibrium is not unique: Φ − I is singular along {} (a free integrator); left at the first guess, drifting per sample by {}",
                names(&free),
                drift.join(", ")
            );
        }
    }
    println!(
        "  x_op = {}\n  u_op = {}\n  w_op = {}\n  y_op = {}",
        fmt(&x),
        fmt(&req.u),
        fmt(&req.w),
        fmt(&y)
    );
    for key in ["Phi", "Gamma_B", "Gamma_E", "C", "d_u", "d_w"] {
        let m = rows(&a[key]);
        let big = m.iter().flatten().fold(0.0f64, |acc, v| acc.max(v.abs()));
        let err = a[key]["error"].as_f64().unwrap_or(f64::NAN);
        let (r, cols) = (m.len(), m.first().map_or(0, Vec::len));
        if let Some(signal) = key.strip_prefix("d_") {
            if big
                > 1e-6
                    * c.iter()
                        .flatten()
                        .fold(0.0f64, |acc, v| acc.max(v.abs()))
                        .max(1e-300)
                && r * cols > 0
            {
                println!(
                    "  warning: y depends on {signal} directly (max |∂y/∂{signal}| = {big:.3e}): the sampled model has no such feedthrough"
                );
            }
            continue;
        }
        println!(
            "  {key:<8} {r}×{cols}  max|entry| {big:.3e}  difference error ≤ {err:.1e} ({:.1e} relative)",
            if big > 0.0 { err / big } else { 0.0 }
        );
    }
    let m = Linearized {
        x: &x,
        u: &req.u,
        w: &req.w,
        y: &y,
        phi: &phi,
        gamma_b: &gb,
        gamma_e: &ge,
        c: &c,
    };
    let written = linearized::write(&req, &m, out)
        .map_err(|e| LaunchError::BadInput(format!("--out {}: {e}", out.display())))?;
    Ok(written)
}
