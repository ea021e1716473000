//! Central differences of the one-sample map with Richardson's extrapolation (module docs of
//! [`super`]): column j from F(z ± h_j e_j) and F(z ± h_j/2 e_j).

use super::one_sample::OneSample;
use super::wire::Block;

/// ∛ε: the central difference's step relative to max(|z_j|, 1).
pub const RELATIVE_STEP: f64 = 6.06e-6;

/// The Jacobian of F = (x⁺, y₀) at z: rows x⁺ then y₀, columns z; and its error estimate.
pub struct Jacobian {
    pub value: Vec<Vec<f64>>,
    pub error: Vec<Vec<f64>>,
    pub steps: Vec<f64>,
}

/// The step of variable j at z_j.
pub fn step(zj: f64) -> f64 {
    RELATIVE_STEP * zj.abs().max(1.0)
}

fn stack(xy: (Vec<f64>, Vec<f64>)) -> Vec<f64> {
    xy.0.into_iter().chain(xy.1).collect()
}

/// The central difference of column j at step h.
pub fn column(f: &mut OneSample, z: &[f64], j: usize, h: f64) -> Result<Vec<f64>, String> {
    let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
    zp[j] += h;
    zm[j] -= h;
    // The step as represented: (z + h) − (z − h) may differ from 2h by rounding.
    let width = zp[j] - zm[j];
    let (fp, fm) = (stack(f.eval(&zp)?), stack(f.eval(&zm)?));
    Ok(fp.iter().zip(&fm).map(|(a, b)| (a - b) / width).collect())
}

/// The whole Jacobian, each column extrapolated from steps h_j and h_j / 2.
pub fn jacobian(f: &mut OneSample, z: &[f64]) -> Result<Jacobian, String> {
    let steps: Vec<f64> = z.iter().map(|&v| step(v)).collect();
    let mut cols = Vec::with_capacity(z.len());
    let mut errs = Vec::with_capacity(z.len());
    for (j, &h) in steps.iter().enumerate() {
        let d1 = column(f, z, j, h)?;
        let d2 = column(f, z, j, h / 2.0)?;
        cols.push(
            d2.iter()
                .zip(&d1)
                .map(|(b, a)| b + (b - a) / 3.0)
                .collect::<Vec<f64>>(),
        );
        errs.push(
            d2.iter()
                .zip(&d1)
                .map(|(b, a)| (b - a).abs() / 3.0)
                .collect::<Vec<f64>>(),
        );
    }
    let rows = cols.first().map_or(0, Vec::len);
    let t = |c: &Vec<Vec<f64>>| {
        (0..rows)
            .map(|i| c.iter().map(|col| col[i]).collect())
            .collect()
    };
    Ok(Jacobian {
        value: t(&cols),
        error: t(&errs),
        steps,
    })
}

/// Rows `r`, columns `c` of the Jacobian, with the block's largest error estimate.
pub fn block(d: &Jacobian, r: std::ops::Range<usize>, c: std::ops::Range<usize>) -> Block {
    let rows = d.value[r.clone()]
        .iter()
        .map(|row| row[c.clone()].to_vec())
        .collect();
    let error = d.error[r]
        .iter()
        .flat_map(|row| row[c.clone()].iter().copied())
        .fold(0.0, f64::max);
    Block { rows, error }
}
