//! A bank of residual generators from a [`DiagnoserSpec`] (Chen & Patton 1999, §3.3):
//!
//! * channels through the state (actuator i: column B_i; component j: column F_f,j). A member
//!   is an unknown-input observer whose unknown inputs are E and the channels it must be blind
//!   to — [E, F_i] for member i of the generalized scheme, [E, F_{j≠i}] for the dedicated one;
//!   its decoupling T F = 0 then holds for them exactly (to rounding, in the sampled design);
//! * sensor channels. Member j uses every output but y_j (generalized) or y_j alone
//!   (dedicated): a fault on an output it does not read cannot reach its residual.
//!
//! Each member is an ordinary [`LinearObserver`] (its K and Q widened with zero columns for the
//! outputs it does not read), run as an observer process like the others. The structure matrix
//! (residual i reacts to channel j) is then computed from the designs ([`crate::structure`]),
//! not assumed.

use lti::{Mat, Model};
use nalgebra::DVector;
use observer::design::Gain;
use observer::{Designed, Spec, design};

use crate::covariance::residual_covariance;
use crate::evaluate::threshold_for;
use crate::glr::GlrDesign;
use crate::spec::{Channels, DiagnoserSpec, MemberKind, Scheme};
use crate::structure::{BLIND, FaultInput, SteadyState, reacts};

/// One residual generator.
#[derive(Debug, Clone)]
pub struct Member {
    /// Its observer's name in the run: `<diagnoser>-<i>` (1-based).
    pub name: String,
    /// The outputs its residual uses (0-based).
    pub outputs: Vec<usize>,
    /// The channels it is blind to by design (0-based).
    pub blind: Vec<usize>,
    /// Its design (runtime widened to every output).
    pub designed: Designed,
    /// Σ_r of its residual under the run's noise (none without noise).
    pub covariance: Option<Mat>,
    /// Its threshold.
    pub threshold: f64,
    /// Degrees of freedom of its χ² statistic (the rank of Σ_r), for `evaluation = "chi2"`.
    pub dof: usize,
    /// Its GLR test, when the bank asks for one ([`crate::glr`]).
    pub glr: Option<GlrDesign>,
}

/// A designed bank.
#[derive(Debug, Clone)]
pub struct Bank {
    /// What was asked.
    pub spec: DiagnoserSpec,
    /// One per channel.
    pub members: Vec<Member>,
    /// Computed structure matrix: `structure[i][j]` = 1 if residual i reacts to channel j.
    pub structure: Vec<Vec<u8>>,
    /// The steady-state structure: `steady[i][j]` = 1 if residual i stays away from 0 under a
    /// constant fault on channel j ([`crate::structure::SteadyState`]); `None` when a member's
    /// state is not a function of x (its T cannot be formed).
    pub steady: Option<Vec<Vec<u8>>>,
    /// Labels of the channels it watches, e.g. "u1", "y3", "f2".
    pub channels: Vec<String>,
    /// Their indices in their class (0-based): column j of the structure is channel `ids[j]`.
    pub ids: Vec<usize>,
    /// How a fault on each watched channel enters the sampled plant (column j: channel `ids[j]`).
    pub inputs: Vec<FaultInput>,
}

/// Why a bank cannot be had: the member (0-based) when one is to blame, and the reason.
#[derive(Debug, Clone, PartialEq)]
pub struct BankError {
    /// The member, if one failed.
    pub member: Option<usize>,
    /// The scenario key the reason concerns (`structure`, `poles`, `false_alarm`, or "").
    pub key: &'static str,
    /// One line.
    pub reason: String,
}

/// Noise the members see: Q_d (n×n) and R (p×p).
pub type NoiseCov<'a> = Option<(&'a Mat, &'a Mat)>;

/// The channel labels of a class.
pub fn channel_labels(channels: Channels, model: &Model, ff: &Mat) -> Vec<String> {
    match channels {
        Channels::Actuator => (1..=model.l()).map(|i| format!("u{i}")).collect(),
        Channels::Sensor => (1..=model.p()).map(|j| format!("y{j}")).collect(),
        Channels::Component => (1..=ff.ncols()).map(|j| format!("f{j}")).collect(),
    }
}

/// The channels a bank watches: (indices in the class, labels) — every channel of the class, or
/// its `channels = […]` subset.
pub fn monitored(spec: &DiagnoserSpec, model: &Model, ff: &Mat) -> (Vec<usize>, Vec<String>) {
    let all = channel_labels(spec.channels, model, ff);
    let ids: Vec<usize> = spec
        .subset
        .clone()
        .unwrap_or_else(|| (0..all.len()).collect());
    let labels = ids.iter().map(|&j| all[j].clone()).collect();
    (ids, labels)
}

/// What member i is blind to, in words: "blind to u2", "without y1", "on y3 alone".
pub fn role(spec: &DiagnoserSpec, labels: &[String], i: usize) -> String {
    let others: Vec<&str> = labels
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != i)
        .map(|(_, l)| l.as_str())
        .collect();
    match (spec.channels, spec.scheme) {
        (Channels::Sensor, Scheme::Generalized) => format!("every output but {}", labels[i]),
        (Channels::Sensor, Scheme::Dedicated) => format!("on {} alone", labels[i]),
        (_, Scheme::Generalized) => format!("blind to {} and the unknown inputs", labels[i]),
        (_, Scheme::Dedicated) => format!("blind to {} and the unknown inputs", others.join(", ")),
    }
}

/// Designs every member, computes the structure matrix and each member's threshold.
// one job: a bank's design: its members, then the structure, the DC structure and the thresholds,
// all from the same members.
pub fn design_bank(
    spec: &DiagnoserSpec,
    model: &Model,
    ff: &Mat,
    dt: f64,
    noise: NoiseCov,
) -> Result<Bank, BankError> {
    let (ids, labels) = monitored(spec, model, ff);
    let m = labels.len();
    if m < 2 {
        return Err(BankError {
            member: None,
            key: "faults",
            reason: format!(
                "a bank needs at least two {} channels to isolate between, it watches {m}",
                spec.channels.name()
            ),
        });
    }
    let columns: Option<Mat> = match spec.channels {
        Channels::Actuator => Some(model.b.clone()),
        Channels::Component => Some(ff.clone()),
        Channels::Sensor => None,
    };
    let dm = model.discretize(dt);
    let p = model.p();
    let mut members = Vec::with_capacity(m);
    for i in 0..m {
        // The watched channels member i must be blind to (indices in the class).
        let blind: Vec<usize> = match spec.scheme {
            Scheme::Generalized => vec![ids[i]],
            Scheme::Dedicated => ids.iter().copied().filter(|&j| j != ids[i]).collect(),
        };
        let (member_model, outputs) = match &columns {
            Some(cols) => {
                let mut e = Mat::zeros(model.n(), model.e.ncols() + blind.len());
                e.columns_mut(0, model.e.ncols()).copy_from(&model.e);
                for (k, &j) in blind.iter().enumerate() {
                    e.set_column(model.e.ncols() + k, &cols.column(j));
                }
                (Model { e, ..model.clone() }, (0..p).collect::<Vec<_>>())
            }
            None => {
                let outputs: Vec<usize> = (0..p).filter(|j| !blind.contains(j)).collect();
                let c = model.c.select_rows(&outputs);
                let d = model.d.select_rows(&outputs);
                (
                    Model {
                        c,
                        d,
                        ..model.clone()
                    },
                    outputs,
                )
            }
        };
        let fail = |key: &'static str, reason: String| BankError {
            member: Some(i),
            key,
            reason,
        };
        let observer_spec = match &spec.member {
            MemberKind::ChenPatton { poles, placement } => Spec::ChenPatton {
                gain: Gain::place(poles.clone(), *placement),
            },
            MemberKind::Luenberger { poles, placement } => Spec::Luenberger {
                gain: Gain::place(poles.clone(), *placement),
            },
            MemberKind::Kalman => {
                let (qd, r) = noise
                    .ok_or_else(|| fail("observer", "a kalman member needs [noise]".into()))?;
                Spec::Kalman {
                    qd: qd.clone(),
                    r: r.select_rows(&outputs).select_columns(&outputs),
                }
            }
        };
        let mut designed = design(&member_model, &observer_spec, dt).map_err(|e| {
            let key = if e.condition.ends_with("poles") || e.condition.ends_with("pole placement") {
                "poles"
            } else {
                ""
            };
            fail(
                key,
                format!("{}: {} does not hold: {}", e.kind, e.condition, e.detail),
            )
        })?;
        widen(&mut designed, &outputs, p);
        members.push(Member {
            name: format!("{}-{}", spec.name, i + 1),
            outputs,
            blind,
            designed,
            covariance: None,
            threshold: 0.0,
            dof: 0,
            glr: None,
        });
    }
    // The structure, from the designs: residual i against a fault on watched channel j.
    let inputs: Vec<FaultInput> = ids
        .iter()
        .map(|&j| match &columns {
            Some(cols) => {
                let (_, g) = lti::discretize::zoh(&model.a, &cols.columns(j, 1).into_owned(), dt);
                FaultInput::State(DVector::from_column_slice(g.as_slice()))
            }
            None => FaultInput::Output(j),
        })
        .collect();
    let structure: Vec<Vec<u8>> = members
        .iter()
        .map(|mb| {
            inputs
                .iter()
                .map(|inp| u8::from(reacts(&dm.a, &dm.c, &mb.designed.runtime, &mb.outputs, inp)))
                .collect()
        })
        .collect();
    check_structure(spec, &structure, &labels)?;
    // Under a constant fault: which residuals stay away from zero.
    let steady: Option<Vec<Vec<u8>>> = members
        .iter()
        .map(|mb| {
            SteadyState::new(&dm.a, &dm.c, &mb.designed.runtime, &mb.outputs).map(|ss| {
                inputs
                    .iter()
                    .map(|inp| u8::from(ss.response(inp) > BLIND))
                    .collect()
            })
        })
        .collect();
    for (i, mb) in members.iter_mut().enumerate() {
        if let Some((qd, r)) = noise {
            let cov = residual_covariance(&dm.a, &dm.c, &mb.designed.runtime, &mb.outputs, qd, r)
                .map_err(|e| BankError {
                member: Some(i),
                key: "",
                reason: format!("residual covariance: {e}"),
            })?;
            mb.covariance = Some(cov);
        }
        let (threshold, dof) =
            threshold_for(spec, mb.covariance.as_ref()).map_err(|reason| BankError {
                member: Some(i),
                key: "false_alarm",
                reason,
            })?;
        mb.threshold = threshold;
        mb.dof = dof;
        if let Some(glr) = spec.glr {
            let noise = noise.ok_or_else(|| BankError {
                member: None,
                key: "glr",
                reason: "a GLR test whitens the residual by its noise: the scenario has no [noise]"
                    .into(),
            })?;
            // It tries the channels the residual reacts to: its row of the structure matrix.
            let tested = (0..inputs.len())
                .filter(|&j| structure[i][j] == 1)
                .collect();
            let design = GlrDesign::new(
                &dm.a,
                &dm.c,
                &mb.designed.runtime,
                &mb.outputs,
                &inputs,
                tested,
                noise,
                glr,
                dt,
            )
            .map_err(|reason| BankError {
                member: Some(i),
                key: "glr",
                reason,
            })?;
            mb.glr = Some(design);
        }
    }
    Ok(Bank {
        spec: spec.clone(),
        members,
        structure,
        steady,
        channels: labels,
        ids,
        inputs,
    })
}

/// Per watched channel whose constant fault only the transient reveals: "u1: residual 2 returns
/// to 0 in steady state; a constant u1 fault is isolable only during transients".
pub fn transient_only(bank: &Bank) -> Vec<String> {
    let Some(steady) = &bank.steady else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (j, label) in bank.channels.iter().enumerate() {
        let gone: Vec<String> = (0..bank.members.len())
            .filter(|&i| bank.structure[i][j] == 1 && steady[i][j] == 0)
            .map(|i| (i + 1).to_string())
            .collect();
        if gone.is_empty() {
            continue;
        }
        let column: Vec<u8> = steady.iter().map(|r| r[j]).collect();
        let consequence = if column.iter().all(|&v| v == 0) {
            "it is detected and isolated only during transients (a bias or step leaves no residual once they settle)".to_string()
        } else if let Some(k) = (0..bank.channels.len()).find(|&k| {
            k != j
                && bank
                    .structure
                    .iter()
                    .map(|r| r[k])
                    .eq(column.iter().copied())
        }) {
            format!(
                "in steady state its signature is {}'s: isolable only during transients",
                bank.channels[k]
            )
        } else {
            "in steady state its signature matches no channel (\"unknown\"): isolable only during transients".to_string()
        };
        let which = if gone.len() == 1 {
            format!("residual {} returns", gone[0])
        } else {
            format!("residuals {} return", gone.join(", "))
        };
        out.push(format!(
            "diagnoser '{}': {label} bias: {which} to 0 in steady state; {consequence}",
            bank.spec.name
        ));
    }
    out
}

/// K and Q of a member reading `outputs` widened to all p outputs (zero columns elsewhere).
fn widen(d: &mut Designed, outputs: &[usize], p: usize) {
    let widen_cols = |m: &lti::MatData| {
        let m: Mat = m.into();
        let mut w = Mat::zeros(m.nrows(), p);
        for (k, &j) in outputs.iter().enumerate() {
            w.set_column(j, &m.column(k));
        }
        lti::MatData::from(&w)
    };
    d.runtime.k = widen_cols(&d.runtime.k);
    d.runtime.q = widen_cols(&d.runtime.q);
}

/// The structure asked for must be the one computed, and must isolate: every channel seen by
/// some residual, no two channels with the same signature.
fn check_structure(
    spec: &DiagnoserSpec,
    computed: &[Vec<u8>],
    labels: &[String],
) -> Result<(), BankError> {
    let m = labels.len();
    if let Some(asked) = &spec.structure {
        if asked.len() != m || asked.iter().any(|r| r.len() != m) {
            return Err(BankError {
                member: None,
                key: "structure",
                reason: format!(
                    "must be {m}×{m} (one row per residual, one column per channel {})",
                    labels.join(", ")
                ),
            });
        }
        for (i, (a, c)) in asked.iter().zip(computed).enumerate() {
            for j in 0..m {
                if a[j] != c[j] {
                    let why = if a[j] == 0 {
                        format!(
                            "asks residual {} to ignore {} but member {} reacts to it (its design cannot be blind to it)",
                            i + 1,
                            labels[j],
                            i + 1
                        )
                    } else {
                        format!(
                            "asks residual {} to react to {} but member {} is blind to it",
                            i + 1,
                            labels[j],
                            i + 1
                        )
                    };
                    return Err(BankError {
                        member: None,
                        key: "structure",
                        reason: format!(
                            "{why}; the {} scheme gives {}",
                            spec.scheme.name(),
                            show(computed)
                        ),
                    });
                }
            }
        }
    }
    let column = |j: usize| computed.iter().map(|r| r[j]).collect::<Vec<u8>>();
    for j in 0..m {
        if column(j).iter().all(|&v| v == 0) {
            return Err(BankError {
                member: None,
                key: "structure",
                reason: format!(
                    "no residual reacts to {}: it cannot be detected ({})",
                    labels[j],
                    show(computed)
                ),
            });
        }
        for k in 0..j {
            if column(j) == column(k) {
                return Err(BankError {
                    member: None,
                    key: "structure",
                    reason: format!(
                        "{} and {} have the same signature: no decision can isolate them ({})",
                        labels[k],
                        labels[j],
                        show(computed)
                    ),
                });
            }
        }
    }
    Ok(())
}

/// "[[0, 1], [1, 0]]".
pub fn show(s: &[Vec<u8>]) -> String {
    let rows: Vec<String> = s
        .iter()
        .map(|r| {
            format!(
                "[{}]",
                r.iter().map(u8::to_string).collect::<Vec<_>>().join(", ")
            )
        })
        .collect();
    format!("[{}]", rows.join(", "))
}
