//! Orthogonal staircase forms: the controllable / uncontrollable split of (A, B) and, by
//! duality, the observable / unobservable split of (A, C).
//!
//! Rosenbrock's staircase algorithm (in the orthogonal form of Van Dooren): at each stage the
//! range of the current input block is rotated to the top of the remaining coordinates, and the
//! block it excites next becomes the new input block. With an orthogonal Q,
//!
//! ```text
//! Qᵀ A Q = ⎡A_c  A_12⎤    Qᵀ B = ⎡B_c⎤    (A_c, B_c) controllable,
//!          ⎣0    A_u ⎦           ⎣ 0 ⎦    eig(A_u) = the uncontrollable modes.
//! ```
//!
//! Rank decisions use the absolute tolerance n²·ε·max(‖A‖₁, ‖B‖₁) (SLICOT's default; see
//! [`tolerance`]), so a block that is tiny compared with the whole model counts as zero.

use nalgebra::DMatrix;

use crate::eig::{C64, eigenvalues};
use crate::error::Result;
use crate::linalg::norm::one_norm;
use crate::linalg::product::mul;
use crate::subspace::orthogonal_complement;

/// The controllable / uncontrollable split of (A, B).
#[derive(Debug, Clone)]
pub struct ControllabilityStaircase {
    /// Orthogonal change of coordinates, x = Q x̃.
    pub q: DMatrix<f64>,
    /// Qᵀ A Q, block upper-triangular.
    pub a: DMatrix<f64>,
    /// Qᵀ B, zero below the first `nc` rows.
    pub b: DMatrix<f64>,
    /// Dimension of the controllable subspace.
    pub nc: usize,
}

impl ControllabilityStaircase {
    /// Eigenvalues of the uncontrollable block A_u.
    pub fn uncontrollable_modes(&self) -> Result<Vec<C64>> {
        let n = self.a.nrows();
        eigenvalues(
            &self
                .a
                .view((self.nc, self.nc), (n - self.nc, n - self.nc))
                .into_owned(),
        )
    }
}

/// The observable / unobservable split of (A, C): with x = Q x̃,
/// Qᵀ A Q = [[A_o, 0], [A_21, A_u]] and C Q = [C_o, 0].
#[derive(Debug, Clone)]
pub struct ObservabilityStaircase {
    /// Orthogonal change of coordinates, x = Q x̃.
    pub q: DMatrix<f64>,
    /// Qᵀ A Q, block lower-triangular.
    pub a: DMatrix<f64>,
    /// C Q, zero after the first `no` columns.
    pub c: DMatrix<f64>,
    /// Dimension of the observable subspace.
    pub no: usize,
}

impl ObservabilityStaircase {
    /// Eigenvalues of the unobservable block A_u.
    pub fn unobservable_modes(&self) -> Result<Vec<C64>> {
        let n = self.a.nrows();
        eigenvalues(
            &self
                .a
                .view((self.no, self.no), (n - self.no, n - self.no))
                .into_owned(),
        )
    }

    /// The observable pair (A_o, C_o).
    pub fn observable_part(&self) -> (DMatrix<f64>, DMatrix<f64>) {
        (
            self.a.view((0, 0), (self.no, self.no)).into_owned(),
            self.c.columns(0, self.no).into_owned(),
        )
    }
}

/// Staircase reduction of (A, B).
pub fn controllability_staircase(a: &DMatrix<f64>, b: &DMatrix<f64>) -> ControllabilityStaircase {
    controllability_staircase_at(a, b, 0.0)
}

/// Staircase reduction of (A, B), rank decisions at n²·ε·max(‖A‖₁, ‖B‖₁, `norm`): `norm` is the
/// size of the data (A, B) were formed from, when they are products — a reduced-order pair
/// such as (LᵀAL, CAL), whose output block is rounding of ‖C‖‖A‖ where the exact one is zero.
pub fn controllability_staircase_at(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    norm: f64,
) -> ControllabilityStaircase {
    let n = a.nrows();
    let tol = tolerance(n, one_norm(a).max(one_norm(b)).max(norm));
    let mut q = DMatrix::<f64>::identity(n, n);
    let mut at = a.clone();
    let mut bt = b.clone();
    let mut k = 0;
    let mut block = b.clone();
    while k < n {
        let u = range_with_tol(&block, tol);
        let r = u.ncols();
        if r == 0 {
            break;
        }
        let mut uf = u.clone().resize_horizontally(n - k, 0.0);
        uf.columns_mut(r, n - k - r)
            .copy_from(&orthogonal_complement(&u));
        // Rotate coordinates k.. by uf.
        // Through `product::mul`: nalgebra's own product below 96 rows (the bits every small
        // design was checked with), faer's blocked one above (≈ 2× on the 1000-state model).
        let rows = mul(&uf.transpose(), &at.rows(k, n - k).into_owned());
        at.rows_mut(k, n - k).copy_from(&rows);
        let cols = mul(&at.columns(k, n - k).into_owned(), &uf);
        at.columns_mut(k, n - k).copy_from(&cols);
        let qc = mul(&q.columns(k, n - k).into_owned(), &uf);
        q.columns_mut(k, n - k).copy_from(&qc);
        if k == 0 {
            bt = uf.transpose() * &bt;
        }
        block = at.view((k + r, k), (n - k - r, r)).into_owned();
        k += r;
    }
    // Clean the exact zeros the construction guarantees.
    for i in k..n {
        for j in 0..k {
            at[(i, j)] = 0.0;
        }
        for j in 0..bt.ncols() {
            bt[(i, j)] = 0.0;
        }
    }
    ControllabilityStaircase {
        q,
        a: at,
        b: bt,
        nc: k,
    }
}

/// Staircase reduction of (A, C), by duality with (Aᵀ, Cᵀ).
pub fn observability_staircase(a: &DMatrix<f64>, c: &DMatrix<f64>) -> ObservabilityStaircase {
    observability_staircase_at(a, c, 0.0)
}

/// [`observability_staircase`] with the data's size `norm` (see [`controllability_staircase_at`]).
pub fn observability_staircase_at(
    a: &DMatrix<f64>,
    c: &DMatrix<f64>,
    norm: f64,
) -> ObservabilityStaircase {
    let dual = controllability_staircase_at(&a.transpose(), &c.transpose(), norm);
    ObservabilityStaircase {
        q: dual.q,
        a: dual.a.transpose(),
        c: dual.b.transpose(),
        no: dual.nc,
    }
}

/// The rank tolerance n²·ε·max(‖A‖₁, ‖B‖₁): SLICOT's default for its staircase (AB01ND, TOLDEF
/// = N²·ε·norm), not MATLAB `ctrbf`'s n·ε. The blocks that should vanish carry the rounding of
/// every product that formed A — a plant given in other coordinates, TA = (I − HC)A — a few tens
/// of ε·‖A‖ for small n, which n·ε misjudges as rank and so hides invariant zeros.
fn tolerance(n: usize, norm: f64) -> f64 {
    (n * n) as f64 * f64::EPSILON * norm.max(f64::MIN_POSITIVE)
}

/// Orthonormal basis of the range of `m`, counting singular values above an absolute `tol`
/// (faer's SVD, [`crate::linalg::svd`]).
fn range_with_tol(m: &DMatrix<f64>, tol: f64) -> DMatrix<f64> {
    if m.is_empty() {
        return DMatrix::zeros(m.nrows(), 0);
    }
    let Some(svd) = crate::linalg::svd::Svd::new(m) else {
        return DMatrix::zeros(m.nrows(), 0);
    };
    let r = svd.s.iter().filter(|&&s| s > tol).count();
    svd.u.columns(0, r).into_owned()
}

/// Whether C alone already makes (A, C) observable: C has full column rank at the staircase's
/// absolute tolerance n²·ε·max(‖A‖₁, ‖C‖₁). A C that is rounding noise beside A (the reduced
/// pair CΦL of a mode no sensor sees: ~1e-16) is not — numpy's rank rule, relative to C's own
/// largest singular value, would call it full and hand a Riccati equation an output of noise.
pub fn observable_by_rank(a: &DMatrix<f64>, c: &DMatrix<f64>) -> bool {
    observable_by_rank_at(a, c, 0.0)
}

/// [`observable_by_rank`] with the data's size `norm` (see [`controllability_staircase_at`]).
pub fn observable_by_rank_at(a: &DMatrix<f64>, c: &DMatrix<f64>, norm: f64) -> bool {
    let n = a.nrows();
    if c.ncols() != n || c.nrows() < n {
        return n == 0;
    }
    let tol = tolerance(n, one_norm(a).max(one_norm(c)).max(norm));
    crate::linalg::svd::singular_values(c)
        .get(n - 1)
        .is_some_and(|&s| s > tol)
}

/// Controllability matrix [B, AB, …, Aⁿ⁻¹B].
pub fn ctrb(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let m = b.ncols();
    let mut out = DMatrix::zeros(n, n * m);
    let mut blk = b.clone();
    for i in 0..n {
        out.columns_mut(i * m, m).copy_from(&blk);
        blk = a * blk;
    }
    out
}

/// Observability matrix [C; CA; …; CAⁿ⁻¹].
pub fn obsv(a: &DMatrix<f64>, c: &DMatrix<f64>) -> DMatrix<f64> {
    ctrb(&a.transpose(), &c.transpose()).transpose()
}

/// (A, B) controllable: the staircase reaches all n coordinates.
pub fn is_controllable(a: &DMatrix<f64>, b: &DMatrix<f64>) -> bool {
    controllability_staircase(a, b).nc == a.nrows()
}

/// (A, C) observable.
pub fn is_observable(a: &DMatrix<f64>, c: &DMatrix<f64>) -> bool {
    observability_staircase(a, c).no == a.nrows()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_an_uncontrollable_mode() {
        // x3 is decoupled from the input: mode −2 is uncontrollable.
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, -2.0, -3.0, 0.0, 0.0, 0.0, -2.0]);
        let b = DMatrix::from_row_slice(3, 1, &[0.0, 4.0, 0.0]);
        let s = controllability_staircase(&a, &b);
        assert_eq!(s.nc, 2);
        let modes = s.uncontrollable_modes().unwrap();
        assert!((modes[0].re + 2.0).abs() < 1e-12);
        assert!((&s.q * &s.a * s.q.transpose() - &a).norm() < 1e-12);
    }

    #[test]
    fn seed002_ta_c_is_observable() {
        // TA from the seed-002 reference (exact fractions).
        let ta = DMatrix::from_row_slice(
            3,
            3,
            &[
                0.0,
                1.0 / 17.0,
                8.0 / 17.0,
                -2.0,
                -3.0,
                0.0,
                0.0,
                -4.0 / 17.0,
                -32.0 / 17.0,
            ],
        );
        let c = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert!(is_observable(&ta, &c));
        assert_eq!(crate::pinv::rank(&obsv(&ta, &c)), 3);
    }
}
