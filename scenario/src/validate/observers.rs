//! `[[observer]]`: names, kinds, each family's design keys and weights, the initial estimate;
//! a process observer's command; the bank members' entries; the cap on observer processes.

use std::collections::BTreeSet;

use lti::{Mat, Model, Poles};
use observer::Spec;
use observer::design::Path as HuiZakPath;
use observer::design::{Gain, Weights};

use super::process::process_spec;
use crate::check::{Bad, bad, check_name, definite, finite, matrix, one_of, placement, poles};
use crate::limits::MAX_OBSERVERS;
use crate::raw::{RawObserver, RawScenario};
use crate::untrusted::quoted;
use crate::{NoiseSpec, ObserverEntry};

/// The scenario's own observers, in order, and their names.
pub(super) fn observers(
    raw: &RawScenario,
    model: &Model,
    noise: Option<&NoiseSpec>,
) -> Result<(Vec<ObserverEntry>, BTreeSet<String>), Bad> {
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
                spec: Some(observer_spec(&f, o, model, noise)?),
                process: None,
                member: None,
                xhat0,
            }
        });
    }
    Ok((observers, seen))
}

/// Each bank member runs as an observer of its own, after the scenario's observers.
pub(super) fn bank_members(
    diagnosers: &[diagnosis::DiagnoserSpec],
    model: &Model,
    ff: &Mat,
    observers: &mut Vec<ObserverEntry>,
) {
    for (di, d) in diagnosers.iter().enumerate() {
        for j in 0..diagnosis::bank::monitored(d, model, ff).0.len() {
            observers.push(ObserverEntry {
                name: format!("{}-{}", d.name, j + 1),
                spec: None,
                process: None,
                member: Some((di, j)),
                xhat0: None,
            });
        }
    }
}

/// Observer kinds a scenario may name.
pub(super) const KINDS: [&str; 8] = [
    "luenberger",
    "chen-patton-uio",
    "das-ghosal",
    "das-ghosal-uio",
    "gi-full-order",
    "cumming",
    "hui-zak-uio",
    "kalman",
];

/// At most [`MAX_OBSERVERS`] observer processes (a bank's members share one,
/// [`crate::observer_processes`]): each subscribes to the plant's samples. The field named is
/// the `[[observer]]` or `[[diagnoser]]` that goes past the cap.
pub(super) fn observer_cap(
    own: usize,
    observers: &[ObserverEntry],
    remote: &std::collections::BTreeMap<String, crate::Remote>,
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

// one job: one `[[observer]]` validated field by field, one arm per kind.
pub(super) fn observer_spec(
    f: &str,
    o: &RawObserver,
    model: &Model,
    noise: Option<&crate::NoiseSpec>,
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
                None => HuiZakPath::Placement,
                Some(v) => one_of(
                    format!("{f}.path"),
                    "design path",
                    v,
                    &[
                        ("placement", HuiZakPath::Placement),
                        ("lmi", HuiZakPath::Lmi),
                    ],
                )?,
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
pub(super) fn initial_estimate(field: &str, x: &[f64], n: usize) -> Result<Vec<f64>, Bad> {
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
pub(super) fn lqe_weights(
    f: &str,
    o: &RawObserver,
    model: &Model,
    noise: Option<&crate::NoiseSpec>,
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
