//! `uio_observers._native`: the launcher's own design, run and read paths, reached from Python.
//! Nothing here designs or simulates: `design` is `uio-launcher design --json`'s report, `run` is
//! `uio-launcher run --mode in-process`, `read` is the export's table of a recording — so the Python
//! package gives the CLI's numbers, bit for bit. The Python layer (`uio_observers/__init__.py`)
//! turns what these return into NumPy arrays.

use std::path::{Path, PathBuf};

use launcher::run::{Mode, Options, Stop};
use launcher::{LaunchError, design_report, shipped};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use scenario::Scenario;

/// Bad input (a scenario, a file) as `ValueError`, what failed while running as `RuntimeError`,
/// each with the launcher's message.
fn raise(e: LaunchError) -> PyErr {
    match e {
        LaunchError::Scenario(_) | LaunchError::BadInput(_) => PyValueError::new_err(e.to_string()),
        _ => PyRuntimeError::new_err(e.to_string()),
    }
}

/// A scenario file or shipped name, or (with `text`) the scenario written in `text` and
/// located at `path` (relative paths in it resolve from its folder).
fn scenario(path: &str, text: Option<&str>) -> Result<Scenario, LaunchError> {
    Ok(match text {
        Some(t) => Scenario::parse(Path::new(path), t)?,
        None => shipped::load(Path::new(path))?,
    })
}

/// The scenario at `path` (its seed replaced by `seed`, if given), designed and calibrated once:
/// what every realisation of a sweep or point of a variation shares.
fn planned(path: &str, seed: Option<u64>) -> PyResult<(Scenario, launcher::plan::Plan)> {
    let mut s = scenario(path, None).map_err(raise)?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    let p = launcher::calibrate::planned(&s).map_err(raise)?;
    Ok((s, p))
}

/// `uio-launcher design --json [--freq]`: (every design holds, the JSON report, the text report).
#[pyfunction]
#[pyo3(signature = (path, text=None, freq=false))]
fn design(path: &str, text: Option<&str>, freq: bool) -> PyResult<(bool, String, String)> {
    let s = scenario(path, text).map_err(raise)?;
    let r = design_report::report(&s);
    let mut json = r.json();
    let mut lines = r.text();
    if freq {
        let f = design_report::freq::freq(&s, &r);
        json["freq"] = f.json();
        lines += &f.text(r.dt);
    }
    Ok((
        r.ok,
        serde_json::to_string(&json).expect("serialises"),
        lines,
    ))
}

/// `uio-launcher run --mode in-process --out OUT`: (the recording, the summary JSON, completed and
/// every expectation met).
#[pyfunction]
#[pyo3(signature = (path, out, force=false))]
fn run(py: Python<'_>, path: &str, out: &str, force: bool) -> PyResult<(String, String, bool)> {
    let s = scenario(path, None).map_err(raise)?;
    let p = launcher::calibrate::planned(&s).map_err(raise)?;
    let select =
        recording::write::Selection::new(1, &[]).map_err(|e| raise(LaunchError::BadInput(e)))?;
    let opts = Options {
        out: PathBuf::from(out),
        mode: Mode::InProcess,
        wait: lockstep::Wait::default_for_machine(),
        force,
        allow_unstable: false,
        record: true,
        pin: false,
        select,
        progress: false,
        realtime: None,
    };
    // The run holds no Python object: other Python threads may go on meanwhile.
    let o = py
        .detach(|| launcher::run::run(&s, &p, &opts))
        .map_err(raise)?;
    let rrd = o
        .rrd
        .as_ref()
        .map(|r| r.display().to_string())
        .unwrap_or_default();
    let summary =
        serde_json::to_string(&o.summary).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let ok = matches!(o.stop, Stop::Completed) && o.summary.expectations_met();
    Ok((rrd, summary, ok))
}

/// `uio-launcher sweep PATH --runs RUNS [--seed SEED] --keep-worst KEEP --shard K/N --jobs JOBS
/// --out OUT` in this process: the path of the shard file it wrote.
#[pyfunction]
#[pyo3(signature = (path, runs, seed, k, n, keep_worst, jobs, out))]
#[allow(clippy::too_many_arguments)]
fn sweep_shard(
    py: Python<'_>,
    path: &str,
    runs: usize,
    seed: Option<u64>,
    k: usize,
    n: usize,
    keep_worst: usize,
    jobs: usize,
    out: &str,
) -> PyResult<String> {
    let sh: launcher::sweep::Shard = format!("{k}/{n}")
        .parse()
        .map_err(|e: String| PyValueError::new_err(format!("shard: {e}")))?;
    launcher::limits::sharded_runs(runs, sh.range(runs).len())
        .and_then(|_| launcher::limits::jobs(jobs))
        .map_err(raise)?;
    // One calibration for every realisation, from the first seed: every shard's the same.
    let (s, p) = planned(path, seed)?;
    let opts = launcher::sweep::SweepOptions {
        runs,
        jobs,
        seed: s.seed,
        mode: Mode::InProcess,
        out: PathBuf::from(out),
        keep_worst,
        wait: lockstep::Wait::default_for_machine(),
        shard: Some(sh),
    };
    let (file, written) = py
        .detach(|| launcher::sweep::shard::run_shard(&s, &p, &opts, sh))
        .map_err(raise)?;
    if let Some(e) = file.verdict()
        && file.interrupted_by.is_some()
    {
        return Err(raise(e));
    }
    Ok(written.display().to_string())
}

/// `uio-launcher sweep merge FILES… --out OUT`: (the sweep summary JSON, its table, the path of
/// `<name>.sweep.json`). A merged sweep with failed realisations is returned, not raised: its
/// summary lists them.
#[pyfunction]
fn sweep_merge(
    py: Python<'_>,
    files: Vec<String>,
    out: &str,
) -> PyResult<(String, String, String)> {
    let files: Vec<PathBuf> = files.into_iter().map(PathBuf::from).collect();
    let out = PathBuf::from(out);
    let (sw, path) = py
        .detach(|| launcher::sweep::shard::merge_into(&files, &out))
        .map_err(raise)?;
    let json = serde_json::to_string(&sw).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok((json, sw.table(), path.display().to_string()))
}

/// `uio-launcher sweep PATH --vary V… --points POINTS [--seed SEED] --jobs JOBS --out OUT`: (the
/// variation's JSON, its table). The CSV, JSON and plots are written into `out`.
#[pyfunction]
#[pyo3(signature = (path, varies, points, seed, jobs, out))]
fn vary(
    py: Python<'_>,
    path: &str,
    varies: Vec<String>,
    points: usize,
    seed: Option<u64>,
    jobs: usize,
    out: &str,
) -> PyResult<(String, String)> {
    let varies = varies
        .iter()
        .map(|v| v.parse::<launcher::vary::spec::Vary>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| PyValueError::new_err(format!("vary: {e}")))?;
    if varies.is_empty() {
        return Err(PyValueError::new_err("vary: give at least one"));
    }
    if !(1..=launcher::vary::MAX_POINTS).contains(&points) {
        return Err(PyValueError::new_err(format!(
            "points: 1 … {}",
            launcher::vary::MAX_POINTS
        )));
    }
    launcher::limits::jobs(jobs).map_err(raise)?;
    // Designed (and calibrated) once, on the nominal model, as the launcher does.
    let (s, p) = planned(path, seed)?;
    let opts = launcher::vary::VaryOptions {
        varies,
        draws: points,
        seed: s.seed,
        jobs,
        out: PathBuf::from(out),
        wait: lockstep::Wait::default_for_machine(),
    };
    let outcomes = py
        .detach(|| launcher::vary::vary(&s, &p, &opts))
        .map_err(raise)?;
    let written =
        launcher::vary::report::write(&opts.out, &s, &opts.varies, &outcomes).map_err(raise)?;
    let jobs = launcher::vary::mode_of(&s, jobs).1.clamp(1, outcomes.len());
    let table = launcher::vary::report::table(&s.name, &opts.varies, s.seed, jobs, &outcomes);
    Ok((written.json_text, table))
}

/// One entity group of a recording: its path, its members' names and labelled names, and its
/// values row by row (steps × members, NaN where a member has no value at a step).
type Group<'py> = (String, Vec<String>, Vec<String>, Bound<'py, PyBytes>);

/// A recording as the exports see it: (the steps, dt if known, the groups).
#[pyfunction]
fn read<'py>(
    py: Python<'py>,
    path: &str,
) -> PyResult<(Bound<'py, PyBytes>, Option<f64>, Vec<Group<'py>>)> {
    let r = recording::read(Path::new(path)).map_err(|e| PyValueError::new_err(e.to_string()))?;
    if let recording::Integrity::Damaged(what) = &r.integrity {
        return Err(PyValueError::new_err(format!("{path}: damaged: {what}")));
    }
    let groups = recording::export::table::labelled(&r);
    let steps = recording::export::table::all_steps(&groups);
    let bytes = |v: &[f64]| {
        PyBytes::new(
            py,
            &v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>(),
        )
    };
    let mut out = Vec::with_capacity(groups.len());
    for g in &groups {
        let cols: Vec<Vec<Option<f64>>> = g
            .members
            .iter()
            .map(|m| recording::export::table::aligned(&steps, m.series).collect())
            .collect();
        let mut values = Vec::with_capacity(steps.len() * cols.len());
        for k in 0..steps.len() {
            values.extend(cols.iter().map(|c| c[k].unwrap_or(f64::NAN)));
        }
        let names = g.members.iter().map(|m| m.name.clone()).collect();
        let labels = g.members.iter().map(|m| m.label.clone()).collect();
        out.push((g.path.clone(), names, labels, bytes(&values)));
    }
    let steps = PyBytes::new(
        py,
        &steps
            .iter()
            .flat_map(|k| k.to_le_bytes())
            .collect::<Vec<u8>>(),
    );
    Ok((steps, recording::tools::recorded_dt(&r), out))
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(design, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_shard, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_merge, m)?)?;
    m.add_function(wrap_pyfunction!(vary, m)?)?;
    Ok(())
}
