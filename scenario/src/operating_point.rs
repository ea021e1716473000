//! `[plant.operating_point]`: the point the design model is linearised at (x, u, w, y).
//!
//! The model is in deviations there; every plant exchanges absolute signals (see
//! [`lti::operating_point`]). Checked here: one finite value per state, known input, unknown
//! input and output; for the built-in linear plant, that the point is an equilibrium
//! (A x + B u + E w = 0, or Φ x + Γ_B u + Γ_E w = x) and that a given y is C x. The outputs
//! default to C x — for an FMU, a log or an external plant, give the outputs it has there when
//! they are not C x (an output with its own offset).

use lti::eig::sig;
use lti::{Mat, Model, OperatingPoint};

use super::SignalNames;
use super::raw::RawOperatingPoint;
use crate::check::{Bad, bad, finite};

/// Rounding of the equilibrium's sums leaves a few ε of their terms; a point off by more than
/// 1e-9 of them is not the plant's equilibrium (a typo, or a point of another model).
const EQUILIBRIUM_TOL: f64 = 1e-9;

/// The operating point, or `None` without the table. `builtin`: the built-in linear plant
/// simulates the model itself (the point must be its equilibrium).
pub(crate) fn operating_point(
    raw: &Option<RawOperatingPoint>,
    model: &Model,
    discrete: bool,
    builtin: bool,
    names: &SignalNames,
) -> Result<Option<OperatingPoint>, Bad> {
    let Some(r) = raw else { return Ok(None) };
    let (n, l, q, p) = (model.n(), model.b.ncols(), model.e.ncols(), model.c.nrows());
    let values =
        |key: &str, given: &Option<Vec<f64>>, count: usize, what: &str| -> Result<Vec<f64>, Bad> {
            let field = format!("plant.operating_point.{key}");
            let v = given.clone().unwrap_or_else(|| vec![0.0; count]);
            if v.len() != count {
                return Err(bad(
                    &field,
                    format!("has {} entries, the plant has {count} {what}", v.len()),
                ));
            }
            for (i, &x) in v.iter().enumerate() {
                finite(&format!("{field}[{}]", i + 1), x)?;
            }
            Ok(v)
        };
    let x = values("x", &r.x, n, "states")?;
    let u = values("u", &r.u, l, "known inputs (columns of B)")?;
    let w = values("w", &r.w, q, "unknown inputs (columns of E)")?;
    let cx: Vec<f64> = (&model.c * Mat::from_column_slice(n, 1, &x))
        .iter()
        .copied()
        .collect();
    let y = match &r.y {
        None => cx.clone(),
        Some(_) => values("y", &r.y, p, "outputs (rows of C)")?,
    };
    let op = OperatingPoint { x, u, w, y };
    if builtin {
        let (residual, scale) = op.equilibrium_residual(&model.a, &model.b, &model.e, discrete);
        let (i, worst) = residual
            .iter()
            .enumerate()
            .fold(
                (0, 0.0_f64),
                |m, (i, &v)| if v.abs() > m.1 { (i, v.abs()) } else { m },
            );
        if worst > EQUILIBRIUM_TOL * scale.max(f64::MIN_POSITIVE) {
            let formula = if discrete {
                "Φ x + Γ_B u + Γ_E w − x"
            } else {
                "A x + B u + E w"
            };
            return Err(bad(
                "plant.operating_point",
                format!(
                    "is not an equilibrium of the built-in plant: {formula} = {} at {} (row {}), more than {EQUILIBRIUM_TOL:e} of the terms ({scale:.3e}); give the x the inputs u, w hold",
                    sig(residual[i]),
                    names.state[i].name,
                    i + 1
                ),
            ));
        }
        let yscale = cx.iter().chain(&op.y).fold(0.0_f64, |m, v| m.max(v.abs()));
        if let Some(j) =
            (0..p).find(|&j| (op.y[j] - cx[j]).abs() > EQUILIBRIUM_TOL * yscale.max(1.0))
        {
            return Err(bad(
                "plant.operating_point.y",
                format!(
                    "{} = {} is not C x = {} at the point: the built-in plant's outputs there are C x (leave y out)",
                    names.output[j].name,
                    sig(op.y[j]),
                    sig(cx[j])
                ),
            ));
        }
    }
    Ok(Some(op))
}
