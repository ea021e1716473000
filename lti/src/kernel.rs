//! Allocation-free matrix–vector products for the step functions.
//!
//! The run-time matrices are small (n ≤ 16) and dynamic; nalgebra's generic `gemv` spends more
//! time dispatching than multiplying at that size. These loops walk the column-major storage
//! directly. The order of operations is fixed, so every caller gets the same bits.

use nalgebra::DMatrix;

/// out = M v (each row summed from 0.0 over the columns in order, as `gemv` with β = 0).
#[inline]
pub fn mul_into(out: &mut [f64], m: &DMatrix<f64>, v: &[f64]) {
    let rows = m.nrows();
    let data = m.as_slice();
    assert!(out.len() == rows && data.len() == rows * v.len(), "mul_into: shapes do not conform");
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = 0.0;
        for (j, &vj) in v.iter().enumerate() {
            // SAFETY: as in `mul_acc`.
            acc += unsafe { *data.get_unchecked(i + j * rows) } * vj;
        }
        *o = acc;
    }
}

/// out += M v, summing each row over the columns in order (the same order as `gemv`).
#[inline]
pub fn mul_acc(out: &mut [f64], m: &DMatrix<f64>, v: &[f64]) {
    let rows = m.nrows();
    let data = m.as_slice();
    assert!(out.len() == rows && data.len() == rows * v.len(), "mul_acc: shapes do not conform");
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = *o;
        for (j, &vj) in v.iter().enumerate() {
            // SAFETY: i < rows and j < v.len(), so i + j·rows < rows·v.len() = data.len()
            // (asserted above).
            acc += unsafe { *data.get_unchecked(i + j * rows) } * vj;
        }
        *o = acc;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_nalgebra() {
        let m = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let v = [1.0, -1.0, 0.5];
        let mut out = [10.0, 10.0];
        mul_into(&mut out, &m, &v);
        assert_eq!(out, [0.5, 2.0]);
        mul_acc(&mut out, &m, &v);
        assert_eq!(out, [1.0, 4.0]);
        let mut empty: [f64; 0] = [];
        mul_into(&mut empty, &DMatrix::zeros(0, 3), &v);
    }
}
