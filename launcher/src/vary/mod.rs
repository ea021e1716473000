//! `uio-launcher sweep --vary`: how far the observers hold when the plant is not the model.
//!
//! The plant varied is the built-in one (its matrices), an FMU or a kit component (their
//! parameters; the points then run as processes, one at a time, as such a plant only runs in
//! its own process). Any of them can also be run at another operating point, from another
//! initial state, or sampled at another interval:
//!
//! - `plant.operating_point.u[i]` (`w[i]`): the plant's known (unknown) input i is moved by
//!   u′_i − u_op,i at every sample — its `[[input]]` (`[[disturbance]]`) signal shifted — while
//!   the observers and the controller keep the design's point and offsets. A nonlinear plant
//!   then settles where its own dynamics put it, which the linear model at u_op only
//!   approximates; the built-in linear plant settles at the model's new equilibrium, which the
//!   observers follow exactly. In a closed loop the controller sets the commanded inputs: only a
//!   measured disturbance's level can be moved this way.
//! - `x0[i]`: the simulated plant's initial state (the observers keep their `xhat0`).
//! - `dt`: the plant is sampled at dt′ — its exact sampling, the process noise's Q_d and the
//!   schedules (inputs, faults, `ignore_before`) at t_k = k·dt′, round(duration/dt′) steps —
//!   while every observer, bank and controller keeps the gains designed at dt (the controller's
//!   integrator sums over the samples' dt′). Not for a plant given per step (`time =
//!   "discrete"`) nor replayed data: their sampling is the data's.
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
use spec::{Matrix, Op, Place, PointSignal, Values, Vary};

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
        _ => None,
    }
}

/// The number `s` gives the parameter a place names, if any.
fn parameter(s: &Scenario, place: &Place) -> Option<f64> {
    let name = match place {
        Place::FmuParameter(n) | Place::ProcessParameter(n) => n,
        _ => return None,
    };
    parameters(s, place)?.get(name)?.as_f64()
}

/// u_op,i or w_op,i of the design's point (0 without `[plant.operating_point]`).
fn point_value(s: &Scenario, which: PointSignal, i: usize) -> f64 {
    s.operating_point.as_ref().map_or(0.0, |op| match which {
        PointSignal::U => op.u[i],
        PointSignal::W => op.w[i],
    })
}

/// The scenario's value of a vector or scalar place (`None` for a matrix or a parameter).
/// Precondition: an entry's index inside its vector ([`check`]).
fn scalar(s: &Scenario, place: &Place) -> Option<f64> {
    match *place {
        Place::OperatingPoint(which, i) => Some(point_value(s, which, i)),
        Place::InitialState(i) => Some(s.x0[i]),
        Place::SamplePeriod => Some(s.dt),
        _ => None,
    }
}

/// Checks a variation of the operating point, the initial state or dt against the scenario.
fn check_scalar(s: &Scenario, v: &Vary) -> Result<(), String> {
    let (n, l, q) = (s.model.n(), s.model.l(), s.model.e.ncols());
    if s.plant_replay.is_some() {
        return Err(format!(
            "{}'s plant is replayed data: its inputs, states and samples are the recording's",
            s.name
        ));
    }
    let (count, what) = match v.place {
        Place::OperatingPoint(PointSignal::U, i) => (Some((i, l)), "known inputs"),
        Place::OperatingPoint(PointSignal::W, i) => (Some((i, q)), "unknown inputs"),
        Place::InitialState(i) => (Some((i, n)), "states"),
        _ => (None, ""),
    };
    if let Some((i, count)) = count
        && i >= count
    {
        return Err(format!(
            "the plant has {count} {what}, there is no entry {}",
            i + 1
        ));
    }
    if let (Place::OperatingPoint(PointSignal::U, i), Some(c)) = (&v.place, &s.controller)
        && !c.measured.contains(i)
    {
        return Err(format!(
            "in {}'s closed loop the controller commands input {}: move its point by its reference ([[input]] {}) or vary a measured disturbance",
            s.name,
            i + 1,
            i + 1
        ));
    }
    if v.place == Place::SamplePeriod && s.discrete {
        return Err(format!(
            "{}'s plant is given per step (time = \"discrete\"): Φ is the sampling of its own dt",
            s.name
        ));
    }
    let nominal = scalar(s, &v.place).unwrap_or(f64::NAN);
    if v.op == Op::Scale && nominal == 0.0 {
        return Err(format!(
            "{} is 0 in this scenario, a scaling keeps it 0: set it ({} = …)",
            v.target, v.target
        ));
    }
    if v.place == Place::SamplePeriod {
        let positive = match &v.values {
            Values::Grid(g) => g.iter().all(|&x| x > 0.0),
            Values::Uniform(lo, _) => *lo > 0.0,
            // Log-uniform draws are positive; a normal one is judged per point.
            Values::LogUniform(..) | Values::Normal(..) => true,
        };
        if !positive {
            return Err(format!(
                "dt must stay > 0 (a {} of dt = {})",
                if v.op == Op::Scale {
                    "scaling"
                } else {
                    "value"
                },
                lti::eig::sig(s.dt)
            ));
        }
    }
    Ok(())
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
            Place::OperatingPoint(..) | Place::InitialState(_) | Place::SamplePeriod => {
                check_scalar(s, v).map_err(|why| bad(v, why))?;
            }
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
        (Op::Set, place) => scalar(s, place)
            .or_else(|| parameter(s, place))
            .unwrap_or(f64::NAN),
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

/// `s` with the point's plant: each `--vary` applied to the model's matrices, the FMU's
/// parameters, the plant's inputs, initial state or dt. The nominal point is the scenario
/// itself. A drawn dt that is no sampling interval (≤ 0, or too many steps) is refused, naming it.
pub fn apply(s: &Scenario, varies: &[Vary], point: &Point) -> Result<Scenario, String> {
    let mut s = s.clone();
    if point.nominal {
        return Ok(s);
    }
    for (v, &x) in varies.iter().zip(&point.values) {
        let value = |nominal: f64| match v.op {
            Op::Scale => nominal * x,
            Op::Set => x,
        };
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
                let value = value(parameter(&s, &v.place).unwrap_or(f64::NAN));
                let params = s.plant_process.as_mut().map(|p| &mut p.params);
                let map = match (&v.place, params) {
                    (Place::FmuParameter(_), Some(p)) => p.get_mut("parameters"),
                    (_, p) => p,
                };
                if let Some(map) = map.and_then(|m| m.as_object_mut()) {
                    map.insert(name.clone(), serde_json::json!(value));
                }
            }
            &Place::OperatingPoint(which, i) => {
                let nominal = point_value(&s, which, i);
                let shift = value(nominal) - nominal;
                let signal = match which {
                    PointSignal::U => &mut s.inputs[i],
                    PointSignal::W => &mut s.disturbances[i],
                };
                *signal = signal.shifted(shift);
            }
            &Place::InitialState(i) => s.x0[i] = value(s.x0[i]),
            Place::SamplePeriod => {
                let dt = value(s.dt);
                let steps = (s.duration / dt).round();
                let runs = (1.0..=scenario::limits::MAX_STEPS as f64).contains(&steps);
                if !(dt > 0.0 && dt.is_finite() && runs) {
                    return Err(format!(
                        "dt = {} gives no run of {} s (1 … {} steps)",
                        lti::eig::sig(dt),
                        lti::eig::sig(s.duration),
                        scenario::limits::MAX_STEPS
                    ));
                }
                s.dt = dt;
                s.steps = steps as u64;
            }
        }
    }
    Ok(s)
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
    let varied = match apply(s, &opts.varies, point) {
        Ok(v) => v,
        Err(why) => {
            return Ok(Outcome {
                point: point.clone(),
                status: "failed",
                reason: Some(why),
                figures: Figures::default(),
            });
        }
    };
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
