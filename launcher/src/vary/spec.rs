//! What a `--vary` names: one entry (or a whole matrix) of the built-in plant's A, B, C, E or D,
//! a parameter of an FMU plant or of a kit component plant, the point the plant operates at, its
//! initial state or its sampling interval; how it differs from the design model, and over which
//! values.
//!
//! ```text
//! A[2,3] *= 0.8..1.2:5              a scaling on a grid: 5 points from 0.8 to 1.2 (linspace)
//! A[2,3] *= [0.5, 1, 2]             a scaling on the listed values
//! A[2,3] = U(-3.5, -2.5)            a value drawn uniformly (`--points` draws, seeded)
//! B *= N(1, 0.05)                   every entry of B scaled by one normal draw
//! E[1,1] *= LogU(0.1, 10)           log-uniform: uniform in log10
//! plant.fmu.parameters.J *= 0.5..2:4   the FMU's start value of J scaled (as the scenario gives it)
//! plant.fmu.parameters.b = [0.05, 0.1, 0.2]   the FMU's parameter b set
//! plant.process.params.pole_mass *= U(0.8, 1.2)   a kit component plant's parameter scaled
//! plant.operating_point.u[1] *= 0.9..1.1:5   the plant run at another known input u_op
//! plant.operating_point.w[1] = [0, 0.01]      … or another unknown input w_op
//! x0[2] = N(0, 0.1)                 the simulated plant's initial state x0[2] set
//! dt *= [0.9, 1, 1.1]               the plant sampled at another interval than the design's
//! ```
//!
//! Indices are 1-based (row, column), as the papers and MATLAB write them. A scaling of 1 (or
//! a set value equal to the model's) is the nominal model; the nominal point is always run too.

use std::str::FromStr;

/// A matrix of the plant model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Matrix {
    A,
    B,
    C,
    E,
    D,
}

impl Matrix {
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Matrix::A => "A",
            Matrix::B => "B",
            Matrix::C => "C",
            Matrix::E => "E",
            Matrix::D => "D",
        }
    }
}

/// Scale the nominal value, or set it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    Scale,
    Set,
}

/// Where the values come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// These values.
    Grid(Vec<f64>),
    /// Uniform on [lo, hi].
    Uniform(f64, f64),
    /// Normal with mean and standard deviation.
    Normal(f64, f64),
    /// 10^U(log10 lo, log10 hi), lo, hi > 0.
    LogUniform(f64, f64),
}

/// What a `--vary` changes in the simulated plant.
#[derive(Debug, Clone, PartialEq)]
pub enum Place {
    /// An entry (0-based) of a matrix of the built-in plant, or the whole matrix.
    Matrix(Matrix, Option<(usize, usize)>),
    /// A parameter of the FMU plant (its start value, `plant.fmu.parameters.NAME`).
    FmuParameter(String),
    /// A parameter of an external-process plant (a kit component's `plant.process.params.NAME`).
    ProcessParameter(String),
    /// The point the simulated plant operates at (0-based entry of u_op or w_op): its known or
    /// unknown inputs moved by the difference from the design's point.
    OperatingPoint(PointSignal, usize),
    /// An entry (0-based) of the simulated plant's initial state x0.
    InitialState(usize),
    /// The plant's sampling interval dt (every designed part keeps the design's).
    SamplePeriod,
}

/// Which signal of the operating point a place names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointSignal {
    /// The known inputs u (columns of B).
    U,
    /// The unknown inputs w (columns of E).
    W,
}

/// The prefix of an FMU parameter's place.
pub const FMU_PARAMETERS: &str = "plant.fmu.parameters.";
/// The prefix of a process plant's parameter's place.
pub const PROCESS_PARAMS: &str = "plant.process.params.";
/// The prefix of the operating point's places.
pub const OPERATING_POINT: &str = "plant.operating_point.";

/// One `--vary`.
#[derive(Debug, Clone, PartialEq)]
pub struct Vary {
    /// As given (trimmed): the column name in the outputs.
    pub text: String,
    /// What it names, as written: "A[2,3]", "B", "plant.fmu.parameters.J".
    pub target: String,
    /// What it changes.
    pub place: Place,
    /// Scale or set.
    pub op: Op,
    /// Over which values.
    pub values: Values,
}

impl Vary {
    /// A value of it as text: "A[2,3] *= 1.2", "A[1,1] = -3".
    pub fn at(&self, x: f64) -> String {
        let op = match self.op {
            Op::Scale => "*=",
            Op::Set => "=",
        };
        format!("{} {op} {}", self.target, lti::eig::sig(x))
    }
}

/// Most values of one grid.
pub const MAX_GRID: usize = 10_000;

use lti::units::number;

/// `f(a, b)` → (a, b).
fn two(args: &str, whole: &str) -> Result<(f64, f64), String> {
    let (a, b) = args
        .split_once(',')
        .ok_or_else(|| format!("'{whole}': a distribution takes two numbers, e.g. U(0.8, 1.2)"))?;
    Ok((number(a, whole)?, number(b, whole)?))
}

fn values(v: &str, whole: &str) -> Result<Values, String> {
    let v = v.trim();
    if let Some(list) = v.strip_prefix('[').and_then(|x| x.strip_suffix(']')) {
        let vals = list
            .split(',')
            .map(|x| number(x, whole))
            .collect::<Result<Vec<_>, _>>()?;
        if vals.is_empty() || vals.len() > MAX_GRID {
            return Err(format!("'{whole}': a list holds 1 … {MAX_GRID} values"));
        }
        return Ok(Values::Grid(vals));
    }
    if let Some((range, count)) = v.split_once(':')
        && let Some((lo, hi)) = range.split_once("..")
    {
        let (lo, hi) = (number(lo, whole)?, number(hi, whole)?);
        let k: usize = count
            .trim()
            .parse()
            .map_err(|_| format!("'{whole}': lo..hi:N takes a whole number of points N"))?;
        if !(2..=MAX_GRID).contains(&k) {
            return Err(format!("'{whole}': lo..hi:N needs 2 … {MAX_GRID} points"));
        }
        // numpy's linspace: lo + i·(hi − lo)/(N − 1), the last point hi exactly.
        let step = (hi - lo) / (k - 1) as f64;
        let grid = (0..k)
            .map(|i| if i + 1 == k { hi } else { lo + i as f64 * step })
            .collect();
        return Ok(Values::Grid(grid));
    }
    let dist = |name: &str| {
        v.strip_prefix(name)
            .and_then(|x| x.trim_start().strip_prefix('('))
            .and_then(|x| x.strip_suffix(')'))
    };
    if let Some(args) = dist("LogU") {
        let (lo, hi) = two(args, whole)?;
        if !(lo > 0.0 && hi > lo) {
            return Err(format!("'{whole}': LogU(lo, hi) needs 0 < lo < hi"));
        }
        return Ok(Values::LogUniform(lo, hi));
    }
    if let Some(args) = dist("U") {
        let (lo, hi) = two(args, whole)?;
        if hi <= lo {
            return Err(format!("'{whole}': U(lo, hi) needs lo < hi"));
        }
        return Ok(Values::Uniform(lo, hi));
    }
    if let Some(args) = dist("N") {
        let (mu, sigma) = two(args, whole)?;
        if sigma <= 0.0 {
            return Err(format!("'{whole}': N(mean, sd) needs sd > 0"));
        }
        return Ok(Values::Normal(mu, sigma));
    }
    Err(format!(
        "'{whole}': the values are a list [a, b, …], a grid lo..hi:N, or U(lo, hi), N(mean, sd), LogU(lo, hi)"
    ))
}

/// The place of `dt`, `x0[i]` or `plant.operating_point.u[i]` / `w[i]` (`None` for another name).
fn scalar_place(name: &str, index: Option<&str>, whole: &str) -> Result<Option<Place>, String> {
    let vector = |what: &str| -> Result<usize, String> {
        let i = index
            .and_then(|i| i.strip_suffix(']'))
            .ok_or_else(|| format!("'{whole}': {what} names one entry, {name}[i], from 1"))?;
        i.trim()
            .parse::<usize>()
            .ok()
            .filter(|&k| k >= 1)
            .map(|k| k - 1)
            .ok_or_else(|| format!("'{whole}': entries count from 1"))
    };
    Ok(match name {
        "dt" if index.is_none() => Some(Place::SamplePeriod),
        "dt" => return Err(format!("'{whole}': dt is one number, it has no entries")),
        "x0" => Some(Place::InitialState(vector("x0")?)),
        _ => match name.strip_prefix(OPERATING_POINT) {
            Some("u") => Some(Place::OperatingPoint(PointSignal::U, vector("u_op")?)),
            Some("w") => Some(Place::OperatingPoint(PointSignal::W, vector("w_op")?)),
            Some(_) => {
                return Err(format!(
                    "'{whole}': the plant's operating point is varied as {OPERATING_POINT}u[i] (a known input) or {OPERATING_POINT}w[i] (an unknown input)"
                ));
            }
            None => None,
        },
    })
}

impl FromStr for Vary {
    type Err = String;

    fn from_str(whole: &str) -> Result<Self, Self::Err> {
        let text = whole.trim().to_string();
        let (target, op, rest) = if let Some((t, r)) = text.split_once("*=") {
            (t, Op::Scale, r)
        } else if let Some((t, r)) = text.split_once('=') {
            (t, Op::Set, r)
        } else {
            return Err(format!(
                "'{whole}': expected TARGET *= VALUES or TARGET = VALUES, e.g. 'A[2,3] *= 0.8..1.2:5'"
            ));
        };
        let target = target.trim().to_string();
        let target = target.as_str();
        let values = values(rest, whole)?;
        let vary = |place| Vary {
            target: target.to_string(),
            place,
            op,
            values: values.clone(),
            text: text.clone(),
        };
        for (prefix, what) in [
            (FMU_PARAMETERS, "FMU variable"),
            (PROCESS_PARAMS, "parameter"),
        ] {
            let Some(name) = target.strip_prefix(prefix) else {
                continue;
            };
            if name.is_empty() || name.contains(|c: char| c.is_whitespace() || c == '.') {
                return Err(format!(
                    "'{whole}': {prefix}NAME names one {what}, e.g. {prefix}J"
                ));
            }
            let place = if prefix == FMU_PARAMETERS {
                Place::FmuParameter(name.to_string())
            } else {
                Place::ProcessParameter(name.to_string())
            };
            return Ok(vary(place));
        }
        let (name, index) = match target.split_once('[') {
            Some((m, idx)) => (m.trim(), Some(idx)),
            None => (target, None),
        };
        if let Some(place) = scalar_place(name, index, whole)? {
            return Ok(vary(place));
        }
        let matrix = match name {
            "A" => Matrix::A,
            "B" => Matrix::B,
            "C" => Matrix::C,
            "E" => Matrix::E,
            "D" => Matrix::D,
            other => {
                return Err(format!(
                    "'{whole}': '{other}' is not one of the plant's matrices A, B, C, E, D, nor {FMU_PARAMETERS}NAME, {PROCESS_PARAMS}NAME, {OPERATING_POINT}u[i] or w[i], x0[i], dt"
                ));
            }
        };
        let entry = match index {
            None => None,
            Some(idx) => {
                let idx = idx.strip_suffix(']').ok_or_else(|| {
                    format!("'{whole}': an entry is written {name}[row,column], from 1")
                })?;
                let (i, j) = idx.split_once(',').ok_or_else(|| {
                    format!("'{whole}': an entry is written {name}[row,column], from 1")
                })?;
                let at = |x: &str| {
                    x.trim()
                        .parse::<usize>()
                        .ok()
                        .filter(|&k| k >= 1)
                        .ok_or_else(|| format!("'{whole}': rows and columns count from 1"))
                };
                Some((at(i)? - 1, at(j)? - 1))
            }
        };
        if op == Op::Set && entry.is_none() {
            return Err(format!(
                "'{whole}': a whole matrix can be scaled (*=), not set; set an entry, {name}[row,column] = …"
            ));
        }
        Ok(vary(Place::Matrix(matrix, entry)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_lists_and_distributions_parse_as_written() {
        let v: Vary = "A[2,3] *= 0.8..1.2:5".parse().unwrap();
        assert_eq!(
            (&v.place, v.op),
            (&Place::Matrix(Matrix::A, Some((1, 2))), Op::Scale)
        );
        let Values::Grid(g) = &v.values else {
            panic!("{v:?}")
        };
        assert_eq!(g.len(), 5);
        assert_eq!((g[0], g[4]), (0.8, 1.2));
        assert!((g[2] - 1.0).abs() < 1e-15);
        let v: Vary = "E *= [0.5, 1, 2]".parse().unwrap();
        assert_eq!(
            (v.place, v.values),
            (
                Place::Matrix(Matrix::E, None),
                Values::Grid(vec![0.5, 1.0, 2.0])
            )
        );
        let v: Vary = "plant.fmu.parameters.tau_c = [0, 0.01, 0.05]"
            .parse()
            .unwrap();
        assert_eq!(
            (v.place, v.op, v.target.as_str()),
            (
                Place::FmuParameter("tau_c".into()),
                Op::Set,
                "plant.fmu.parameters.tau_c"
            )
        );
        let v: Vary = "plant.process.params.pole_mass *= [0.8, 1.2]"
            .parse()
            .unwrap();
        assert_eq!(v.place, Place::ProcessParameter("pole_mass".into()));
        for (text, place) in [
            (
                "plant.operating_point.u[2] *= [0.9, 1.1]",
                Place::OperatingPoint(PointSignal::U, 1),
            ),
            (
                "plant.operating_point.w[1] = [0, 1]",
                Place::OperatingPoint(PointSignal::W, 0),
            ),
            ("x0[3] = [0, 1]", Place::InitialState(2)),
            ("dt *= [0.9, 1.1]", Place::SamplePeriod),
        ] {
            assert_eq!(text.parse::<Vary>().unwrap().place, place, "{text}");
        }
        let v: Vary = "A[1,1] = U(-3.5, -2.5)".parse().unwrap();
        assert_eq!((v.op, v.values), (Op::Set, Values::Uniform(-3.5, -2.5)));
        assert_eq!(
            "B *= N(1, 0.05)".parse::<Vary>().unwrap().values,
            Values::Normal(1.0, 0.05)
        );
        assert_eq!(
            "D[1,1] *= LogU(0.1, 10)".parse::<Vary>().unwrap().values,
            Values::LogUniform(0.1, 10.0)
        );
    }

    #[test]
    fn a_malformed_vary_names_what_is_wrong() {
        for (bad, says) in [
            ("A[0,1] *= [1]", "count from 1"),
            ("F[1,1] *= [1]", "not one of the plant's matrices"),
            ("A *= 1", "the values are"),
            ("A = [1, 2]", "a whole matrix can be scaled"),
            ("A[1,1] *= 1..2:1", "2 … 10000 points"),
            ("A[1,1] *= U(2, 1)", "lo < hi"),
            ("A[1,1] *= LogU(0, 1)", "0 < lo < hi"),
            ("A[1,1] *= N(1, 0)", "sd > 0"),
            ("A[1,1] *= [1, nan]", "not finite"),
            ("A[1,1]", "expected TARGET"),
            ("plant.fmu.parameters. *= [1]", "names one FMU variable"),
            ("plant.fmu.J *= [1]", "nor plant.fmu.parameters.NAME"),
            ("plant.process.params.a.b *= [1]", "names one parameter"),
            ("plant.operating_point.x[1] *= [1]", "u[i] (a known input)"),
            ("plant.operating_point.u *= [1]", "names one entry"),
            ("x0[0] = [1]", "entries count from 1"),
            ("dt[1] *= [1]", "no entries"),
        ] {
            let e = bad.parse::<Vary>().unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }
}
