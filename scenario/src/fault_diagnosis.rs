//! `[noise]`, `[[fault]]` and `[[diagnoser]]`: validated into what the plant injects and the
//! banks that must find it.

use std::collections::BTreeSet;

use diagnosis::{Channels, DiagnoserSpec, Evaluation, MemberKind, Scheme, Threshold};
use lti::signal::{Switch, locate};
use lti::{Mat, Model};
use plant::fault::{Fault, Kind, Profile, Target};

use super::limits::{MAX_CALIBRATION_RUNS, MAX_WINDOW};
use super::raw::{RawDiagnoser, RawFault, RawNoise};
use super::untrusted::quoted;
use crate::check::{
    Bad, bad, check_name, definite, false_alarm, finite, matrix, one_of, placement, poles,
};

/// The run's noise: the per-step covariances the plant draws from and the Kalman filter uses.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseSpec {
    /// Q_d, n×n (zero without process noise).
    pub qd: Mat,
    /// R, p×p (zero without measurement noise).
    pub r: Mat,
}

/// A covariance named `symbol` (Q_c, Q_d, R): of the size asked, and symmetric ⪰ 0 by the rule
/// the Riccati and Van Loan code applies to its arguments ([`lti::dare::symmetric`]).
fn covariance(
    field: &str,
    symbol: &str,
    rows: &super::raw::Rows,
    size: Option<usize>,
    why: &str,
) -> Result<Mat, Bad> {
    let m = matrix(field, rows, (size, size), why)?;
    definite(field, symbol, &m, lti::dare::Definite::Semi)
}

/// `[noise]`, with Q_d computed from the continuous intensity by Van Loan's method.
pub(crate) fn noise(
    raw: &Option<RawNoise>,
    model: &Model,
    dt: f64,
) -> Result<Option<NoiseSpec>, Bad> {
    let Some(z) = raw else { return Ok(None) };
    let (n, p) = (model.n(), model.p());
    let qd = match (&z.process, &z.process_discrete) {
        (Some(_), Some(_)) => {
            return Err(bad(
                "noise.process_discrete",
                "give process (continuous intensity) or process_discrete, not both",
            ));
        }
        (Some(qc), None) => {
            let g = match &z.g {
                Some(g) => matrix(
                    "noise.G",
                    g,
                    (Some(n), None),
                    "n rows, one column per process-noise input",
                )?,
                None => Mat::identity(n, n),
            };
            let qc = covariance(
                "noise.process",
                "Q_c",
                qc,
                Some(g.ncols()),
                "one row and column per column of noise.G",
            )?;
            lti::process_noise_covariance(&model.a, &g, &qc, dt)
                .map_err(|e| bad("noise.process", e.to_string()))?
        }
        (None, Some(qd)) => {
            if z.g.is_some() {
                return Err(bad(
                    "noise.G",
                    "G shapes the continuous intensity `process`; process_discrete is the state's own covariance",
                ));
            }
            covariance(
                "noise.process_discrete",
                "Q_d",
                qd,
                Some(n),
                "n×n, the covariance of the state's noise per step",
            )?
        }
        (None, None) => {
            if z.g.is_some() {
                return Err(bad("noise.G", "G needs process = [[…]]"));
            }
            Mat::zeros(n, n)
        }
    };
    let r = match &z.measurement {
        Some(r) => covariance(
            "noise.measurement",
            "R",
            r,
            Some(p),
            "p×p, one row and column per output",
        )?,
        None => Mat::zeros(p, p),
    };
    Ok(Some(NoiseSpec { qd, r }))
}

/// A fault's switching time: finite, ≥ 0, on a sample.
fn on_sample(field: &str, t: f64, dt: f64) -> Result<f64, Bad> {
    finite(field, t)?;
    if t < 0.0 {
        return Err(bad(field, format!("{t} must be ≥ 0")));
    }
    match locate(t, dt) {
        Switch::OnSample(_) | Switch::Beyond => Ok(t),
        Switch::Inside { .. } => Err(bad(
            field,
            format!("{t} is not a sample time of dt = {dt} (faults switch at samples)"),
        )),
    }
}

/// `[[fault]]`.
// one job: `[[fault]]` validated field by field in the order the docs list them; splitting would
// scatter one section's rules.
pub(crate) fn faults(
    raw: &[RawFault],
    model: &Model,
    ff: &Mat,
    dt: f64,
) -> Result<Vec<Fault>, Bad> {
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    for (i, f) in raw.iter().enumerate() {
        let at = |key: &str| format!("fault[{}].{key}", i + 1);
        check_name(&at("name"), &f.name, "it names the fault's signals")?;
        if !seen.insert(f.name.clone()) {
            return Err(bad(
                at("name"),
                format!("two faults are named {}", quoted(&f.name)),
            ));
        }
        let (count, what) = match f.target.as_str() {
            "actuator" => (model.l(), "known inputs (columns of B)"),
            "sensor" => (model.p(), "outputs (rows of C)"),
            "component" => (ff.ncols(), "columns of plant.Ff"),
            other => {
                return Err(bad(
                    at("target"),
                    format!(
                        "{} is not a fault target (actuator, sensor, component){}",
                        quoted(other),
                        crate::suggest::did_you_mean(other, ["actuator", "sensor", "component"])
                    ),
                ));
            }
        };
        if f.channel < 1 || f.channel as usize > count {
            return Err(bad(
                at("channel"),
                format!("{} does not exist: the plant has {count} {what}", f.channel),
            ));
        }
        let ch = f.channel as usize - 1;
        let target = match f.target.as_str() {
            "actuator" => Target::Actuator(ch),
            "sensor" => Target::Sensor(ch),
            _ => Target::Component(ch),
        };
        let kinds: &[&str] = match target {
            Target::Actuator(_) => &["additive", "stuck", "gain"],
            Target::Sensor(_) => &["bias", "drift", "stuck", "noise"],
            Target::Component(_) => &["additive"],
        };
        if !kinds.contains(&f.kind.as_str()) {
            return Err(bad(
                at("kind"),
                format!(
                    "{} is not a kind of {} fault ({}){}",
                    quoted(&f.kind),
                    f.target,
                    kinds.join(", "),
                    crate::suggest::did_you_mean(&f.kind, kinds.iter().copied())
                ),
            ));
        }
        let kind = match f.kind.as_str() {
            "additive" => Kind::Additive,
            "stuck" => Kind::Stuck,
            "gain" => Kind::Gain,
            "bias" => Kind::Bias,
            "drift" => Kind::Drift,
            _ => Kind::Noise,
        };
        let value = finite(&at("value"), f.value)?;
        if kind == Kind::Gain && !(0.0..=1.0).contains(&value) {
            return Err(bad(
                at("value"),
                format!("{value}: the fraction of gain lost is between 0 and 1"),
            ));
        }
        if kind == Kind::Noise && value < 0.0 {
            return Err(bad(
                at("value"),
                format!("{value}: a standard deviation is ≥ 0"),
            ));
        }
        let default = if kind == Kind::Drift { "ramp" } else { "step" };
        let profile_name = f.profile.as_deref().unwrap_or(default);
        let ramps = matches!(kind, Kind::Additive | Kind::Bias | Kind::Drift);
        if kind == Kind::Drift && profile_name != "ramp" {
            return Err(bad(
                at("profile"),
                "a drift is a ramp (profile = \"ramp\", or no profile)",
            ));
        }
        let profile = match profile_name {
            "step" | "ramp" => {
                if f.intervals.is_some() {
                    return Err(bad(
                        at("intervals"),
                        format!("a {profile_name} profile has start and end, not intervals"),
                    ));
                }
                let start = on_sample(
                    &at("start"),
                    f.start.ok_or_else(|| {
                        bad(at("start"), format!("a {profile_name} fault needs start"))
                    })?,
                    dt,
                )?;
                let end = f.end.map(|e| on_sample(&at("end"), e, dt)).transpose()?;
                if end.is_some_and(|e| e <= start) {
                    return Err(bad(
                        at("end"),
                        format!("{} must be after start = {start}", end.unwrap_or(0.0)),
                    ));
                }
                if profile_name == "ramp" {
                    if !ramps {
                        return Err(bad(
                            at("profile"),
                            format!(
                                "a {} fault cannot ramp (only additive, bias and drift)",
                                f.kind
                            ),
                        ));
                    }
                    Profile::Ramp { start, end }
                } else {
                    Profile::Step { start, end }
                }
            }
            "intermittent" => {
                if f.start.is_some() || f.end.is_some() {
                    return Err(bad(
                        at("start"),
                        "an intermittent fault has intervals = [[on, off], …], not start and end",
                    ));
                }
                let list = f
                    .intervals
                    .as_ref()
                    .filter(|l| !l.is_empty())
                    .ok_or_else(|| {
                        bad(
                            at("intervals"),
                            "an intermittent fault needs intervals = [[on, off], …]",
                        )
                    })?;
                let mut ivs: Vec<[f64; 2]> = Vec::new();
                for (j, iv) in list.iter().enumerate() {
                    let fj = format!("fault[{}].intervals[{}]", i + 1, j + 1);
                    let [on, off] = iv.as_slice() else {
                        return Err(bad(fj, "each interval is [on, off]"));
                    };
                    let (on, off) = (on_sample(&fj, *on, dt)?, on_sample(&fj, *off, dt)?);
                    if off <= on || ivs.last().is_some_and(|l| on < l[1]) {
                        return Err(bad(
                            fj,
                            format!(
                                "[{on}, {off}] must end after it starts and after the previous interval"
                            ),
                        ));
                    }
                    ivs.push([on, off]);
                }
                Profile::Intermittent { intervals: ivs }
            }
            other => {
                return Err(bad(
                    at("profile"),
                    format!(
                        "{} is not a profile (step, ramp, intermittent){}",
                        quoted(other),
                        crate::suggest::did_you_mean(other, ["step", "ramp", "intermittent"])
                    ),
                ));
            }
        };
        out.push(Fault {
            name: f.name.clone(),
            target,
            kind,
            value,
            profile,
        });
    }
    Ok(out)
}

/// `[[diagnoser]]`; the banks themselves are designed with the observers (launcher `plan`).
pub(crate) fn diagnosers(
    raw: &[RawDiagnoser],
    model: &Model,
    ff: &Mat,
    noise: Option<&NoiseSpec>,
    dt: f64,
    taken: &mut BTreeSet<String>,
) -> Result<Vec<DiagnoserSpec>, Bad> {
    raw.iter()
        .enumerate()
        .map(|(i, d)| diagnoser(i, d, model, ff, noise, dt, taken))
        .collect()
}

/// The `i`-th (0-based) `[[diagnoser]]`, its members' names claimed in `taken`.
fn diagnoser(
    i: usize,
    d: &RawDiagnoser,
    model: &Model,
    ff: &Mat,
    noise: Option<&NoiseSpec>,
    dt: f64,
    taken: &mut BTreeSet<String>,
) -> Result<DiagnoserSpec, Bad> {
    let at = |key: &str| format!("diagnoser[{}].{key}", i + 1);
    check_name(
        &at("name"),
        &d.name,
        "it names the bank's observers and signals",
    )?;
    let scheme = one_of(
        at("scheme"),
        "scheme",
        &d.scheme,
        &[
            ("generalized", Scheme::Generalized),
            ("dedicated", Scheme::Dedicated),
        ],
    )?;
    let channels = one_of(
        at("faults"),
        "channel class",
        &d.faults,
        &[
            ("actuator", Channels::Actuator),
            ("sensor", Channels::Sensor),
            ("component", Channels::Component),
        ],
    )?;
    let all = diagnosis::bank::channel_labels(channels, model, ff);
    let subset = subset(i, d, channels, &all)?;
    claim_members(i, d, subset.as_ref().map_or(all.len(), Vec::len), taken)?;
    let member = member(i, d, channels, noise)?;
    let structure = structure(i, d)?;
    let evaluation = evaluation(i, d)?;
    let threshold = threshold(i, d, &evaluation, noise)?;
    let persistence = d.persistence.unwrap_or(1);
    if persistence < 1 {
        return Err(bad(
            at("persistence"),
            format!("{persistence} must be a whole number of samples ≥ 1"),
        ));
    }
    let ignore_before = finite(&at("ignore_before"), d.ignore_before.unwrap_or(0.0))?;
    if ignore_before < 0.0 {
        return Err(bad(
            at("ignore_before"),
            format!("{ignore_before} must be ≥ 0"),
        ));
    }
    Ok(DiagnoserSpec {
        name: d.name.clone(),
        scheme,
        channels,
        subset,
        member,
        structure,
        evaluation,
        threshold,
        persistence: persistence.min(u32::MAX as i64) as u32,
        ignore_before,
        glr: crate::glr::glr(i, d.glr.as_ref(), noise.is_some(), dt)?,
    })
}

/// `channels`: a subset of the class's channels (0-based, sorted), at least two; `None`: all.
fn subset(
    i: usize,
    d: &RawDiagnoser,
    channels: Channels,
    all: &[String],
) -> Result<Option<Vec<usize>>, Bad> {
    let at = |key: &str| format!("diagnoser[{}].{key}", i + 1);
    Ok(match &d.channels {
        None => None,
        Some(list) => {
            let mut ids = Vec::with_capacity(list.len());
            for &c in list {
                if c < 1 || c as usize > all.len() {
                    return Err(bad(
                        at("channels"),
                        format!(
                            "{c} is not a {} channel: they are 1 … {} ({})",
                            channels.name(),
                            all.len(),
                            all.join(", ")
                        ),
                    ));
                }
                if ids.contains(&(c as usize - 1)) {
                    return Err(bad(at("channels"), format!("{c} is listed twice")));
                }
                ids.push(c as usize - 1);
            }
            if ids.len() < 2 {
                return Err(bad(
                    at("channels"),
                    format!(
                        "a bank needs at least two channels to isolate between, {} given",
                        ids.len()
                    ),
                ));
            }
            ids.sort_unstable();
            Some(ids)
        }
    })
}

/// The members' observer names (`<name>-1` … `<name>-m`) must be free, and short enough to be
/// names themselves.
fn claim_members(
    i: usize,
    d: &RawDiagnoser,
    m: usize,
    taken: &mut BTreeSet<String>,
) -> Result<(), Bad> {
    let at = |key: &str| format!("diagnoser[{}].{key}", i + 1);
    for j in 1..=m {
        let member = format!("{}-{j}", d.name);
        check_name(&at("name"), &member, "it names the bank's observers")?;
        if !taken.insert(member.clone()) {
            return Err(bad(
                at("name"),
                format!(
                    "its member {} would share a name with an observer or another member",
                    quoted(&member)
                ),
            ));
        }
    }
    Ok(())
}

/// The members' design: `observer` (default: Luenberger for sensor channels, else the
/// Chen–Patton UIO, the only one blind to an input channel) with its poles and placement.
fn member(
    i: usize,
    d: &RawDiagnoser,
    channels: Channels,
    noise: Option<&NoiseSpec>,
) -> Result<MemberKind, Bad> {
    let at = |key: &str| format!("diagnoser[{}].{key}", i + 1);
    let default = if channels == Channels::Sensor {
        "luenberger"
    } else {
        "chen-patton-uio"
    };
    let kind = d.observer.as_deref().unwrap_or(default);
    let pole_list = || match &d.poles {
        Some(p) => poles(&at("poles"), p),
        None => Err(bad(at("poles"), format!("{kind} members need poles"))),
    };
    let method = placement(&at("placement"), &d.placement)?;
    let member = match kind {
        "chen-patton-uio" => MemberKind::ChenPatton {
            poles: pole_list()?,
            placement: method,
        },
        "luenberger" => MemberKind::Luenberger {
            poles: pole_list()?,
            placement: method,
        },
        "kalman" => {
            if d.poles.is_some() {
                return Err(bad(
                    at("poles"),
                    "kalman members take no poles (the noise sets them)",
                ));
            }
            if noise.is_none() {
                return Err(bad(at("observer"), "kalman members need [noise]"));
            }
            MemberKind::Kalman
        }
        other => {
            return Err(bad(
                at("observer"),
                format!(
                    "{} is not a member design (chen-patton-uio, luenberger, kalman){}",
                    quoted(other),
                    crate::suggest::did_you_mean(
                        other,
                        ["chen-patton-uio", "luenberger", "kalman"]
                    )
                ),
            ));
        }
    };
    if channels != Channels::Sensor && kind != "chen-patton-uio" {
        return Err(bad(
            at("observer"),
            format!(
                "{kind} cannot be blind to a {} channel: use chen-patton-uio",
                channels.name()
            ),
        ));
    }
    Ok(member)
}

/// `structure`: the structure matrix asked for, of 0 and 1.
fn structure(i: usize, d: &RawDiagnoser) -> Result<Option<Vec<Vec<u8>>>, Bad> {
    d.structure
        .as_ref()
        .map(|rows| {
            rows.iter()
                .enumerate()
                .map(|(r, row)| {
                    row.iter()
                        .map(|&v| {
                            if v == 0 || v == 1 {
                                Ok(v as u8)
                            } else {
                                Err(bad(
                                    format!("diagnoser[{}].structure[{}]", i + 1, r + 1),
                                    format!("{v}: entries are 0 or 1"),
                                ))
                            }
                        })
                        .collect::<Result<Vec<u8>, Bad>>()
                })
                .collect::<Result<Vec<_>, Bad>>()
        })
        .transpose()
}

/// `evaluation` (norm, rms with its window, forgetting with λ, chi2) and the keys only one of
/// them takes.
fn evaluation(i: usize, d: &RawDiagnoser) -> Result<Evaluation, Bad> {
    let at = |key: &str| format!("diagnoser[{}].{key}", i + 1);
    let evaluation = match d.evaluation.as_deref().unwrap_or("rms") {
        "norm" => Evaluation::Norm,
        "rms" => {
            let w = d.window.unwrap_or(10);
            if w < 1 {
                return Err(bad(
                    at("window"),
                    format!("{w} must be a whole number of samples ≥ 1"),
                ));
            }
            if w > MAX_WINDOW {
                return Err(bad(
                    at("window"),
                    format!(
                        "{w} samples: at most {MAX_WINDOW} (each member keeps its window in memory, 8 bytes a sample)"
                    ),
                ));
            }
            Evaluation::Rms { window: w as usize }
        }
        "forgetting" => {
            let l = finite(
                &at("forgetting"),
                d.forgetting.ok_or_else(|| {
                    bad(
                        at("forgetting"),
                        "evaluation = \"forgetting\" needs forgetting = λ, 0 < λ < 1",
                    )
                })?,
            )?;
            if !(l > 0.0 && l < 1.0) {
                return Err(bad(
                    at("forgetting"),
                    format!("{l} must be between 0 and 1"),
                ));
            }
            Evaluation::Forgetting { lambda: l }
        }
        "chi2" => Evaluation::Chi2,
        other => {
            return Err(bad(
                at("evaluation"),
                format!(
                    "{} is not an evaluation (norm, rms, forgetting, chi2){}",
                    quoted(other),
                    crate::suggest::did_you_mean(other, ["norm", "rms", "forgetting", "chi2"])
                ),
            ));
        }
    };
    if d.window.is_some() && !matches!(evaluation, Evaluation::Rms { .. }) {
        return Err(bad(
            at("window"),
            "only evaluation = \"rms\" takes a window",
        ));
    }
    if d.forgetting.is_some() && !matches!(evaluation, Evaluation::Forgetting { .. }) {
        return Err(bad(
            at("forgetting"),
            "only evaluation = \"forgetting\" takes forgetting",
        ));
    }
    Ok(evaluation)
}

/// One of `threshold`, `false_alarm` (a χ² threshold) and `calibrate`.
fn threshold(
    i: usize,
    d: &RawDiagnoser,
    evaluation: &Evaluation,
    noise: Option<&NoiseSpec>,
) -> Result<Threshold, Bad> {
    let at = |key: &str| format!("diagnoser[{}].{key}", i + 1);
    let given = [
        d.threshold.is_some(),
        d.false_alarm.is_some(),
        d.calibrate.is_some(),
    ]
    .iter()
    .filter(|&&g| g)
    .count();
    if given > 1 {
        return Err(bad(
            at("threshold"),
            "give one of threshold, false_alarm and calibrate",
        ));
    }
    let threshold = match (d.threshold, d.false_alarm) {
        _ if d.calibrate.is_some() => {
            let c = d.calibrate.as_ref().expect("given");
            if c.runs < 1 {
                return Err(bad(
                    at("calibrate.runs"),
                    format!("{} must be a whole number of realisations ≥ 1", c.runs),
                ));
            }
            if c.runs > MAX_CALIBRATION_RUNS {
                return Err(bad(
                    at("calibrate.runs"),
                    format!(
                        "{} realisations: at most {MAX_CALIBRATION_RUNS} (each is a whole run of the scenario, made before the run starts)",
                        c.runs
                    ),
                ));
            }
            let margin = finite(&at("calibrate.margin"), c.margin.unwrap_or(1.2))?;
            if margin < 1.0 {
                return Err(bad(
                    at("calibrate.margin"),
                    format!(
                        "{margin} must be ≥ 1 (the threshold is margin × the largest fault-free J)"
                    ),
                ));
            }
            if noise.is_none() {
                return Err(bad(
                    at("calibrate"),
                    "calibration runs fault-free noisy realisations: the scenario has no [noise]",
                ));
            }
            Threshold::Calibrated {
                runs: c.runs as usize,
                margin,
            }
        }
        (Some(t), None) => {
            let t = finite(&at("threshold"), t)?;
            if t <= 0.0 {
                return Err(bad(at("threshold"), format!("{t} must be > 0")));
            }
            Threshold::Fixed(t)
        }
        (None, Some(a)) => {
            let a = false_alarm(&at("false_alarm"), a)?;
            if *evaluation != Evaluation::Chi2 {
                return Err(bad(
                    at("false_alarm"),
                    "a false-alarm probability sets a χ² threshold: it needs evaluation = \"chi2\"",
                ));
            }
            if noise.is_none() {
                return Err(bad(
                    at("false_alarm"),
                    "a χ² threshold needs the noise statistics: the scenario has no [noise]",
                ));
            }
            Threshold::FalseAlarm(a)
        }
        (Some(_), Some(_)) => {
            return Err(bad(
                at("false_alarm"),
                "give threshold or false_alarm, not both",
            ));
        }
        (None, None) => {
            return Err(bad(
                at("threshold"),
                "a diagnoser needs threshold = value, false_alarm = probability or calibrate = { runs = N }",
            ));
        }
    };
    Ok(threshold)
}
