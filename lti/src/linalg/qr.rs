//! QR with column pivoting, AP = QR (faer's blocked Householder QR with column pivoting,
//! LAPACK `xGEQP3`'s method): rank-revealing, |R₁₁| ≥ |R₂₂| ≥ … .
//!
//! Used to pick well-conditioned columns of a matrix (the basis of ker C that keeps the
//! coordinate vectors where ker C is spanned by them). Preconditions: finite entries.

use nalgebra::DMatrix;

use super::view;

/// The column order of A's pivoted QR: `order[k]` is the column of A moved to position k.
pub fn pivot_order(a: &DMatrix<f64>) -> Vec<usize> {
    if a.ncols() == 0 {
        return Vec::new();
    }
    if a.nrows() == 0 {
        return (0..a.ncols()).collect();
    }
    let qr = view(a).col_piv_qr();
    qr.P().arrays().0.to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_column_comes_first() {
        let a = DMatrix::from_row_slice(2, 3, &[0.0, 3.0, 1.0, 0.0, 4.0, 0.0]);
        assert_eq!(pivot_order(&a)[0], 1);
        assert_eq!(pivot_order(&a).len(), 3);
    }
}
