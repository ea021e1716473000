//! `uio-launcher export-fmu`: one of a scenario's observers as an FMI 2.0 or 3.0 co-simulation FMU.
//!
//! Orchestration only: the observer is designed exactly as a run designs it
//! ([`launcher::plan::design_observer`]), and crate `fmu-export` writes its matrices, the
//! modelDescription and the archive around the library `fmu-observer` builds (found beside this
//! executable). Refusals are one line, before anything is written.

use std::path::{Path, PathBuf};

use fmu_export::{Description, Fmi, ObserverResource, OperatingPoint, Signal};
use launcher::{LaunchError, Scenario, plan, println, shipped};
use std::process::ExitCode;

use crate::cli::ExportFmuArgs;

/// The observer FMUs' shared library, as cargo names it in target/release.
pub const LIBRARY: &str = "libuio_observer_fmu.so";

pub fn command(a: ExportFmuArgs) -> Result<ExitCode, LaunchError> {
    let s = shipped::load(&a.scenario)?;
    let path = export_fmu(&s, &a.observer, &a.out, Fmi::from(a.fmi))?;
    println!("{}", path.display());
    Ok(ExitCode::SUCCESS)
}

/// Writes DIR/<observer>_fmi<2|3>.fmu; its path.
pub fn export_fmu(
    s: &Scenario,
    observer: &str,
    out: &Path,
    fmi: Fmi,
) -> Result<PathBuf, LaunchError> {
    let bad = |why: String| LaunchError::BadInput(format!("{}: {why}", s.path.display()));
    let Some(o) = s.observers.iter().find(|o| o.name == observer) else {
        let own: Vec<&str> = s
            .observers
            .iter()
            .filter(|o| o.spec.is_some())
            .map(|o| o.name.as_str())
            .collect();
        return Err(bad(format!(
            "no observer {} (observers with matrices to export: {})",
            scenario::quoted(observer),
            if own.is_empty() {
                "none".into()
            } else {
                own.join(", ")
            }
        )));
    };
    let spec = match (&o.spec, o.member) {
        (Some(spec), _) => spec,
        (None, Some((b, _))) => {
            return Err(bad(format!(
                "observer '{}' is a member of diagnoser '{}''s bank: export one of the scenario's own [[observer]] entries",
                o.name, s.diagnosers[b].name
            )));
        }
        (None, None) => {
            return Err(bad(format!(
                "observer '{}' is an external process (kind = \"process\"): it has no matrices to export",
                o.name
            )));
        }
    };
    let library = library()?;
    let d = plan::design_observer(s, o, spec)
        .map_err(|e| bad(format!("observer '{}': {e}", o.name)))?;
    let lo = d.runtime;
    let offset = lo.offset.clone();
    let mut res = ObserverResource::new(
        &o.name,
        s.dt,
        lo.f,
        lo.g,
        lo.k,
        lo.p,
        lo.q,
        (&s.model.c).into(),
        lo.xhat0,
    )
    .map_err(|e| bad(format!("observer '{}': {e}", o.name)))?;
    // At an operating point the FMU takes the plant's absolute u and y and gives x̂ in the plant's
    // units, with the run's own offsets.
    if let (Some(op), Some(off)) = (&s.operating_point, offset) {
        let c_r = op.output_offset(&s.model.c);
        let c_r = if c_r.iter().any(|&v| v != 0.0) {
            c_r
        } else {
            Vec::new()
        };
        let point = OperatingPoint {
            u: op.u.clone(),
            y: op.y.clone(),
            c_z: off.z,
            c_x: off.x,
            c_r,
        };
        res = res
            .at_operating_point(point)
            .map_err(|e| bad(format!("observer '{}': {e}", o.name)))?;
    }
    let at_point = res.operating_point.is_some();
    let signals = |v: &[scenario::Named]| {
        v.iter()
            .map(|n| Signal {
                name: n.name.clone(),
                unit: n.unit.clone(),
            })
            .collect()
    };
    let desc = Description {
        model_identifier: fmu_export::identifier(&o.name),
        model_name: fmu_export::identifier(&format!("{}_{}", s.name, o.name)),
        description: format!(
            "{} observer '{}' of scenario {}, sampled at dt = {} s: z+ = F z + G u + K y{}, xhat = P z + Q y{}, r = y - C xhat{}",
            o.kind(),
            o.name,
            s.name,
            s.dt,
            if at_point { " + c_z" } else { "" },
            if at_point { " + c_x" } else { "" },
            if at_point {
                "; designed in deviations from its operating point, fed and giving absolute signals (the inputs start there)"
            } else {
                ""
            }
        ),
        states: signals(&s.names.state),
        outputs: signals(&s.names.output),
        inputs: signals(&s.names.input),
        stop_time: s.duration,
    };
    std::fs::create_dir_all(out)
        .map_err(|e| LaunchError::BadInput(format!("{}: cannot create: {e}", out.display())))?;
    let version = if fmi == Fmi::V2 { 2 } else { 3 };
    let path = out.join(format!("{}_fmi{version}.fmu", o.name));
    fmu_export::export(&res, &desc, fmi, &library, &path).map_err(LaunchError::BadInput)?;
    Ok(path)
}

/// The library beside the launcher executable, or how to build it.
fn library() -> Result<PathBuf, LaunchError> {
    let exe = std::env::current_exe().map_err(|e| {
        LaunchError::BadInput(format!("cannot locate the launcher executable: {e}"))
    })?;
    let path = exe
        .parent()
        .map_or_else(|| PathBuf::from(LIBRARY), |d| d.join(LIBRARY));
    if path.is_file() {
        Ok(path)
    } else {
        Err(LaunchError::BadInput(format!(
            "{} is not built: build it with `cargo build --release -p fmu-observer`",
            path.display()
        )))
    }
}
