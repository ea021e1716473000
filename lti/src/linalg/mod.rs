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
pub mod complex;
pub mod evd;
pub mod norm;
pub mod product;
pub mod qr;
pub mod svd;

use faer::{MatMut, MatRef};
use nalgebra::DMatrix;

/// A borrowed faer view of a column-major nalgebra matrix (no copy).
pub(crate) fn view(a: &DMatrix<f64>) -> MatRef<'_, f64> {
    MatRef::from_column_major_slice(a.as_slice(), a.nrows(), a.ncols())
}

/// A mutable faer view of a column-major nalgebra matrix (no copy).
pub(crate) fn view_mut(a: &mut DMatrix<f64>) -> MatMut<'_, f64> {
    let (m, n) = a.shape();
    MatMut::from_column_major_slice_mut(a.as_mut_slice(), m, n)
}

/// A faer matrix (or view) copied into nalgebra's type.
pub(crate) fn to_nalgebra(a: MatRef<'_, f64>) -> DMatrix<f64> {
    let (m, n) = (a.nrows(), a.ncols());
    let mut data = Vec::with_capacity(m * n);
    for j in 0..n {
        match a.col(j).try_as_col_major() {
            // A contiguous column (faer's own matrices): copied as one slice.
            Some(col) => data.extend_from_slice(col.as_slice()),
            None => data.extend((0..m).map(|i| a[(i, j)])),
        }
    }
    DMatrix::from_vec(m, n, data)
}
