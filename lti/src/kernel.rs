//! Allocation-free matrix–vector products for the step functions.
//!
//! The run-time matrices are small (n ≤ 16) and dynamic; nalgebra's generic `gemv` spends more
//! time dispatching than multiplying at that size. These loops walk the column-major storage
//! directly. The order of operations is fixed, so every caller gets the same bits.

use nalgebra::DMatrix;

/// out = M v (each row summed from 0.0 over the columns in order, as `gemv` with β = 0).
#[inline]
pub fn mul_into(out: &mut [f64], m: &DMatrix<f64>, v: &[f64]) {
    product(out, m, v, false);
}

/// out += M v, summing each row over the columns in order (the same order as `gemv`).
#[inline]
pub fn mul_acc(out: &mut [f64], m: &DMatrix<f64>, v: &[f64]) {
    product(out, m, v, true);
}

/// out = M v, or out += M v when `add`. The rows are taken four at a time, each block's sums in
/// registers while the columns are walked in order, j = 0, 1, …: every row still sums its own
/// terms in column order, so the bits are those of one row at a time, and the column-major
/// storage is read contiguously.
#[inline(always)]
fn product(out: &mut [f64], m: &DMatrix<f64>, v: &[f64], add: bool) {
    let rows = m.nrows();
    let data = m.as_slice();
    assert!(
        out.len() == rows && data.len() == rows * v.len(),
        "matrix–vector product: shapes do not conform"
    );
    let mut i0 = 0;
    while rows - i0 >= 4 {
        block::<4>(out, data, rows, i0, v, add);
        i0 += 4;
    }
    match rows - i0 {
        3 => block::<3>(out, data, rows, i0, v, add),
        2 => block::<2>(out, data, rows, i0, v, add),
        1 => block::<1>(out, data, rows, i0, v, add),
        _ => {}
    }
}

/// Rows i0 … i0 + B − 1 of [`product`].
#[inline(always)]
fn block<const B: usize>(
    out: &mut [f64],
    data: &[f64],
    rows: usize,
    i0: usize,
    v: &[f64],
    add: bool,
) {
    let out = &mut out[i0..i0 + B];
    let mut acc = [0.0; B];
    if add {
        acc.copy_from_slice(out);
    }
    for (j, &vj) in v.iter().enumerate() {
        for (i, a) in acc.iter_mut().enumerate() {
            // SAFETY: i0 + B ≤ rows and j < v.len(), so i0 + i + j·rows < rows·v.len() =
            // data.len() (asserted by `product`).
            *a += unsafe { *data.get_unchecked(i0 + i + j * rows) } * vj;
        }
    }
    out.copy_from_slice(&acc);
}

/// dst = src, for the short vectors of a step: up to 8 values as register moves (a call to
/// `memcpy`, which `copy_from_slice` makes for a length known only at run time, costs more
/// than such a copy); longer ones with `copy_from_slice`.
#[inline(always)]
pub fn copy(dst: &mut [f64], src: &[f64]) {
    assert!(dst.len() == src.len(), "copy: lengths differ");
    match src.len() {
        0 => {}
        1 => dst[0] = src[0],
        2 => fixed::<2>(dst, src),
        3 => fixed::<3>(dst, src),
        4 => fixed::<4>(dst, src),
        5 => fixed::<5>(dst, src),
        6 => fixed::<6>(dst, src),
        7 => fixed::<7>(dst, src),
        8 => fixed::<8>(dst, src),
        _ => dst.copy_from_slice(src),
    }
}

#[inline(always)]
fn fixed<const N: usize>(dst: &mut [f64], src: &[f64]) {
    let (d, s): (&mut [f64; N], &[f64; N]) = (
        dst.try_into().expect("length N"),
        src.try_into().expect("length N"),
    );
    *d = *s;
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

    /// Every block size and remainder gives the bits of one row at a time, summed in column
    /// order from 0.0 (or from out), on values whose sums depend on that order.
    #[test]
    fn blocks_sum_each_row_in_column_order() {
        for rows in 0..11 {
            for cols in 0..7 {
                let m = DMatrix::from_fn(rows, cols, |i, j| {
                    ((i * 7 + j * 3) as f64 * 0.37).sin() * 10f64.powi((i + j) as i32 % 5 - 2)
                });
                let v: Vec<f64> = (0..cols).map(|j| (j as f64 * 1.3).cos() * 1e3).collect();
                let start: Vec<f64> = (0..rows).map(|i| i as f64 * 1e-3 - 0.1).collect();
                let mut into = vec![f64::NAN; rows];
                let mut acc = start.clone();
                mul_into(&mut into, &m, &v);
                mul_acc(&mut acc, &m, &v);
                for i in 0..rows {
                    let (mut a, mut b) = (0.0, start[i]);
                    for j in 0..cols {
                        a += m[(i, j)] * v[j];
                        b += m[(i, j)] * v[j];
                    }
                    assert_eq!(
                        (into[i].to_bits(), acc[i].to_bits()),
                        (a.to_bits(), b.to_bits()),
                        "{rows}×{cols} row {i}"
                    );
                }
                let mut copied = vec![0.0; rows];
                copy(&mut copied, &acc);
                assert_eq!(
                    copied.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    acc.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
                );
            }
        }
    }
}
