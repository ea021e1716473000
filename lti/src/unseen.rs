//! Modes no sensor sees, found by the PBH test where they matter: the eigenvalues of A on or
//! outside the stability boundary, each cluster tested at its mean.
//!
//! A mode λ of (A, C) is unobservable iff [λI − A; C] has a null vector v (PBH), and v is then the
//! mode's eigenvector: its largest entries name the states that carry it. The staircase form
//! answers the same question for every mode at once, but on large models its rank decisions
//! accumulate over up to n stages; IEEE 39 (160 states) and WECC (569) have stabiliser filter
//! states with zero rows in A — modes at s = 0, z = 1, of multiplicity 4 and 3, that no sensor
//! sees — and the staircase passed them, leaving the Riccati iteration to fail ("did not
//! converge"). The PBH test at those few eigenvalues is decisive (σ_min/‖[A; C]‖ ~ 1e-16 there,
//! ≥ 1e-9 for the observable ones).
//!
//! Each eigenvalue is tested on its own, not at a cluster's mean: at dt = 1 ms dozens of distinct
//! slow modes sit within 1e-3 of z = 1 (IEEE 39: 0.9990 … 1.0011), and a mean over them is no
//! mode at all.

use nalgebra::DMatrix;

use crate::dare::one_norm;
use crate::eig::{C64, eigenvalues};
use crate::error::Result;
use crate::linalg::svd::Svd;

/// Modes found unseen within this (relative to max(1, |λ|)) of one another are reported as one,
/// with their count as its multiplicity.
pub const CLUSTER: f64 = 1e-6;

/// σ_min([λI − A; C]) ≤ this · max(‖A‖₁, ‖C‖₁, 1): λ is a mode no sensor sees.
pub const PBH_TOL: f64 = 1e-12;

/// A mode of (A, C) that no output sees.
#[derive(Debug, Clone, PartialEq)]
pub struct Unseen {
    /// The mode.
    pub value: C64,
    /// How many computed eigenvalues it holds.
    pub multiplicity: usize,
    /// The states that carry it, largest |vᵢ| first (0-based), with |vᵢ|: those within 1e-3 of the
    /// largest, at most eight.
    pub states: Vec<(usize, f64)>,
}

/// The modes of (A, C) with `concerns(λ)` (on or outside the stability boundary) that no row of C
/// sees, each computed eigenvalue tested on its own: one that is a defective mode's, spread by
/// ~(ε‖A‖)^{1/k}, still leaves σ_min ~ spread^k, far below [`PBH_TOL`]. Found modes within
/// [`CLUSTER`] of one another are one; conjugate pairs are reported once (Im ≥ 0).
pub fn unseen_modes(
    a: &DMatrix<f64>,
    c: &DMatrix<f64>,
    concerns: impl Fn(C64) -> bool,
) -> Result<Vec<Unseen>> {
    let n = a.nrows();
    let ev = eigenvalues(a)?;
    let scale = one_norm(a).max(one_norm(c)).max(1.0);
    let p = c.nrows();
    let mut out: Vec<Unseen> = Vec::new();
    for &z in ev.iter().filter(|&&z| concerns(z) && z.im >= 0.0) {
        if let Some(m) = out
            .iter_mut()
            .find(|m| (m.value - z).norm() <= CLUSTER * z.norm().max(1.0))
        {
            m.multiplicity += 1;
            continue;
        }
        // [λI − A; C] as a real matrix: itself for real λ, else [[Re, −Im], [Im, Re]] (2n columns).
        let (m, cols) = if z.im == 0.0 {
            let mut m = DMatrix::zeros(n + p, n);
            m.rows_mut(0, n)
                .copy_from(&(DMatrix::identity(n, n) * z.re - a));
            m.rows_mut(n, p).copy_from(c);
            (m, n)
        } else {
            let mut m = DMatrix::zeros(2 * (n + p), 2 * n);
            let re = DMatrix::identity(n, n) * z.re - a;
            let im = DMatrix::identity(n, n) * z.im;
            m.view_mut((0, 0), (n, n)).copy_from(&re);
            m.view_mut((0, n), (n, n)).copy_from(&(-&im));
            m.view_mut((n, 0), (p, n)).copy_from(c);
            m.view_mut((n + p, 0), (n, n)).copy_from(&im);
            m.view_mut((n + p, n), (n, n)).copy_from(&re);
            m.view_mut((2 * n + p, n), (p, n)).copy_from(c);
            (m, 2 * n)
        };
        let Some(svd) = Svd::new(&m) else { continue };
        let smin = svd.s.get(cols - 1).copied().unwrap_or(0.0);
        if smin > PBH_TOL * scale {
            continue;
        }
        // The null vector: the last right singular vector (for complex λ, Re and Im stacked).
        let v = svd.v.column(cols - 1);
        let weight: Vec<f64> = (0..n)
            .map(|i| {
                if cols == n {
                    v[i].abs()
                } else {
                    v[i].hypot(v[n + i])
                }
            })
            .collect();
        let top = weight.iter().copied().fold(0.0, f64::max);
        let mut states: Vec<(usize, f64)> = weight
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, w)| *w >= 1e-3 * top)
            .collect();
        states.sort_by(|x, y| y.1.total_cmp(&x.1));
        states.truncate(8);
        out.push(Unseen {
            value: z,
            multiplicity: 1,
            states,
        });
    }
    // The multiplicity counts every computed eigenvalue of the mode, also those that rounding put
    // just inside the boundary (a multiple mode at z = 1 comes out as 1 ± a few ε).
    for m in &mut out {
        m.multiplicity = ev
            .iter()
            .filter(|w| (**w - m.value).norm() <= CLUSTER * m.value.norm().max(1.0))
            .count();
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_state_no_sensor_sees_is_named_with_its_mode() {
        // x3 integrates nothing and is not measured: a mode at 0 carried by x3 alone.
        let a = DMatrix::from_row_slice(3, 3, &[-1.0, 1.0, 0.0, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0]);
        let c = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, 0.0]);
        let unseen = unseen_modes(&a, &c, |z| z.re >= -1e-9).unwrap();
        assert_eq!(unseen.len(), 1);
        assert_eq!(unseen[0].value, C64::new(0.0, 0.0));
        assert_eq!(unseen[0].states[0].0, 2);
        // Measured, it is seen.
        let c = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert!(unseen_modes(&a, &c, |z| z.re >= -1e-9).unwrap().is_empty());
    }

    #[test]
    fn a_defective_unseen_mode_is_found_once_with_its_multiplicity() {
        // A Jordan block of size 4 at 1 that no sensor sees, beside a measured stable state.
        let mut a = DMatrix::<f64>::identity(5, 5);
        for i in 0..3 {
            a[(i, i + 1)] = 1.0;
        }
        a[(4, 4)] = 0.5;
        let c = DMatrix::from_row_slice(1, 5, &[0.0, 0.0, 0.0, 0.0, 1.0]);
        let unseen = unseen_modes(&a, &c, |z| z.norm() >= 1.0 - 1e-9).unwrap();
        assert_eq!(unseen.len(), 1, "{unseen:?}");
        assert!((unseen[0].value - C64::new(1.0, 0.0)).norm() < 1e-9);
        assert_eq!(unseen[0].multiplicity, 4);
    }
}
