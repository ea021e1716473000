//! The toolbox every section of the validator uses: a located problem ([`Bad`]), finite
//! numbers, matrices, poles, names, one-of-a-list keys with a "did you mean".

use lti::place::Method;
use lti::{Mat, PoleSpec, Poles};

use crate::raw::{RawPole, Rows};
use crate::untrusted::quoted;

/// A problem with one field, before the location is looked up: the field's path (such as
/// `plant.A` or `observer[1].poles`) and the reason.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Bad {
    pub field: String,
    pub reason: String,
}

pub(crate) fn bad(field: impl Into<String>, reason: impl Into<String>) -> Bad {
    Bad {
        field: field.into(),
        reason: reason.into(),
    }
}

/// The value of an enum-like key: `value` must be one of the names of `choices`; otherwise
/// "\"x\" is not a <what> (a, b, c)" with the closest name suggested.
pub(crate) fn one_of<T: Clone>(
    field: impl Into<String>,
    what: &str,
    value: &str,
    choices: &[(&str, T)],
) -> Result<T, Bad> {
    if let Some((_, t)) = choices.iter().find(|(name, _)| *name == value) {
        return Ok(t.clone());
    }
    let names: Vec<&str> = choices.iter().map(|(name, _)| *name).collect();
    Err(bad(
        field,
        format!(
            "{} is not a {what} ({}){}",
            quoted(value),
            names.join(", "),
            crate::suggest::did_you_mean(value, names.iter().copied())
        ),
    ))
}

pub(crate) fn finite(field: &str, v: f64) -> Result<f64, Bad> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(bad(field, format!("{v} is not a finite number")))
    }
}

/// A false-alarm probability per sample: finite, in (0, 0.5).
pub(crate) fn false_alarm(field: &str, a: f64) -> Result<f64, Bad> {
    let a = finite(field, a)?;
    if a > 0.0 && a < 0.5 {
        Ok(a)
    } else {
        Err(bad(
            field,
            format!("{a}: a false-alarm probability per sample is between 0 and 0.5"),
        ))
    }
}

/// A matrix from rows: not empty, not ragged, finite, and of the required shape.
pub(crate) fn matrix(
    field: &str,
    rows: &Rows,
    shape: (Option<usize>, Option<usize>),
    why: &str,
) -> Result<Mat, Bad> {
    let rows = match rows {
        Rows::Inline(rows) => rows,
        Rows::File(name) => {
            return Err(bad(
                field,
                format!("{}: a matrix file is read before validation", quoted(name)),
            ));
        }
    };
    if rows.is_empty() || rows.iter().all(|r| r.is_empty()) {
        return Err(bad(field, "must not be empty"));
    }
    let cols = rows[0].len();
    for (i, r) in rows.iter().enumerate() {
        if r.len() != cols {
            return Err(bad(
                format!("{field}[{}]", i + 1),
                format!(
                    "ragged: row {} has {} entries, row 1 has {cols}",
                    i + 1,
                    r.len()
                ),
            ));
        }
        for (j, &v) in r.iter().enumerate() {
            if !v.is_finite() {
                return Err(bad(
                    format!("{field}[{}]", i + 1),
                    format!("entry {} is {v}, not a finite number", j + 1),
                ));
            }
        }
    }
    let (want_r, want_c) = shape;
    if want_r.is_some_and(|r| r != rows.len()) || want_c.is_some_and(|c| c != cols) {
        let show = |o: Option<usize>| o.map_or("·".to_string(), |v| v.to_string());
        return Err(bad(
            field,
            format!(
                "is {}×{cols}, must be {}×{} ({why})",
                rows.len(),
                show(want_r),
                show(want_c)
            ),
        ));
    }
    Ok(Mat::from_fn(rows.len(), cols, |i, j| rows[i][j]))
}

pub(crate) fn poles(field: &str, raw: &[RawPole]) -> Result<Poles, Bad> {
    let mut specs = Vec::new();
    for (i, p) in raw.iter().enumerate() {
        let f = format!("{field}[{}]", i + 1);
        match p {
            RawPole::Real(x) => specs.push(PoleSpec::Real(finite(&f, *x)?)),
            RawPole::Pair(v) if v.len() == 2 => {
                let (re, im) = (finite(&f, v[0])?, finite(&f, v[1])?);
                if im != 0.0 && specs.contains(&PoleSpec::Pair(re, -im)) {
                    return Err(bad(
                        f,
                        format!(
                            "[{re}, {im}] is the conjugate of [{re}, {}], which already implies it",
                            -im
                        ),
                    ));
                }
                specs.push(PoleSpec::Pair(re, im));
            }
            RawPole::Pair(v) => {
                return Err(bad(
                    f,
                    format!(
                        "a complex pair is written [re, im]; this has {} numbers",
                        v.len()
                    ),
                ));
            }
        }
    }
    // An empty list is valid: a design whose pair has only fixed modes takes no free poles, and
    // the design itself says how many it needs when the count is wrong.
    Poles::new(specs).map_err(|e| bad(field, e.to_string()))
}

pub(crate) fn placement(field: &str, p: &Option<String>) -> Result<Method, Bad> {
    // "yt" (Yang–Tits) is the robust method's other name, accepted and not listed.
    match p.as_deref() {
        None | Some("yt") => Ok(Method::YangTits),
        Some(v) => one_of(
            field,
            "placement",
            v,
            &[
                ("robust", Method::YangTits),
                ("knv0", Method::Knv0),
                ("matlab", Method::Matlab),
                ("ackermann", Method::Ackermann),
            ],
        ),
    }
}

/// Longest scenario or observer name, in characters. Names become file names (the recording,
/// the summary, PNGs, CSVs, component configurations) and iceoryx2 service names: this keeps
/// every one of them far below the file system's 255-byte limit, checked before anything is
/// created.
pub const MAX_NAME_CHARS: usize = 64;

/// A name: 1 to [`MAX_NAME_CHARS`] ASCII letters, digits, '-' or '_'.
pub(crate) fn check_name(field: &str, name: &str, why: &str) -> Result<(), Bad> {
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        return Err(bad(
            field,
            format!(
                "{} must be non-empty letters, digits, '-' or '_' ({why})",
                quoted(name)
            ),
        ));
    }
    if name.len() > MAX_NAME_CHARS {
        return Err(bad(
            field,
            format!(
                "{} is {} characters long, at most {MAX_NAME_CHARS} are allowed ({why})",
                quoted(name),
                name.len()
            ),
        ));
    }
    Ok(())
}

/// A weight or covariance that must be symmetric and (semi-)definite, by the rule the Riccati
/// and Van Loan code applies to its arguments ([`lti::dare::symmetric`]).
pub(crate) fn definite(
    field: &str,
    symbol: &str,
    m: &Mat,
    how: lti::dare::Definite,
) -> Result<Mat, Bad> {
    lti::dare::symmetric(symbol, m, how).map_err(|e| {
        let reason = match e {
            lti::LtiError::InvalidInput(r) => r,
            other => other.to_string(),
        };
        bad(field, reason)
    })
}
