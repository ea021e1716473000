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
//! A defective eigenvalue of multiplicity k comes out of the Schur form as k values spread by
//! ~ε^{1/k} (1e-4 for k = 4) around it; their mean is accurate to ~ε‖A‖, so the test is made
//! at the mean of each cluster of eigenvalues within [`CLUSTER`] of one another.

use nalgebra::DMatrix;

use crate::eig::{C64, eigenvalues};
use crate::error::Result;
use crate::linalg::svd::Svd;

/// Eigenvalues within this (relative to max(1, |λ|)) of one another form one cluster.
pub const CLUSTER: f64 = 1e-3;

/// σ_min([λI − A; C]) ≤ this · max(‖A‖₁, ‖C‖₁, 1): λ is a mode no sensor sees.
pub const PBH_TOL: f64 = 1e-12;

/// A mode of (A, C) that no output sees.
#[derive(Debug, Clone, PartialEq)]
pub struct Unseen {
    /// The mode (the mean of its cluster).
    pub value: C64,
    /// How many computed eigenvalues the cluster holds.
    pub multiplicity: usize,
    /// The states that carry it, largest |vᵢ| first (0-based), with |vᵢ|: those within 1e-3 of the
    /// largest, at most eight.
    pub states: Vec<(usize, f64)>,
}

/// The modes of (A, C) with `concerns(λ)` (on or outside the stability boundary) that no row of C
/// sees. One per cluster, sorted as the eigenvalues are; conjugate pairs reported once (Im ≥ 0).
/// `near(λ)` is a looser `concerns`, wide enough to hold the whole spread of a defective mode's
/// computed values (|z| ≥ 1 − 1e-3, Re s ≥ −1e-3·max(1, |s|)): the clusters are gathered from it,
/// and `concerns` is asked of their means.
pub fn unseen_modes(
    a: &DMatrix<f64>,
    c: &DMatrix<f64>,
    near: impl Fn(C64) -> bool,
    concerns: impl Fn(C64) -> bool,
) -> Result<Vec<Unseen>> {
    let n = a.nrows();
    let ev = eigenvalues(a)?;
    let candidates: Vec<C64> = ev
        .iter()
        .copied()
        .filter(|&z| near(z) && z.im >= -CLUSTER * z.norm().max(1.0))
        .collect();
    let mut clusters: Vec<Vec<C64>> = Vec::new();
    for z in candidates {
        match clusters
            .iter_mut()
            .find(|cl| (cl[0] - z).norm() <= CLUSTER * z.norm().max(1.0))
        {
            Some(cl) => cl.push(z),
            None => clusters.push(vec![z]),
        }
    }
    let norm1 = |m: &DMatrix<f64>| {
        (0..m.ncols())
            .map(|j| m.column(j).iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let scale = norm1(a).max(norm1(c)).max(1.0);
    let p = c.nrows();
    let mut out = Vec::new();
    for cl in clusters {
        let mut mean = cl.iter().sum::<C64>() / cl.len() as f64;
        if mean.im.abs() <= CLUSTER * mean.norm().max(1.0) {
            mean.im = 0.0; // a real mode's cluster (its spread holds conjugate pairs)
        }
        if !concerns(mean) {
            continue;
        }
        // The multiplicity counts the conjugates too: the cluster was gathered from Im ≥ 0.
        let multiplicity = ev
            .iter()
            .filter(|z| (**z - mean).norm() <= CLUSTER * mean.norm().max(1.0))
            .count();
        // [λI − A; C] as a real matrix: itself for real λ, else [[Re, −Im], [Im, Re]] (2n columns).
        let (m, cols) = if mean.im == 0.0 {
            let mut m = DMatrix::zeros(n + p, n);
            m.rows_mut(0, n)
                .copy_from(&(DMatrix::identity(n, n) * mean.re - a));
            m.rows_mut(n, p).copy_from(c);
            (m, n)
        } else {
            let mut m = DMatrix::zeros(2 * (n + p), 2 * n);
            let re = DMatrix::identity(n, n) * mean.re - a;
            let im = DMatrix::identity(n, n) * mean.im;
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
            value: mean,
            multiplicity,
            states,
        });
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
        let unseen = unseen_modes(&a, &c, |z| z.re >= -1e-3, |z| z.re >= -1e-9).unwrap();
        assert_eq!(unseen.len(), 1);
        assert_eq!(unseen[0].value, C64::new(0.0, 0.0));
        assert_eq!(unseen[0].states[0].0, 2);
        // Measured, it is seen.
        let c = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert!(
            unseen_modes(&a, &c, |z| z.re >= -1e-3, |z| z.re >= -1e-9)
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn a_defective_unseen_mode_is_found_at_its_cluster_mean() {
        // A Jordan block of size 4 at 1 that no sensor sees, beside a measured stable state.
        let mut a = DMatrix::<f64>::identity(5, 5);
        for i in 0..3 {
            a[(i, i + 1)] = 1.0;
        }
        a[(4, 4)] = 0.5;
        let c = DMatrix::from_row_slice(1, 5, &[0.0, 0.0, 0.0, 0.0, 1.0]);
        let unseen = unseen_modes(
            &a,
            &c,
            |z| z.norm() >= 1.0 - 1e-3,
            |z| z.norm() >= 1.0 - 1e-9,
        )
        .unwrap();
        assert_eq!(unseen.len(), 1, "{unseen:?}");
        assert!((unseen[0].value - C64::new(1.0, 0.0)).norm() < 1e-9);
        assert_eq!(unseen[0].multiplicity, 4);
    }
}
