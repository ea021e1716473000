//! The matrix exponential e^{Mh}, correctly rounded in practice.
//!
//! Method: the scaling and squaring algorithm of Al-Mohy & Higham, "A new scaling and squaring
//! algorithm for the matrix exponential", SIAM J. Matrix Anal. Appl. 31(3), 2009 (Algorithm 5.1),
//! with its evaluation carried out in double-double arithmetic (Dekker, "A floating-point
//! technique for extending the available precision", Numer. Math. 18, 1971).
//!
//! With X = Mh, the [m/m] Padé approximant of e^x is r_m = q_m(x)⁻¹ p_m(x),
//!
//! ```text
//! p_m(x) = Σ_{j=0}^{m} b_j x^j,   b_j = (2m − j)! / (j! (m − j)!),   q_m(x) = p_m(−x),
//! p_m(X) = V + U,  q_m(X) = V − U,   U = X Σ_j b_{2j+1} X^{2j},  V = Σ_j b_{2j} X^{2j}
//! ```
//!
//! (for m = 13, U = X[X⁶(b₁₃X⁶ + b₁₁X⁴ + b₉X²) + b₇X⁶ + b₅X⁴ + b₃X² + b₁I] and V likewise, the
//! paper's scheme), and e^X ≈ r_m(2^{−s}X)^{2^s}. In exact arithmetic that is e^{X + ΔX} with
//! ΔX = 2^s h_{2m+1}(2^{−s}X), h_{2m+1}(Y) = log(e^{−Y} r_m(Y)) a power series in Y from Y^{2m+1} on
//! (Higham 2005, SIAM J. Matrix Anal. Appl. 26(4)), bounded by
//!
//! ```text
//! ‖ΔX‖/‖X‖ ≤ h̃_{2m+1}(α_p)/α_p,  α_p = max(d_p, d_{p+1}),  d_k = ‖(2^{−s}X)^k‖₁^{1/k},  2m + 1 ≥ p(p − 1)
//! ```
//!
//! with h̃ the series of |coefficients|. θ_m is the largest α for which that bound is ≤ u = 2⁻⁵³
//! (Higham 2005's values, which the 2009 paper keeps). Algorithm 5.1 picks the cheapest
//! m ∈ {3, 5, 7, 9} with α ≤ θ_m, else m = 13 with the smallest such s, each time with
//! ℓ(A, m) = max(⌈log₂(α/u)/(2m)⌉, 0), α = |c_{2m+1}|·‖|A|^{2m+1}‖₁/‖A‖₁, |c_{2m+1}| =
//! (m!)²/((2m)!(2m+1)!), the squarings that keep the rounding errors of evaluating r_m in check.
//! The norms here are exact (the matrices are small), not the paper's estimates.
//!
//! Why not plain double precision (nalgebra's `exp()`, a port of the same algorithm): the bound is
//! normwise. For the stiff missile autopilot (entries 10⁻³ … 3·10⁴, dt = 10⁻⁴: m = 13, s = 0,
//! ‖X‖₁ ≈ 3.3) the small entries of Φ = e^{Ah} carry errors of ~u·‖Φ‖, i.e. thousands of ulps of
//! themselves. So here, after choosing (m, s) as above,
//!
//! 1. X = M·h is formed exactly (hi + lo, by a fused multiply-add);
//! 2. s is raised by j = ⌈53/(2m)⌉: since h̃_{2m+1} has non-negative coefficients from x^{2m+1} on,
//!    h̃(α/2^j)/(α/2^j) ≤ 2^{−2mj} h̃(α)/α, so the truncation bound drops from u to ≤ u²;
//! 3. the powers, the solve of q_m·R = p_m (Gaussian elimination, partial pivoting) and the
//!    squaring phase all run in double-double (unit roundoff ≈ 2⁻¹⁰⁴), so the squarings — the
//!    step the paper's Code Fragment 2.1 makes exact for triangular matrices only — add no
//!    double-precision rounding either;
//! 4. each entry is rounded to double once, at the end.
//!
//! Every entry, however small beside the norm, then sits within its own final rounding of the
//! exact value (≤ 0.5 ulp on every seed model; lti/tests/expm_reference.rs checks against 40-digit
//! values). Balancing (D⁻¹XD with D a diagonal of powers of two) was tried and left out: with
//! steps 1–4 it changes nothing on the seed models, and in plain double precision it helps a full
//! step of the missile but costs ~300 ulps on part of a step (it lowers m while Γ's entries stay
//! graded). Block-triangular structure survives exactly: the zero blocks of [[A, G], [0, W]] stay
//! 0 through every product, and the solve never pivots into them. Set-up code only: it allocates.
//!
//! Above [`DOUBLE_DOUBLE_MAX`] rows the double-double products (≈ 20 flops each, no blocking)
//! would dominate a large model's set-up — minutes at n = 1000 — so there the same algorithm runs
//! in double precision on faer's blocked products ([`expm_double`], scipy's `expm`): normwise
//! accurate, ‖ΔΦ‖ ≲ u·‖Φ‖, as scipy and MATLAB are. Both paths are deterministic, so a
//! run's processes still compute bit-identical designs.

use nalgebra::DMatrix;

use crate::dd::{Dd, two_prod};
use crate::linalg::norm::one_norm;
use crate::linalg::product::{mul, solve};

/// Unit roundoff of IEEE double precision, the u of the paper's θ_m.
const U: f64 = 1.1102230246251565e-16;

/// θ_m for m = 3, 5, 7, 9, 13 at u = 2⁻⁵³ (Higham 2005; Al-Mohy & Higham 2009).
const THETA: [(usize, f64); 5] = [
    (3, 1.495585217958292e-2),
    (5, 2.53939833006323e-1),
    (7, 9.504178996162932e-1),
    (9, 2.097847961257068e0),
    (13, 5.371920351148152e0),
];

/// Largest matrix evaluated in double-double; larger ones run in double precision.
pub const DOUBLE_DOUBLE_MAX: usize = 96;

/// e^{Mh} for a square M, with the product M·h formed exactly (up to [`DOUBLE_DOUBLE_MAX`]).
pub fn expm(m: &DMatrix<f64>, h: f64) -> DMatrix<f64> {
    let n = m.nrows();
    assert_eq!(n, m.ncols(), "expm of a non-square matrix");
    if n == 0 {
        return DMatrix::zeros(0, 0);
    }
    if !h.is_finite() || m.iter().any(|x| !x.is_finite()) {
        return DMatrix::from_element(n, n, f64::NAN);
    }
    if n > DOUBLE_DOUBLE_MAX {
        return expm_double(&(m * h));
    }
    // X = M h exactly, row-major.
    let x = DdMat {
        n,
        v: (0..n * n).map(|k| two_prod(m[(k / n, k % n)], h)).collect(),
    };
    let xf = DMatrix::from_fn(n, n, |i, j| x.v[i * n + j].hi);
    let (deg, s) = degree_and_scaling(&xf);
    // Step 2: truncation bound from u to u².
    let s = s + 53usize.div_ceil(2 * deg);
    let y = x.scaled(2f64.powi(-(s as i32)));
    let mut r = pade(&y, deg);
    for _ in 0..s {
        r = r.mul(&r);
    }
    DMatrix::from_fn(n, n, |i, j| r.v[i * n + j].to_f64())
}

/// e^X in double precision above [`DOUBLE_DOUBLE_MAX`] rows: the same (m, s) and the same
/// Padé scheme, on faer's blocked products and LU ([`crate::linalg::product`]), the powers X²,
/// X⁴, X⁶ of the degree choice reused (scaled by 4^{−s}, 16^{−s}, 64^{−s}, exact powers of two)
/// for r_m(2^{−s}X). This is scipy's `expm` (the same algorithm, exact norms here where scipy
/// estimates them): normwise accurate, ‖ΔΦ‖ ≲ u·‖Φ‖ (on the 1100-row ZOH block of the 1000-state
/// model of BENCHMARKS.md, 3× faster than nalgebra's `Matrix::exp`, which it replaced).
fn expm_double(x: &DMatrix<f64>) -> DMatrix<f64> {
    let n = x.nrows();
    let powers = Powers::of(x, mul);
    let (deg, s) = degree_and_scaling_from(x, &powers);
    let c = 2f64.powi(-(s as i32));
    let b: Vec<f64> = pade_coefficients(deg).iter().map(|d| d.hi).collect();
    let id = DMatrix::<f64>::identity(n, n);
    let y = x * c;
    let y2 = &powers.p2 * (c * c);
    let (u, v) = if deg == 13 {
        let y4 = &powers.p4 * c.powi(4);
        let y6 = &powers.p6 * c.powi(6);
        let inner_u = mul(&y6, &(&y6 * b[13] + &y4 * b[11] + &y2 * b[9]))
            + &y6 * b[7]
            + &y4 * b[5]
            + &y2 * b[3]
            + &id * b[1];
        let v = mul(&y6, &(&y6 * b[12] + &y4 * b[10] + &y2 * b[8]))
            + &y6 * b[6]
            + &y4 * b[4]
            + &y2 * b[2]
            + &id * b[0];
        (mul(&y, &inner_u), v)
    } else {
        // m < 13 comes with s = 0 (Algorithm 5.1): Y = X, and its even powers are formed.
        let even = [&id, &powers.p2, &powers.p4, &powers.p6, &powers.p8];
        let mut odd = DMatrix::zeros(n, n);
        let mut v = DMatrix::zeros(n, n);
        for (j, p) in even.iter().enumerate().take(deg / 2 + 1) {
            odd += *p * b[2 * j + 1];
            v += *p * b[2 * j];
        }
        (mul(&y, &odd), v)
    };
    let Some(mut r) = solve(&(&v - &u), &(&v + &u)) else {
        return DMatrix::from_element(n, n, f64::NAN);
    };
    for _ in 0..s {
        r = mul(&r, &r);
    }
    r
}

/// X², X⁴, X⁶, X⁸, X¹⁰: the powers the degree choice measures.
struct Powers {
    p2: DMatrix<f64>,
    p4: DMatrix<f64>,
    p6: DMatrix<f64>,
    p8: DMatrix<f64>,
    p10: DMatrix<f64>,
}

impl Powers {
    /// The powers by `mul`: nalgebra's product on the double-double path (its bits decide
    /// (m, s) there, as they always have), faer's above it.
    fn of(a: &DMatrix<f64>, mul: impl Fn(&DMatrix<f64>, &DMatrix<f64>) -> DMatrix<f64>) -> Self {
        let p2 = mul(a, a);
        let p4 = mul(&p2, &p2);
        let p6 = mul(&p4, &p2);
        let p8 = mul(&p4, &p4);
        let p10 = mul(&p8, &p2);
        Powers {
            p2,
            p4,
            p6,
            p8,
            p10,
        }
    }
}

/// (m, s) of Al-Mohy & Higham (2009), Algorithm 5.1, steps 1–16, with exact norms.
fn degree_and_scaling(a: &DMatrix<f64>) -> (usize, usize) {
    degree_and_scaling_from(a, &Powers::of(a, |x, y| x * y))
}

/// [`degree_and_scaling`] from the powers already formed.
fn degree_and_scaling_from(a: &DMatrix<f64>, p: &Powers) -> (usize, usize) {
    let norm = |p: &DMatrix<f64>| one_norm(p);
    let (a4, a6, a8, a10) = (&p.p4, &p.p6, &p.p8, &p.p10);
    let d = |p: &DMatrix<f64>, k: i32| norm(p).powf(1.0 / k as f64);
    let (d4, d6, d8, d10) = (d(a4, 4), d(a6, 6), d(a8, 8), d(a10, 10));
    let eta1 = d4.max(d6);
    let eta3 = d6.max(d8);
    for &(m, theta) in &THETA[..4] {
        let eta = if m <= 5 { eta1 } else { eta3 };
        if eta <= theta && ell(a, m) == 0 {
            return (m, 0);
        }
    }
    let eta5 = eta3.min(d8.max(d10));
    let theta13 = THETA[4].1;
    let mut s = if eta5 > 0.0 {
        (eta5 / theta13).log2().ceil().max(0.0) as usize
    } else {
        0
    };
    // A norm so large that e^X overflows anyway: no point squaring more than that.
    s = s.min(1100);
    s += ell(&(a * 2f64.powi(-(s as i32))), 13);
    (13, s.min(1100))
}

/// ℓ(A, m) of Al-Mohy & Higham (2009), Algorithm 5.1: the squarings that keep the rounding errors
/// of evaluating r_m below the truncation error u when |A| has much larger powers than A.
fn ell(a: &DMatrix<f64>, m: usize) -> usize {
    let n1 = one_norm(a);
    if n1 == 0.0 {
        return 0;
    }
    // ‖|A|^{2m+1}‖₁ = max of (|A|ᵀ)^{2m+1}·1 (non-negative matrix: no cancellation).
    let abs_t = a.map(f64::abs).transpose();
    let mut v = nalgebra::DVector::from_element(a.nrows(), 1.0);
    for _ in 0..2 * m + 1 {
        v = &abs_t * v;
    }
    let power = v.max();
    // |c_{2m+1}| = (m!)² / ((2m)! (2m+1)!), as a running product to stay in range.
    let mut c = 1.0f64;
    for k in 1..=m {
        c *= k as f64 / (m + k) as f64; // m!·m!/(2m)! = Π m!/((m+1)…(2m)) step by step
    }
    for k in 1..=2 * m + 1 {
        c /= k as f64;
    }
    let alpha = c * power / n1;
    if alpha <= 0.0 {
        return 0;
    }
    ((alpha / U).log2() / (2 * m) as f64).ceil().max(0.0) as usize
}

/// b_j = (2m − j)! / (j! (m − j)!), j = 0 … m: integers (exact in u128 and in double-double).
fn pade_coefficients(m: usize) -> Vec<Dd> {
    let fact = |k: usize| (1..=k as u128).product::<u128>();
    (0..=m)
        .map(|j| Dd::from_u128(fact(2 * m - j) / (fact(j) * fact(m - j))))
        .collect()
}

/// r_m(Y) = q_m(Y)⁻¹ p_m(Y) in double-double.
fn pade(y: &DdMat, m: usize) -> DdMat {
    let n = y.n;
    let b = pade_coefficients(m);
    let id = DdMat::identity(n);
    let y2 = y.mul(y);
    let (u, v) = if m == 13 {
        let y4 = y2.mul(&y2);
        let y6 = y4.mul(&y2);
        let lin = |c: [(usize, &DdMat); 3]| {
            let mut acc = DdMat::zeros(n);
            for (k, p) in c {
                acc.add_scaled(p, b[k]);
            }
            acc
        };
        let mut inner_u = y6.mul(&lin([(13, &y6), (11, &y4), (9, &y2)]));
        inner_u.add_scaled(&y6, b[7]);
        inner_u.add_scaled(&y4, b[5]);
        inner_u.add_scaled(&y2, b[3]);
        inner_u.add_scaled(&id, b[1]);
        let mut v = y6.mul(&lin([(12, &y6), (10, &y4), (8, &y2)]));
        v.add_scaled(&y6, b[6]);
        v.add_scaled(&y4, b[4]);
        v.add_scaled(&y2, b[2]);
        v.add_scaled(&id, b[0]);
        (y.mul(&inner_u), v)
    } else {
        let mut odd = DdMat::zeros(n);
        let mut v = DdMat::zeros(n);
        let mut p = id;
        for j in 0..=m / 2 {
            odd.add_scaled(&p, b[2 * j + 1]);
            v.add_scaled(&p, b[2 * j]);
            if j < m / 2 {
                p = p.mul(&y2);
            }
        }
        (y.mul(&odd), v)
    };
    let mut q = v.clone();
    q.add_scaled(&u, Dd::from(-1.0));
    let mut p = v;
    p.add_scaled(&u, Dd::from(1.0));
    q.solve(p)
}

/// A square double-double matrix, row-major.
#[derive(Debug, Clone)]
struct DdMat {
    n: usize,
    v: Vec<Dd>,
}

impl DdMat {
    fn zeros(n: usize) -> Self {
        DdMat {
            n,
            v: vec![Dd::ZERO; n * n],
        }
    }

    fn identity(n: usize) -> Self {
        let mut m = Self::zeros(n);
        for i in 0..n {
            m.v[i * n + i] = Dd::from(1.0);
        }
        m
    }

    /// Every entry times a power of two (exact).
    fn scaled(&self, pow2: f64) -> Self {
        DdMat {
            n: self.n,
            v: self
                .v
                .iter()
                .map(|x| Dd {
                    hi: x.hi * pow2,
                    lo: x.lo * pow2,
                })
                .collect(),
        }
    }

    fn mul(&self, o: &DdMat) -> DdMat {
        let n = self.n;
        let mut out = Self::zeros(n);
        for i in 0..n {
            for k in 0..n {
                let a = self.v[i * n + k];
                if a.hi == 0.0 {
                    continue; // keeps structural zeros exact and skips work
                }
                for j in 0..n {
                    let b = o.v[k * n + j];
                    if b.hi != 0.0 {
                        out.v[i * n + j] = out.v[i * n + j].add(a.mul(b));
                    }
                }
            }
        }
        out
    }

    /// self += c·o.
    fn add_scaled(&mut self, o: &DdMat, c: Dd) {
        for (x, y) in self.v.iter_mut().zip(&o.v) {
            if y.hi != 0.0 {
                *x = x.add(c.mul(*y));
            }
        }
    }

    /// self⁻¹·rhs by Gaussian elimination with partial pivoting.
    fn solve(mut self, mut rhs: DdMat) -> DdMat {
        let n = self.n;
        for c in 0..n {
            let p = (c..n)
                .max_by(|&i, &j| {
                    self.v[i * n + c]
                        .hi
                        .abs()
                        .total_cmp(&self.v[j * n + c].hi.abs())
                })
                .unwrap_or(c);
            if p != c {
                for j in 0..n {
                    self.v.swap(c * n + j, p * n + j);
                    rhs.v.swap(c * n + j, p * n + j);
                }
            }
            let piv = self.v[c * n + c];
            for i in c + 1..n {
                if self.v[i * n + c].hi == 0.0 {
                    continue;
                }
                let f = self.v[i * n + c].div(piv);
                for j in c..n {
                    self.v[i * n + j] = self.v[i * n + j].sub(f.mul(self.v[c * n + j]));
                }
                for j in 0..n {
                    rhs.v[i * n + j] = rhs.v[i * n + j].sub(f.mul(rhs.v[c * n + j]));
                }
            }
        }
        for i in (0..n).rev() {
            for j in 0..n {
                let mut acc = rhs.v[i * n + j];
                for k in i + 1..n {
                    acc = acc.sub(self.v[i * n + k].mul(rhs.v[k * n + j]));
                }
                rhs.v[i * n + j] = acc.div(self.v[i * n + i]);
            }
        }
        rhs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pade_coefficients_are_the_papers() {
        // b_j for m = 3 and two of m = 13 (the textbook [m/m] coefficients, scaled so b_m = 1).
        let b3: Vec<f64> = pade_coefficients(3).iter().map(|x| x.to_f64()).collect();
        assert_eq!(b3, [120.0, 60.0, 12.0, 1.0]);
        let b13 = pade_coefficients(13);
        assert_eq!(b13[0].to_f64(), 64_764_752_532_480_000.0);
        assert_eq!(b13[12].to_f64(), 182.0);
        // e^x − r_3(x) = ±(3!)²/(6!·7!)·x⁷·(1 + O(x)): a wrong b_j would leave
        // an error of order x^j, j ≤ 6, hundreds of times larger at x = 0.1.
        let x = 0.1f64;
        let p: f64 = b3
            .iter()
            .enumerate()
            .map(|(j, b)| b * x.powi(j as i32))
            .sum();
        let q: f64 = b3
            .iter()
            .enumerate()
            .map(|(j, b)| b * (-x).powi(j as i32))
            .sum();
        let lead = 36.0 / (720.0 * 5040.0) * x.powi(7);
        assert!(
            ((p / q - x.exp()) / lead - 1.0).abs() < 0.2,
            "{}",
            (p / q - x.exp()) / lead
        );
    }

    #[test]
    fn scalar_and_rotation_against_closed_forms() {
        // e^{−2·0.1} and the rotation exp([[0, ω], [−ω, 0]]h) = [[cos, sin], [−sin, cos]](ωh).
        let e = expm(&DMatrix::from_element(1, 1, -2.0), 0.1)[(0, 0)];
        assert!((e - (-0.2f64).exp()).abs() <= f64::EPSILON * e);
        let w = 7.0;
        let r = expm(&DMatrix::from_row_slice(2, 2, &[0.0, w, -w, 0.0]), 0.25);
        let (s, c) = (1.75f64).sin_cos();
        for (got, want) in r.iter().zip([c, -s, s, c]) {
            assert!(
                (got - want).abs() <= f64::EPSILON * want.abs(),
                "{got} vs {want}"
            );
        }
    }

    #[test]
    fn nilpotent_and_large_norms() {
        // e^{N} = I + N + N²/2 exactly for a nilpotent Jordan block.
        let nil = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        let e = expm(&nil, 3.0);
        assert_eq!(
            e,
            DMatrix::from_row_slice(3, 3, &[1.0, 3.0, 4.5, 0.0, 1.0, 3.0, 0.0, 0.0, 1.0])
        );
        // Many squarings: diag(−50, −60)·1: e^{−50}, e^{−60} to the last bit.
        let e = expm(
            &DMatrix::from_row_slice(2, 2, &[-50.0, 0.0, 0.0, -60.0]),
            1.0,
        );
        assert_eq!(e[(0, 1)], 0.0);
        assert!((e[(0, 0)] / (-50.0f64).exp() - 1.0).abs() <= f64::EPSILON);
        assert!((e[(1, 1)] / (-60.0f64).exp() - 1.0).abs() <= f64::EPSILON);
        assert!(expm(&DMatrix::from_element(2, 2, f64::NAN), 1.0)[(0, 0)].is_nan());
        assert_eq!(expm(&DMatrix::zeros(0, 0), 1.0).nrows(), 0);
    }

    #[test]
    fn large_rotations_with_squarings_match_their_closed_form() {
        // 60 damped rotations [[−a, ω], [−ω, −a]] (120 rows: the double path), ‖X‖ up to ~90 so
        // that m = 13 and several squarings run; e^{Xt} = e^{−at}[[cos ωt, sin ωt], [−sin ωt, cos ωt]].
        let k = 60;
        let n = 2 * k;
        let mut m = DMatrix::zeros(n, n);
        let pars: Vec<(f64, f64)> = (0..k)
            .map(|i| (0.1 + 0.7 * i as f64, 1.0 + 1.3 * i as f64))
            .collect();
        for (i, &(a, w)) in pars.iter().enumerate() {
            let j = 2 * i;
            m[(j, j)] = -a;
            m[(j + 1, j + 1)] = -a;
            m[(j, j + 1)] = w;
            m[(j + 1, j)] = -w;
        }
        let t = 0.7;
        let e = expm(&m, t);
        for (i, &(a, w)) in pars.iter().enumerate() {
            let j = 2 * i;
            let (d, c, s) = ((-a * t).exp(), (w * t).cos(), (w * t).sin());
            for (r, cc, want) in [(0, 0, d * c), (0, 1, d * s), (1, 0, -d * s), (1, 1, d * c)] {
                let got = e[(j + r, j + cc)];
                assert!(
                    (got - want).abs() <= 1e-13,
                    "block {i} ({r},{cc}): {got} vs {want}"
                );
            }
        }
        // Nothing leaks between blocks (the products of a block-diagonal matrix stay block-diagonal).
        for i in 0..n {
            for j in 0..n {
                if i / 2 != j / 2 {
                    assert_eq!(e[(i, j)], 0.0);
                }
            }
        }
    }

    #[test]
    fn large_matrices_agree_with_the_double_double_blocks() {
        // e^{diag(A₁, A₂)} = diag(e^{A₁}, e^{A₂}): the 140×140 matrix takes the double path, its
        // 70×70 blocks the double-double one.
        let k = 70;
        let block = |seed: f64| {
            DMatrix::from_fn(k, k, |i, j| {
                ((i * 31 + j * 17) as f64 * seed).sin() / 4.0 - if i == j { 1.0 } else { 0.0 }
            })
        };
        let (a1, a2) = (block(0.37), block(0.91));
        let mut big = DMatrix::zeros(2 * k, 2 * k);
        big.view_mut((0, 0), (k, k)).copy_from(&a1);
        big.view_mut((k, k), (k, k)).copy_from(&a2);
        let e = expm(&big, 0.05);
        let (e1, e2) = (expm(&a1, 0.05), expm(&a2, 0.05));
        assert!((e.view((0, 0), (k, k)) - &e1).norm() <= 1e-14 * e1.norm());
        assert!((e.view((k, k), (k, k)) - &e2).norm() <= 1e-14 * e2.norm());
        assert_eq!(e.view((0, k), (k, k)).amax(), 0.0);
    }
}
