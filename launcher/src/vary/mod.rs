//! `uio-launcher sweep --vary`: how far the observers hold when the plant is not the model.
//!
//! The plant varied is the built-in one (its matrices), an FMU or a kit component (their
//! parameters; the points then run as processes, one at a time, as such a plant only runs in
//! its own process).
//!
//! The observers, banks, thresholds and controller are designed once, on the scenario's model
//! (the nominal plan); each point of the variation runs the same scenario with the simulated
//! plant's matrices changed as its `--vary`s say ([`spec`]), at the same seed (common random
//! numbers: the points differ by the plant alone). Grids make a product; distributions are
//! drawn `--points` times (ChaCha8, seeded), the same draws for every grid combination. The
//! nominal point (the model itself) is run too and marked. Per point the run's figures
//! ([`figures`]); the table, `<name>.vary.csv`, `<name>.vary.json` and one PNG per figure and
//! varied parameter ([`report`]); per figure its worst point, named.

pub mod figures;
pub mod report;
pub mod spec;

use std::path::PathBuf;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, Uniform};

use crate::error::LaunchError;
use crate::plan::Plan;
use crate::run::{self, Mode, Options, Stop};
use figures::Figures;
use scenario::Scenario;
use spec::{Matrix, Op, Place, Values, Vary};

/// Most points of one variation (each a whole run).
pub const MAX_POINTS: usize = 100_000;

/// How to vary.
#[derive(Debug, Clone)]
pub struct VaryOptions {
    /// What differs.
    pub varies: Vec<Vary>,
    /// Draws of the distributions (ignored when every `--vary` is a grid).
    pub draws: usize,
    /// The seed of every run and of the draws.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
    /// Output folder.
    pub out: PathBuf,
    /// Wait strategy.
    pub wait: lockstep::Wait,
}

/// One point: each `--vary`'s value (the scaling, or the value set).
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// In `--vary` order.
    pub values: Vec<f64>,
    /// The model itself.
    pub nominal: bool,
}

/// How a point's run ended, and its figures.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The point.
    pub point: Point,
    /// "completed", "diverged" or "failed".
    pub status: &'static str,
    /// Why, when not completed.
    pub reason: Option<String>,
    /// Its figures (those it reached, for a run cut short).
    pub figures: Figures,
}

/// The matrix a `--vary` names, of `s`'s model.
fn matrix(s: &mut Scenario, m: Matrix) -> &mut lti::Mat {
    match m {
        Matrix::A => &mut s.model.a,
        Matrix::B => &mut s.model.b,
        Matrix::C => &mut s.model.c,
        Matrix::E => &mut s.model.e,
        Matrix::D => &mut s.model.d,
    }
}

/// [`matrix`], to read.
fn matrix_ref(s: &Scenario, m: Matrix) -> &lti::Mat {
    match m {
        Matrix::A => &s.model.a,
        Matrix::B => &s.model.b,
        Matrix::C => &s.model.c,
        Matrix::E => &s.model.e,
        Matrix::D => &s.model.d,
    }
}

/// The parameter map a place names: the FMU plant's `parameters`, or a process plant's `params`.
fn parameters<'s>(
    s: &'s Scenario,
    place: &Place,
) -> Option<&'s serde_json::Map<String, serde_json::Value>> {
    let params = &s.plant_process.as_ref()?.params;
    match place {
        Place::FmuParameter(_) => params.get("parameters")?.as_object(),
        Place::ProcessParameter(_) => params.as_object(),
        Place::Matrix(..) => None,
    }
}

/// The number `s` gives the parameter a place names, if any.
fn parameter(s: &Scenario, place: &Place) -> Option<f64> {
    let name = match place {
        Place::FmuParameter(n) | Place::ProcessParameter(n) => n,
        Place::Matrix(..) => return None,
    };
    parameters(s, place)?.get(name)?.as_f64()
}

/// Checks the `--vary`s against the scenario: matrices of a built-in plant, entries inside
/// them; parameters of an FMU plant whose nominal value the scenario gives.
pub fn check(s: &Scenario, varies: &[Vary]) -> Result<(), LaunchError> {
    let other = if s.plant_fmu.is_some() {
        Some("an FMU")
    } else if s.plant_replay.is_some() {
        Some("replayed data")
    } else if s.plant_process.is_some() {
        Some("an external process")
    } else {
        None
    };
    let bad = |v: &Vary, why: String| LaunchError::BadInput(format!("--vary '{}': {why}", v.text));
    let kit = s.plant_process.is_some() && s.plant_fmu.is_none() && s.plant_replay.is_none();
    for v in varies {
        match &v.place {
            Place::Matrix(..) if other.is_some() => {
                return Err(bad(
                    v,
                    format!(
                        "{}'s plant is {}; a matrix is varied in the built-in plant (an FMU's parameters as {}NAME, a process's as {}NAME)",
                        s.name,
                        other.unwrap_or_default(),
                        spec::FMU_PARAMETERS,
                        spec::PROCESS_PARAMS
                    ),
                ));
            }
            Place::Matrix(m, entry) => {
                let (r, c) = matrix_ref(s, *m).shape();
                if r * c == 0 {
                    return Err(bad(v, format!("{} is empty in this scenario", m.name())));
                }
                if let Some((i, j)) = *entry
                    && (i >= r || j >= c)
                {
                    return Err(bad(
                        v,
                        format!(
                            "{} is {r}×{c}, it has no entry [{},{}]",
                            m.name(),
                            i + 1,
                            j + 1
                        ),
                    ));
                }
            }
            Place::FmuParameter(_) if s.plant_fmu.is_none() => {
                return Err(bad(v, format!("{}'s plant is not an FMU", s.name)));
            }
            Place::ProcessParameter(_) if !kit => {
                return Err(bad(
                    v,
                    format!("{}'s plant is not an external process", s.name),
                ));
            }
            Place::FmuParameter(name) | Place::ProcessParameter(name) => {
                if parameter(s, &v.place).is_none() {
                    let table = match v.place {
                        Place::FmuParameter(_) => "[plant.fmu] parameters",
                        _ => "[plant.process] params",
                    };
                    return Err(bad(
                        v,
                        format!(
                            "the scenario gives no number for {name} in {table}: give its nominal value (the one the model stands for)"
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The value of `v` at the nominal model: a scaling of 1, or the entry's own value.
fn nominal_value(s: &Scenario, v: &Vary) -> f64 {
    match (v.op, &v.place) {
        (Op::Scale, _) | (Op::Set, Place::Matrix(_, None)) => 1.0,
        (Op::Set, Place::Matrix(m, Some((i, j)))) => matrix_ref(s, *m)[(*i, *j)],
        (Op::Set, place) => parameter(s, place).unwrap_or(f64::NAN),
    }
}

/// The points: the nominal one first, then the grids' product times the draws.
pub fn points(s: &Scenario, opts: &VaryOptions) -> Result<Vec<Point>, LaunchError> {
    let grids: Vec<Option<&Vec<f64>>> = opts
        .varies
        .iter()
        .map(|v| match &v.values {
            Values::Grid(g) => Some(g),
            _ => None,
        })
        .collect();
    let random = grids.iter().any(Option::is_none);
    let draws = if random { opts.draws.max(1) } else { 1 };
    let combos: usize = grids
        .iter()
        .map(|g| g.map_or(1, Vec::len))
        .try_fold(draws, |acc: usize, k| acc.checked_mul(k))
        .filter(|&n| n < MAX_POINTS)
        .ok_or_else(|| {
            LaunchError::BadInput(format!(
                "--vary: more than {MAX_POINTS} points (the grids' product times --points)"
            ))
        })?;
    // The draws, one row per draw, the same for every grid combination. One stream, drawn in
    // (draw, --vary) order.
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed ^ 0x7661_7279); // "vary"
    let mut drawn = vec![vec![f64::NAN; opts.varies.len()]; draws];
    for row in drawn.iter_mut() {
        for (k, v) in opts.varies.iter().enumerate() {
            row[k] = match v.values {
                Values::Grid(_) => f64::NAN,
                Values::Uniform(lo, hi) => Uniform::new_inclusive(lo, hi)
                    .map_err(|e| LaunchError::BadInput(format!("--vary '{}': {e}", v.text)))?
                    .sample(&mut rng),
                Values::Normal(mu, sd) => Normal::new(mu, sd)
                    .map_err(|e| LaunchError::BadInput(format!("--vary '{}': {e}", v.text)))?
                    .sample(&mut rng),
                Values::LogUniform(lo, hi) => 10f64.powf(
                    Uniform::new_inclusive(lo.log10(), hi.log10())
                        .map_err(|e| LaunchError::BadInput(format!("--vary '{}': {e}", v.text)))?
                        .sample(&mut rng),
                ),
            };
        }
    }
    let mut out = vec![Point {
        values: opts.varies.iter().map(|v| nominal_value(s, v)).collect(),
        nominal: true,
    }];
    for n in 0..combos {
        // Mixed radix over the grids, the last --vary fastest; the draw index slowest.
        let (mut rest, mut values) = (n, vec![0.0; opts.varies.len()]);
        for (k, g) in grids.iter().enumerate().rev() {
            if let Some(g) = g {
                values[k] = g[rest % g.len()];
                rest /= g.len();
            }
        }
        for (k, g) in grids.iter().enumerate() {
            if g.is_none() {
                values[k] = drawn[rest][k];
            }
        }
        out.push(Point {
            values,
            nominal: false,
        });
    }
    Ok(out)
}

/// `s` with the point's plant: each `--vary` applied to the model's matrices or the FMU's
/// parameters. The nominal point is the scenario itself.
pub fn apply(s: &Scenario, varies: &[Vary], point: &Point) -> Scenario {
    let mut s = s.clone();
    if point.nominal {
        return s;
    }
    for (v, &x) in varies.iter().zip(&point.values) {
        match &v.place {
            Place::Matrix(m, entry) => {
                let m = matrix(&mut s, *m);
                match (v.op, entry) {
                    (Op::Scale, Some((i, j))) => m[(*i, *j)] *= x,
                    (Op::Scale, None) => *m *= x,
                    (Op::Set, Some((i, j))) => m[(*i, *j)] = x,
                    (Op::Set, None) => unreachable!("a whole matrix is only scaled (spec.rs)"),
                }
            }
            Place::FmuParameter(name) | Place::ProcessParameter(name) => {
                let value = match v.op {
                    Op::Scale => parameter(&s, &v.place).unwrap_or(f64::NAN) * x,
                    Op::Set => x,
                };
                let params = s.plant_process.as_mut().map(|p| &mut p.params);
                let map = match (&v.place, params) {
                    (Place::FmuParameter(_), Some(p)) => p.get_mut("parameters"),
                    (_, p) => p,
                };
                if let Some(map) = map.and_then(|m| m.as_object_mut()) {
                    map.insert(name.clone(), serde_json::json!(value));
                }
            }
        }
    }
    s
}

/// How the points run: in one process, or — an FMU or kit component plant, which runs only in
/// its own process — as processes, one point at a time.
pub fn mode_of(s: &Scenario, jobs: usize) -> (Mode, usize) {
    if s.plant_process.is_some() {
        (Mode::Processes, 1)
    } else {
        (Mode::InProcess, jobs)
    }
}

/// Runs every point (in-process, `jobs` at a time), in point order.
pub fn vary(s: &Scenario, plan: &Plan, opts: &VaryOptions) -> Result<Vec<Outcome>, LaunchError> {
    check(s, &opts.varies)?;
    crate::limits::jobs(opts.jobs)?;
    let points = points(s, opts)?;
    let jobs = mode_of(s, opts.jobs).1.clamp(1, points.len());
    run::budget::check_memory(s, plan, jobs as u64)?;
    run::create_output_dir(&opts.out)?;
    let mut base = s.clone();
    base.seed = opts.seed;
    let results = crate::sweep::pool::in_order(
        points.len(),
        jobs,
        |i| one(&base, plan, opts, &points[i]),
        || {},
    );
    if let Some(sig) = run::interrupt::received() {
        return Err(LaunchError::Interrupted(format!(
            "{}: --vary interrupted by {sig}",
            s.name
        )));
    }
    // A point that could not run ends the variation (the points after it never started).
    let mut out = Vec::with_capacity(results.len());
    for r in results {
        match r {
            Some(Ok(o)) => out.push(o),
            Some(Err(e)) => return Err(e),
            None => {}
        }
    }
    Ok(out)
}

/// Runs one point.
fn one(
    s: &Scenario,
    plan: &Plan,
    opts: &VaryOptions,
    point: &Point,
) -> Result<Outcome, LaunchError> {
    let varied = apply(s, &opts.varies, point);
    let o = run::run(
        &varied,
        plan,
        &Options::quiet(&opts.out, mode_of(s, opts.jobs).0, opts.wait, false),
    )?;
    let (status, reason) = match &o.stop {
        Stop::Completed => ("completed", None),
        Stop::Diverged(w) => ("diverged", Some(w.clone())),
        Stop::Failed(w) => ("failed", Some(w.clone())),
        Stop::Interrupted(sig) => {
            return Err(LaunchError::Interrupted(format!(
                "{}: --vary interrupted by {sig}",
                s.name
            )));
        }
    };
    Ok(Outcome {
        point: point.clone(),
        status,
        reason,
        figures: Figures::of(&o.summary),
    })
}
