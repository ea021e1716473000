//! Double-double arithmetic: a value hi + lo with |lo| ≤ ulp(hi)/2, unit roundoff ≈ 2⁻¹⁰⁴
//! (Dekker, "A floating-point technique for extending the available precision", Numer. Math. 18,
//! 1971; Knuth's two-sum), for the computations whose double-precision rounding would be the
//! error that matters: the evaluation of the matrix exponential ([`crate::expm`]) and the DARE
//! residual that drives Newton refinement ([`crate::dare`]).

use nalgebra::DMatrix;

/// A double-double number hi + lo with |lo| ≤ ulp(hi)/2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dd {
    pub(crate) hi: f64,
    pub(crate) lo: f64,
}

impl From<f64> for Dd {
    fn from(hi: f64) -> Self {
        Dd { hi, lo: 0.0 }
    }
}

/// a + b exactly (Knuth).
pub(crate) fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd {
        hi: s,
        lo: (a - (s - bb)) + (b - bb),
    }
}

/// a + b exactly, for |a| ≥ |b| (Dekker).
pub(crate) fn quick_two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    Dd {
        hi: s,
        lo: b - (s - a),
    }
}

/// a·b exactly: the fused multiply-add returns the rounding error of the product.
pub(crate) fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    Dd {
        hi: p,
        lo: a.mul_add(b, -p),
    }
}

impl Dd {
    pub(crate) const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    pub(crate) fn from_u128(x: u128) -> Dd {
        let hi = x as f64;
        // x − hi is exact in i128 and below 2⁵³ for the coefficients used here.
        let lo = (x as i128 - hi as i128) as f64;
        quick_two_sum(hi, lo)
    }

    pub(crate) fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.hi, o.hi);
        let t = two_sum(self.lo, o.lo);
        let u = quick_two_sum(s.hi, s.lo + t.hi);
        quick_two_sum(u.hi, u.lo + t.lo)
    }

    pub(crate) fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    pub(crate) fn sub(self, o: Dd) -> Dd {
        self.add(o.neg())
    }

    pub(crate) fn mul(self, o: Dd) -> Dd {
        let p = two_prod(self.hi, o.hi);
        quick_two_sum(p.hi, p.lo + (self.hi * o.lo + self.lo * o.hi))
    }

    pub(crate) fn div(self, o: Dd) -> Dd {
        let q1 = self.hi / o.hi;
        let r = self.sub(o.mul(Dd::from(q1)));
        let q2 = r.hi / o.hi;
        let r = r.sub(o.mul(Dd::from(q2)));
        let q3 = r.hi / o.hi;
        quick_two_sum(q1, q2).add(Dd::from(q3))
    }

    /// Rounded to the nearest double.
    pub(crate) fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
}

/// A dense double-double matrix, row-major, for products whose rounding must not show.
#[derive(Debug, Clone)]
pub(crate) struct DdMatrix {
    rows: usize,
    cols: usize,
    v: Vec<Dd>,
}

impl DdMatrix {
    /// The exact value of a double matrix.
    pub(crate) fn from_f64(m: &DMatrix<f64>) -> Self {
        let (rows, cols) = m.shape();
        DdMatrix {
            rows,
            cols,
            v: (0..rows * cols)
                .map(|k| Dd::from(m[(k / cols, k % cols)]))
                .collect(),
        }
    }

    /// Each entry rounded to the nearest double.
    pub(crate) fn to_f64(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.rows, self.cols, |i, j| {
            self.v[i * self.cols + j].to_f64()
        })
    }

    pub(crate) fn transpose(&self) -> Self {
        let mut v = Vec::with_capacity(self.v.len());
        for j in 0..self.cols {
            for i in 0..self.rows {
                v.push(self.v[i * self.cols + j]);
            }
        }
        DdMatrix {
            rows: self.cols,
            cols: self.rows,
            v,
        }
    }

    pub(crate) fn mul(&self, o: &DdMatrix) -> Self {
        assert_eq!(
            self.cols, o.rows,
            "double-double product of non-conforming matrices"
        );
        let mut out = DdMatrix {
            rows: self.rows,
            cols: o.cols,
            v: vec![Dd::ZERO; self.rows * o.cols],
        };
        for i in 0..self.rows {
            for k in 0..self.cols {
                let a = self.v[i * self.cols + k];
                if a.hi == 0.0 {
                    continue;
                }
                for j in 0..o.cols {
                    let x = &mut out.v[i * o.cols + j];
                    *x = x.add(a.mul(o.v[k * o.cols + j]));
                }
            }
        }
        out
    }

    /// self + sign·o, sign = ±1.
    pub(crate) fn add(&self, o: &DdMatrix, sign: f64) -> Self {
        assert_eq!(
            (self.rows, self.cols),
            (o.rows, o.cols),
            "double-double sum of non-conforming matrices"
        );
        let v = self
            .v
            .iter()
            .zip(&o.v)
            .map(|(a, b)| {
                a.add(Dd {
                    hi: sign * b.hi,
                    lo: sign * b.lo,
                })
            })
            .collect();
        DdMatrix {
            rows: self.rows,
            cols: self.cols,
            v,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn double_double_products_are_exact() {
        let (a, b) = (0.1f64, 3.0f64);
        let p = two_prod(a, b);
        // 0.1·3 = 0.30000000000000001665…: hi is the rounded product, lo what rounding dropped.
        assert_eq!(p.hi, 0.30000000000000004);
        assert_eq!(p.lo, -2.7755575615628914e-17);
        let q = Dd::from(1.0).div(Dd::from(3.0));
        let back = q.mul(Dd::from(3.0)).sub(Dd::from(1.0));
        assert!(back.hi.abs() < 1e-31);
    }

    #[test]
    fn matrix_products_keep_what_double_drops() {
        // (1 + 2⁻⁶⁰)·(1 − 2⁻⁶⁰) = 1 − 2⁻¹²⁰ in rows of exact doubles: the sum 1·1 + 2⁻⁶⁰·(−2⁻⁶⁰)
        // rounds to 1 in double; double-double keeps the 2⁻¹²⁰.
        let t = 2f64.powi(-60);
        let a = DdMatrix::from_f64(&DMatrix::from_row_slice(1, 2, &[1.0, t]));
        let b = DdMatrix::from_f64(&DMatrix::from_row_slice(2, 1, &[1.0, -t]));
        let p = a.mul(&b);
        assert_eq!((p.v[0].hi, p.v[0].lo), (1.0, -t * t));
        let d = p.add(&DdMatrix::from_f64(&DMatrix::from_element(1, 1, 1.0)), -1.0);
        assert_eq!(d.to_f64()[(0, 0)], -t * t);
        assert_eq!(
            a.transpose().mul(&a).to_f64(),
            DMatrix::from_row_slice(2, 2, &[1.0, t, t, t * t])
        );
    }
}
