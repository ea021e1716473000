//! Tits & Yang (1996), "Globally convergent algorithms for robust pole assignment by state
//! feedback", IEEE TAC 41(10) — the method behind scipy's `place_poles(method="YT")`, whose
//! pole order, visiting order and stopping rule this follows.
//!
//! Where KNV method 0 moves one eigenvector at a time, Tits–Yang moves two at once so as to
//! maximise |det X| over unit columns with the other columns fixed. Let [a b] be an orthonormal
//! basis of the complement of the other n − 2 columns.
//!
//! * Two real poles i, j: with xᵢ = 𝒮ᵢμ, xⱼ = 𝒮ⱼν, det X ∝ μᵀ Nᵢⱼ ν where
//!   Nᵢⱼ = 𝒮ᵢᵀ(abᵀ − baᵀ)𝒮ⱼ; the maximum over unit μ, ν is σ_max(Nᵢⱼ), at its top singular pair
//!   (paper §6.1).
//! * A complex pair (x, x̄): with x = 𝒮μ and u = √2(a + jb), det[Re x, Im x]-part ∝ μᴴ M μ,
//!   M = 𝒮ᴴ(uuᴴ − ūuᵀ)𝒮 Hermitian, maximised in modulus by the eigenvector of M whose
//!   eigenvalue is largest in modulus (paper §6.2).
//!
//! One sweep visits real pairs in the staggered order of the paper's Algorithm 1 (as scipy
//! implements it), with every complex pair updated between the stages.

use nalgebra::{DMatrix, DVector};

use super::eigenstructure::{Eigenstructure, abs_det};
use super::knv0::converged;
use crate::eig::C64;
use crate::householder::qr_q_columns;

/// Runs Tits–Yang sweeps from X until |det X| settles (scipy's rule), at most `max` sweeps.
/// The poles in `es` must be ordered real first, then complex pairs.
pub fn yang_tits(
    es: &Eigenstructure,
    mut x: DMatrix<C64>,
    rtol: f64,
    max: usize,
) -> (DMatrix<C64>, usize) {
    let n = x.nrows();
    if n <= 1 || es.s.first().is_none_or(|s| s.ncols() <= 1) {
        return (x, 0); // single input: X is already unique
    }
    let plan = schedule(es);
    let mut sweeps = 0;
    while sweeps < max {
        let before = abs_det(&x);
        for step in &plan {
            match *step {
                Update::Single(i) => knv_column(es, &mut x, i),
                Update::RealPair(i, j) => real_pair(es, &mut x, i, j),
                Update::ComplexPair(i) => complex_pair(es, &mut x, i),
            }
        }
        sweeps += 1;
        if converged(before, abs_det(&x), rtol) {
            break;
        }
    }
    (x, sweeps)
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Update {
    /// KNV0 step on one real column.
    Single(usize),
    /// Joint update of two real columns.
    RealPair(usize, usize),
    /// Update of the complex pair whose first column is this one.
    ComplexPair(usize),
}

/// The visiting order of one sweep (Algorithm 1 of the paper, scipy's indexing).
fn schedule(es: &Eigenstructure) -> Vec<Update> {
    let real = es.poles.iter().take_while(|p| p.im == 0.0).count();
    let pairs: Vec<Update> = (real..es.poles.len())
        .step_by(2)
        .map(Update::ComplexPair)
        .collect();
    let (h, o) = (real / 2, real % 2);
    // 1-based (i, j) → update, wrapping j past R as the paper does.
    let pair = |i: usize, j: usize| {
        let j = if j > real { j - real } else { j };
        if i == j {
            Update::Single(i - 1)
        } else {
            Update::RealPair(i - 1, j - 1)
        }
    };
    let interlude = |out: &mut Vec<Update>| {
        if h == 0 && real > 0 {
            out.push(Update::Single(0));
        }
        out.extend(pairs.iter().copied());
    };
    let mut out = Vec::new();
    if real > 0 {
        out.push(pair(real, 1));
    }
    for k in 1..(h + o) {
        out.push(pair(2 * k, 2 * k + 1));
    }
    out.extend(pairs.iter().copied());
    for k in 1..=h {
        out.push(pair(2 * k - 1, 2 * k));
    }
    interlude(&mut out);
    for d in 2..(h + o) {
        for i in 1..=h {
            out.push(pair(i, i + d));
        }
    }
    interlude(&mut out);
    for d in 2..(h + o) {
        for i in (h + 1)..=real {
            out.push(pair(i, i + d));
        }
    }
    interlude(&mut out);
    for i in 1..=h {
        out.push(pair(i, i + h));
    }
    interlude(&mut out);
    out
}

/// KNV method-0 step on column i.
fn knv_column(es: &Eigenstructure, x: &mut DMatrix<C64>, i: usize) {
    let n = x.nrows();
    let others = x.clone().remove_column(i);
    let y = qr_q_columns(&others, n - 1..n).column(0).into_owned();
    if let Some(v) = es.project(i, &y) {
        es.set(x, i, &v);
    }
}

/// A real orthonormal basis [a b] of the complement of all columns but i and j.
///
/// The other columns come in conjugate pairs, so their span and its complement are closed under
/// conjugation and have a real basis: orthonormalise the real and imaginary parts.
fn complement(x: &DMatrix<C64>, i: usize, j: usize) -> (DVector<f64>, DVector<f64>) {
    let n = x.nrows();
    let q2 = qr_q_columns(&x.clone().remove_columns_at(&[i, j]), n - 2..n);
    let mut parts = DMatrix::<f64>::zeros(n, 4);
    for c in 0..2 {
        parts.set_column(2 * c, &q2.column(c).map(|e| e.re));
        parts.set_column(2 * c + 1, &q2.column(c).map(|e| e.im));
    }
    let basis = crate::subspace::range(&parts);
    (
        basis.column(0).into_owned(),
        basis.column(1.min(basis.ncols() - 1)).into_owned(),
    )
}

/// numpy's `allclose` for two scalars.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-8 + 1e-5 * b.abs()
}

/// Two real poles: both columns from the top singular pair of Nᵢⱼ = 𝒮ᵢᵀ(abᵀ − baᵀ)𝒮ⱼ. When the
/// two largest singular values tie, the maximiser is not unique: the current columns are
/// projected onto the span of both top pairs, which moves them least (scipy's rule).
fn real_pair(es: &Eigenstructure, x: &mut DMatrix<C64>, i: usize, j: usize) {
    let n = x.nrows();
    let (a, b) = complement(x, i, j);
    let si = es.s[i].map(|e| e.re);
    let sj = es.s[j].map(|e| e.re);
    let skew = &a * b.transpose() - &b * a.transpose();
    let svd = (si.transpose() * skew * &sj).svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return;
    };
    let sv = &svd.singular_values;
    let tie = sv.len() > 1 && close(sv[0], sv[1]);
    let k = if tie { 2 } else { 1 };
    // G = blockdiag(𝒮ᵢ, 𝒮ⱼ)·[μ; ν] with k columns; w = [xᵢ; xⱼ]; t = G Gᵀ w.
    let mut g = DMatrix::<f64>::zeros(2 * n, k);
    g.view_mut((0, 0), (n, k))
        .copy_from(&(&si * u.columns(0, k)));
    g.view_mut((n, 0), (n, k))
        .copy_from(&(&sj * vt.rows(0, k).transpose()));
    let mut w = DVector::<f64>::zeros(2 * n);
    w.rows_mut(0, n).copy_from(&x.column(i).map(|e| e.re));
    w.rows_mut(n, n).copy_from(&x.column(j).map(|e| e.re));
    let t = &g * (g.transpose() * w);
    let t = if t.amax() > 1e-8 {
        t.normalize() * 2f64.sqrt()
    } else {
        g.column(0).into_owned()
    };
    es.set(x, i, &t.rows(0, n).map(|e| C64::new(e, 0.0)));
    es.set(x, j, &t.rows(n, n).map(|e| C64::new(e, 0.0)));
}

/// A complex pair: x = 𝒮μ with μ the dominant eigenvector of M = 𝒮ᴴ(uuᴴ − ūuᵀ)𝒮 (projected on
/// the two dominant eigenvectors when their moduli tie, as for real pairs).
fn complex_pair(es: &Eigenstructure, x: &mut DMatrix<C64>, i: usize) {
    let (a, b) = complement(x, i, i + 1);
    let s2 = C64::new(2f64.sqrt(), 0.0);
    let u: DVector<C64> = a.zip_map(&b, C64::new) * s2;
    let s = &es.s[i];
    let m = s.adjoint() * (&u * u.adjoint() - u.map(|e| e.conj()) * u.transpose()) * s;
    // M is Hermitian: real eigenvalues; order them by modulus.
    let eig = m.symmetric_eigen();
    let mut idx: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    idx.sort_by(|&p, &q| {
        eig.eigenvalues[q]
            .abs()
            .total_cmp(&eig.eigenvalues[p].abs())
    });
    let tie = idx.len() > 1 && close(eig.eigenvalues[idx[0]].abs(), eig.eigenvalues[idx[1]].abs());
    let cols: Vec<_> = idx
        .iter()
        .take(if tie { 2 } else { 1 })
        .map(|&c| eig.eigenvectors.column(c).into_owned())
        .collect();
    let g = s * DMatrix::from_columns(&cols);
    let w = x.column(i).into_owned();
    let t = &g * (g.adjoint() * w);
    let v = if t.norm() > 1e-8 {
        t.normalize()
    } else {
        g.column(0).into_owned()
    };
    es.set(x, i, &v);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn order(real: usize, pairs: usize) -> Vec<(usize, usize)> {
        let mut poles: Vec<C64> = (0..real)
            .map(|k| C64::new(-(k as f64) - 1.0, 0.0))
            .collect();
        for k in 0..pairs {
            poles.push(C64::new(-1.0, k as f64 + 1.0));
            poles.push(C64::new(-1.0, -(k as f64) - 1.0));
        }
        let es = Eigenstructure {
            poles,
            u0: DMatrix::zeros(0, 0),
            z: DMatrix::zeros(0, 0),
            s: vec![],
        };
        schedule(&es)
            .into_iter()
            .map(|u| match u {
                Update::Single(i) => (i + 1, i + 1),
                Update::RealPair(i, j) => (i + 1, j + 1),
                Update::ComplexPair(i) => (i + 1, i + 2),
            })
            .collect()
    }

    #[test]
    fn visiting_order_matches_the_algorithm() {
        assert_eq!(
            order(4, 0),
            [(4, 1), (2, 3), (1, 2), (3, 4), (1, 3), (2, 4)]
        );
        assert_eq!(
            order(5, 0),
            [
                (5, 1),
                (2, 3),
                (4, 5),
                (1, 2),
                (3, 4),
                (1, 3),
                (2, 4),
                (3, 5),
                (4, 1),
                (5, 2),
                (1, 3),
                (2, 4)
            ]
        );
        assert_eq!(
            order(2, 1),
            [
                (2, 1),
                (3, 4),
                (1, 2),
                (3, 4),
                (3, 4),
                (3, 4),
                (1, 2),
                (3, 4)
            ]
        );
        assert_eq!(order(1, 2).len(), 15);
        assert_eq!(order(0, 1), vec![(1, 2); 5]);
    }
}
