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
use crate::linalg::svd::{Svd, singular_values};

/// Modes found unseen within this (relative to max(1, |λ|)) of one another are reported as one,
/// with their count as its multiplicity.
pub const CLUSTER: f64 = 1e-6;

/// σ_min([λI − A; C]) ≤ this · max(‖A‖₁, ‖C‖₁, 1): λ is a mode no sensor sees.
pub const PBH_TOL: f64 = 1e-12;

/// From this order on, an isolated eigenvalue is first screened by its eigenvector (inverse
/// iteration, [`seen_by_its_eigenvector`]) before the PBH SVD: at n = 1000 the SVDs of the
/// 2(n + p) × 2n embeddings took two thirds of a Chen–Patton design with `gain = "lqe"` (70 of
/// 106 s for four unstable pairs of TΦ), an LU solve a fraction of one. Below it the SVD alone.
pub const SCREEN_FROM: usize = 64;

/// Whether λ is a simple mode that C sees, shown by its eigenvector: λ is isolated (no other
/// computed eigenvalue within [`CLUSTER`]·max(1, |λ|): a multiple eigenvalue, semisimple or
/// defective, comes out of the QR iteration as a cluster far tighter than that — at dt = 1 ms
/// distinct slow modes sit 10⁻⁵ apart near z = 1, a hundred within 10⁻³), inverse iteration gives a vector v with
/// ‖(A − λI)v‖ ≤ 10⁻¹⁰‖A‖‖v‖ (an eigenvector to rounding), and ‖Cv‖∞ ≥ 10⁻⁶·max(‖C‖₁, 1)‖v‖∞.
/// For a simple eigenvalue the PBH null vector could only be v, so C v ≠ 0 is decisive; a
/// clustered or multiple λ, or any doubt, is left to the PBH test (false is "not shown").
fn seen_by_its_eigenvector(a: &DMatrix<f64>, c: &DMatrix<f64>, z: C64, ev: &[C64]) -> bool {
    let near = ev
        .iter()
        .filter(|w| (**w - z).norm() <= CLUSTER * z.norm().max(1.0))
        .count();
    if near > 1 {
        return false;
    }
    let Some((v, residual)) = crate::linalg::evd::inverse_iteration(a, z) else {
        return false;
    };
    // (A NaN residual is no eigenvector either.)
    if residual.is_nan() || residual > 1e-10 {
        return false;
    }
    let cv = (0..c.nrows())
        .map(|i| {
            v.iter()
                .enumerate()
                .map(|(j, x)| x * c[(i, j)])
                .sum::<C64>()
                .norm()
        })
        .fold(0.0, f64::max);
    cv >= 1e-6 * one_norm(c).max(1.0)
}

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
        if n >= SCREEN_FROM && seen_by_its_eigenvector(a, c, z, &ev) {
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
        // σ_min alone first: nearly every mode tested is seen, and its vectors are not needed
        // (a large model's unstable pair has dozens of such modes; each full SVD of the
        // 2(n + p) × 2n embedding cost seconds at n = 1000).
        // (NaN for a failed iteration: not above the tolerance, so the full SVD decides.)
        let s = singular_values(&m);
        if s.get(cols - 1).copied().unwrap_or(0.0) > PBH_TOL * scale {
            continue;
        }
        let Some(svd) = Svd::new(&m) else { continue };
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

    /// Above [`SCREEN_FROM`] states the eigenvector screen passes the seen unstable modes and
    /// leaves the unseen ones — simple, a complex pair, and a semisimple double mode of which
    /// one copy is measured — to the PBH test, which still finds them.
    #[test]
    fn the_eigenvector_screen_passes_seen_modes_and_never_an_unseen_one() {
        let n = 80;
        // Block diagonal: stable modes −1 … (n − 7) and, at the end, 0.7 (seen), 0.5 (unseen), a
        // pair 0.2 ± 0.9i (unseen), 0.3 twice (one copy seen, one not), 0.4 (seen); then a
        // well-conditioned similarity T = I + 0.3·(a fixed pattern)/n so no state is alone.
        let mut d = DMatrix::<f64>::zeros(n, n);
        for i in 0..n - 7 {
            d[(i, i)] = -1.0 - i as f64 * 0.1;
        }
        let k = n - 7;
        d[(k, k)] = 0.7;
        d[(k + 1, k + 1)] = 0.5;
        d[(k + 2, k + 2)] = 0.2;
        d[(k + 2, k + 3)] = 0.9;
        d[(k + 3, k + 2)] = -0.9;
        d[(k + 3, k + 3)] = 0.2;
        d[(k + 4, k + 4)] = 0.3;
        d[(k + 5, k + 5)] = 0.3;
        d[(k + 6, k + 6)] = 0.4;
        // C sees every stable state, 0.7, one copy of 0.3 and 0.4.
        let seen: Vec<usize> = (0..k).chain([k, k + 4, k + 6]).collect();
        let mut c0 = DMatrix::<f64>::zeros(seen.len(), n);
        for (r, &j) in seen.iter().enumerate() {
            c0[(r, j)] = 1.0;
        }
        let t = DMatrix::<f64>::from_fn(n, n, |i, j| {
            f64::from(i == j) + 0.3 * (((i * 7 + j * 13) % 11) as f64 - 5.0) / n as f64
        });
        let ti = t.clone().try_inverse().unwrap();
        let (a, c) = (&t * &d * &ti, &c0 * &ti);
        let unseen = unseen_modes(&a, &c, |z| z.re >= 0.0).unwrap();
        let mut values: Vec<(f64, f64, usize)> = unseen
            .iter()
            .map(|m| (m.value.re, m.value.im, m.multiplicity))
            .collect();
        values.sort_by(|x, y| x.0.total_cmp(&y.0));
        let round = |v: f64| (v * 1e6).round() / 1e6;
        let got: Vec<(f64, f64, usize)> = values
            .iter()
            .map(|&(r, i, m)| (round(r), round(i), m))
            .collect();
        assert_eq!(
            got,
            vec![(0.2, 0.9, 1), (0.3, 0.0, 2), (0.5, 0.0, 1)],
            "{unseen:?}"
        );
    }

    #[test]
    fn inverse_iteration_gives_the_eigenvector_of_a_simple_eigenvalue() {
        let a = DMatrix::from_row_slice(3, 3, &[2.0, 1.0, 0.0, 0.0, 3.0, 1.0, 0.0, 0.0, 5.0]);
        let lambda = C64::new(3.0, 0.0);
        let (v, residual) = crate::linalg::evd::inverse_iteration(&a, lambda).unwrap();
        assert!(residual < 1e-14, "{residual:e}");
        // (A − 3I)v = 0: v ∝ (1, 1, 0).
        assert!((v[0] - v[1]).norm() < 1e-14 && v[2].norm() < 1e-14, "{v:?}");
    }
}
