//! Pole sets: closed under conjugation, each complex pair stored as (λ, λ̄) side by side.

use crate::eig::C64;
use crate::error::{LtiError, Result};

/// A requested eigenvalue set for a real matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct Poles(Vec<C64>);

impl Poles {
    /// Real poles and complex pairs, each pair given once by its member with positive
    /// imaginary part (its conjugate is implied), in the order written.
    pub fn new(real: impl IntoIterator<Item = PoleSpec>) -> Result<Self> {
        let mut v = Vec::new();
        for p in real {
            match p {
                PoleSpec::Real(x) => {
                    if !x.is_finite() {
                        return Err(LtiError::InvalidPoles(format!("{x} is not finite")));
                    }
                    v.push(C64::new(x, 0.0));
                }
                PoleSpec::Pair(re, im) => {
                    if !re.is_finite() || !im.is_finite() {
                        return Err(LtiError::InvalidPoles(format!(
                            "[{re}, {im}] is not finite"
                        )));
                    }
                    if im == 0.0 {
                        v.push(C64::new(re, 0.0));
                    } else {
                        v.push(C64::new(re, im.abs()));
                        v.push(C64::new(re, -im.abs()));
                    }
                }
            }
        }
        Ok(Poles(v))
    }

    /// From a full list that must already be closed under conjugation (pairs adjacent or not).
    pub fn from_values(values: &[C64]) -> Result<Self> {
        let mut out = Vec::with_capacity(values.len());
        let mut used = vec![false; values.len()];
        for i in 0..values.len() {
            if used[i] {
                continue;
            }
            let p = values[i];
            used[i] = true;
            if p.im == 0.0 {
                out.push(p);
                continue;
            }
            let partner = (0..values.len()).find(|&j| !used[j] && values[j] == p.conj());
            match partner {
                Some(j) => {
                    used[j] = true;
                    out.push(C64::new(p.re, p.im.abs()));
                    out.push(C64::new(p.re, -p.im.abs()));
                }
                None => {
                    return Err(LtiError::InvalidPoles(format!(
                        "complex pole {} has no conjugate",
                        crate::eig::format_one(p, false)
                    )));
                }
            }
        }
        Ok(Poles(out))
    }

    /// All eigenvalues, conjugates included, pairs adjacent (positive imaginary part first).
    pub fn values(&self) -> &[C64] {
        &self.0
    }

    /// Number of eigenvalues, conjugates included.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when there are no poles.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The largest number of times one value occurs.
    pub fn max_multiplicity(&self) -> (C64, usize) {
        let mut best = (C64::new(0.0, 0.0), 0);
        for p in &self.0 {
            let k = self.0.iter().filter(|q| *q == p).count();
            if k > best.1 {
                best = (*p, k);
            }
        }
        best
    }

    /// The sampled-data image z = e^{p·dt} of each pole, in the same order.
    pub fn to_discrete(&self, dt: f64) -> Poles {
        Poles(self.0.iter().map(|p| (p * dt).exp()).collect())
    }
}

/// Complex numbers as [re, im] pairs (how reports and JSON write poles).
pub fn re_im(v: &[C64]) -> Vec<[f64; 2]> {
    v.iter().map(|p| [p.re, p.im]).collect()
}

/// One entry of a pole list as a user writes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PoleSpec {
    /// A real pole.
    Real(f64),
    /// A complex pair re ± j·im.
    Pair(f64, f64),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pair_expands_to_conjugates() {
        let p = Poles::new([PoleSpec::Real(-1.0), PoleSpec::Pair(-2.0, -3.0)]).unwrap();
        assert_eq!(
            p.values(),
            &[
                C64::new(-1.0, 0.0),
                C64::new(-2.0, 3.0),
                C64::new(-2.0, -3.0)
            ]
        );
    }

    #[test]
    fn lone_complex_value_is_refused() {
        assert!(Poles::from_values(&[C64::new(-1.0, 2.0), C64::new(-1.0, 0.0)]).is_err());
        assert!(Poles::from_values(&[C64::new(-1.0, -2.0), C64::new(-1.0, 2.0)]).is_ok());
    }

    #[test]
    fn discrete_image() {
        let p = Poles::new([PoleSpec::Real(-2.0)]).unwrap().to_discrete(0.5);
        assert!((p.values()[0].re - (-1.0f64).exp()).abs() < 1e-16);
    }
}
