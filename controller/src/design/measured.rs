//! Measured disturbances: known inputs the controller does not command (`[controller]
//! measured_disturbances`, MATLAB's "MD" inputs beside the manipulated "MV" ones), such as the
//! outdoor temperature of a building. They keep their `[[input]]` signal, absolute, and the
//! observers see them as every known input.
//!
//! With the inputs split into commanded (c) and measured (m) columns, Γ_B = [Γ_c, Γ_m], the
//! feedback is designed on (Φ, Γ_c) alone — l_c = l − l_m inputs, l_c tracked outputs, l_c
//! integrators, R l_c×l_c — and the controller's u then holds
//!
//! ```text
//! u_c = N_c r_c − G_c x̂ (− G_ξ ξ − M_c ŵ),      u_m = r_m,
//! ```
//!
//! i.e. G and N embedded in l rows: G's measured rows 0, N's the unit rows e_mᵀ. At an
//! operating point r_m is absolute and its offset 0 ([`super::FeedbackDesign::offset_at`]).
//! What u_m does to the state stays in the loop as a disturbance the feedback rejects (and the
//! integrators remove at DC).

use lti::{Discrete, Mat, Model};

/// The commanded inputs (0-based, ascending): every input of `l` not in `measured`.
pub fn commanded(l: usize, measured: &[usize]) -> Vec<usize> {
    (0..l).filter(|j| !measured.contains(j)).collect()
}

/// The columns `keep` of `b`.
fn columns(b: &Mat, keep: &[usize]) -> Mat {
    Mat::from_fn(b.nrows(), keep.len(), |i, j| b[(i, keep[j])])
}

/// The sampled plant with only the commanded inputs: Γ_c in place of Γ_B.
pub fn sampled(dm: &Discrete, keep: &[usize]) -> Discrete {
    Discrete {
        b: columns(&dm.b, keep),
        ..dm.clone()
    }
}

/// The continuous plant with only the commanded inputs: B_c in place of B.
pub fn continuous(m: &Model, keep: &[usize]) -> Model {
    Model {
        b: columns(&m.b, keep),
        ..m.clone()
    }
}

/// `x` (l_c rows, one per commanded input) as l rows: row `keep[i]` is x's row i, the measured
/// rows 0.
pub fn rows(x: &Mat, l: usize, keep: &[usize]) -> Mat {
    let mut out = Mat::zeros(l, x.ncols());
    for (i, &j) in keep.iter().enumerate() {
        out.row_mut(j).copy_from(&x.row(i));
    }
    out
}

/// N_c (l_c×l_c) as the l×l prefilter: u_c = N_c r_c, u_m = r_m.
pub fn prefilter(n_c: &Mat, l: usize, keep: &[usize]) -> Mat {
    let mut out = Mat::zeros(l, l);
    for (i, &ji) in keep.iter().enumerate() {
        for (k, &jk) in keep.iter().enumerate() {
            out[(ji, jk)] = n_c[(i, k)];
        }
    }
    for j in 0..l {
        if !keep.contains(&j) {
            out[(j, j)] = 1.0;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_rows_and_prefilter_pass_measured_inputs_through() {
        let keep = commanded(3, &[1]);
        assert_eq!(keep, vec![0, 2]);
        let g = Mat::from_row_slice(2, 2, &[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(
            rows(&g, 3, &keep),
            Mat::from_row_slice(3, 2, &[1.0, 2.0, 0.0, 0.0, 3.0, 4.0])
        );
        let n = prefilter(&g, 3, &keep);
        assert_eq!(
            n,
            Mat::from_row_slice(3, 3, &[1.0, 0.0, 2.0, 0.0, 1.0, 0.0, 3.0, 0.0, 4.0])
        );
    }
}
