//! Dense decompositions from `faer` (pure Rust, LAPACK-grade algorithms), one file per
//! decomposition as in nalgebra's `linalg`, each stating its preconditions.
//!
//! Why faer and not nalgebra's own: nalgebra's real Schur iteration failed to converge on the
//! sampled Kundur model (n = 52, dt = 1 ms) and on the NPCC (334) and WECC (569) models, and its
//! SVD returned a basis 2° off on a rank-deficient projector; faer implements LAPACK's
//! algorithms (multishift Francis QR with aggressive early deflation, divide-and-conquer
//! bidiagonal SVD, blocked Householder QR with column pivoting) and its matrix product is
//! blocked and vectorised (≈ 20× nalgebra's at n = 1000). Why faer and not LAPACK through the
//! system OpenBLAS: the default `cargo run --release` must build on a fresh machine, where no
//! system BLAS is installed; faer is pure Rust. See ARCHITECTURE.md.
//!
//! All functions take and return nalgebra matrices (the rest of the code base's type): the
//! conversion is one copy each way, negligible beside the O(n³) work.
//!
//! * [`svd`] — singular values and the full SVD, the one rank rule ([`svd::rank_tolerance`]),
//!   orthonormal bases of the four fundamental subspaces;
//! * [`evd`] — eigenvalues (and eigenvectors) of a real square matrix;
//! * [`qr`] — QR with column pivoting (rank-revealing);
//! * [`product`] — blocked matrix products and LU solves for large matrices.

pub mod balance;
pub mod evd;
pub mod norm;
pub mod product;
pub mod qr;
pub mod svd;

use faer::{Mat as FMat, MatRef};
use nalgebra::DMatrix;

/// A borrowed faer view of a column-major nalgebra matrix (no copy).
pub(crate) fn view(a: &DMatrix<f64>) -> MatRef<'_, f64> {
    MatRef::from_column_major_slice(a.as_slice(), a.nrows(), a.ncols())
}

/// A faer matrix (or view) copied into nalgebra's type.
pub(crate) fn to_nalgebra(a: MatRef<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)])
}

/// An owned faer matrix moved into nalgebra's type.
pub(crate) fn from_faer(a: &FMat<f64>) -> DMatrix<f64> {
    to_nalgebra(a.as_ref())
}
