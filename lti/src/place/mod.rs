//! Eigenvalue assignment: state-feedback gains K with eig(A − BK) = P, and by duality observer
//! gains L with eig(A − LC) = P (L = Kᵀ for the pair (Aᵀ, Cᵀ)).
//!
//! Four methods:
//! * [`Method::YangTits`] — Tits & Yang (1996), scipy's default; robust, any controllable pair.
//! * [`Method::Knv0`] — Kautsky, Nichols & Van Dooren (1985) method 0, iterated to convergence.
//! * [`Method::Matlab`] — KNV method 0 exactly as MATLAB's `place` runs it: 5 sweeps over the
//!   poles in the order given, each eigenvector starting from the first vector of its basis.
//!   It returns the gain MATLAB returns (seeds 001 and 002 print such gains).
//! * [`Method::Ackermann`] — Ackermann's formula, single input only.
//!
//! Every placement checks the eigenvalues it achieved and fails if they are off. A sampled loop's
//! poles crowded at z = 1 are placed in the δ-domain ([`place_sampled`]).

mod ackermann;
mod delta;
mod eigenstructure;
mod knv0;
mod yang_tits;

use nalgebra::DMatrix;

pub use ackermann::{ackermann, characteristic_polynomial};
pub use delta::{delta_pole, place_sampled};
pub use eigenstructure::Eigenstructure;
pub use knv0::{Sweeps, knv0};
pub use yang_tits::yang_tits;

use crate::eig::{C64, eigenvalues, format_list, match_error};
use crate::error::{LtiError, Result};
use crate::pinv::rank;
use crate::poles::Poles;
use crate::staircase::controllability_staircase;

/// Largest relative error |achieved − requested| / max(1, |requested|) a placement may leave.
pub const PLACEMENT_RTOL: f64 = 1e-6;

/// A pole-placement method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Tits–Yang robust assignment (scipy's default "YT").
    YangTits,
    /// KNV method 0 until |det X| settles (scipy's "KNV0").
    Knv0,
    /// MATLAB-compatible: KNV method 0, 5 sweeps, poles in the order given.
    Matlab,
    /// Ackermann's formula (single input).
    Ackermann,
}

/// A placed gain and what it achieved.
#[derive(Debug, Clone)]
pub struct Placed {
    /// K (m×n) for state feedback, L (n×p) for an observer.
    pub gain: DMatrix<f64>,
    /// eig(A − BK) (or eig(A − LC)), sorted.
    pub achieved: Vec<C64>,
    /// Sweeps the iterative method ran (0 for direct methods).
    pub sweeps: usize,
}

/// K with eig(A − BK) = poles.
pub fn place(a: &DMatrix<f64>, b: &DMatrix<f64>, poles: &Poles, method: Method) -> Result<Placed> {
    place_pair(a, b, poles, method, "(A, B)", "controllable")
}

/// L with eig(A − LC) = poles (placement on the dual pair (Aᵀ, Cᵀ)).
pub fn place_observer(
    a: &DMatrix<f64>,
    c: &DMatrix<f64>,
    poles: &Poles,
    method: Method,
) -> Result<Placed> {
    let mut p = place_pair(
        &a.transpose(),
        &c.transpose(),
        poles,
        method,
        "(A, C)",
        "observable",
    )?;
    p.gain = p.gain.transpose();
    Ok(p)
}

// one job: one placement: the checks of the pair and the poles, the method's gain, and the achieved
// poles verified, in that order.
fn place_pair(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    poles: &Poles,
    method: Method,
    pair: &str,
    property: &'static str,
) -> Result<Placed> {
    let n = a.nrows();
    if a.ncols() != n || b.nrows() != n {
        return Err(LtiError::Dimension(format!(
            "A is {}×{}, B is {}×{}",
            a.nrows(),
            a.ncols(),
            b.nrows(),
            b.ncols()
        )));
    }
    if poles.len() != n {
        return Err(LtiError::InvalidPoles(format!(
            "{} poles given for {} states",
            poles.len(),
            n
        )));
    }
    // A B of rank n makes the pair controllable: the staircase, a large model's costliest step,
    // is only needed below that.
    let r = rank(b);
    if r < n {
        let stairs = controllability_staircase(a, b);
        if stairs.nc < n {
            return Err(LtiError::NotAssignable {
                what: pair.to_string(),
                property,
                modes: format_list(&stairs.uncontrollable_modes()?),
            });
        }
    }
    // Work with a full-column-rank input matrix B W (W: right singular vectors of B).
    let (b_used, w) = if r < b.ncols() {
        let svd = b.clone().svd(false, true);
        let w = svd.v_t.expect("requested Vᵀ").rows(0, r).transpose();
        (b * &w, Some(w))
    } else {
        (b.clone(), None)
    };
    let (p, k) = poles.max_multiplicity();
    // Eigenstructure methods need m independent eigenvectors per pole; Ackermann does not.
    if method != Method::Ackermann && k > r {
        return Err(LtiError::InvalidPoles(format!(
            "{} is repeated {} times; at most rank = {} repetitions can be placed",
            crate::eig::format_one(p, true),
            k,
            r
        )));
    }
    // The robust methods take the poles as scipy orders them (real ascending, then pairs).
    let ordered = if matches!(method, Method::Knv0 | Method::YangTits) {
        scipy_order(poles.values())
    } else {
        poles.values().to_vec()
    };
    let values = &ordered[..];
    // κ(X) of the closed loop's eigenvectors, where the method chose them: how far the
    // placed spectrum is from what rounding can hold (the achieved poles move by up to κ·ε·‖A‖).
    let kappa = |x: &DMatrix<C64>| {
        let sv = x.clone().svd(false, false).singular_values;
        sv.max() / sv.min()
    };
    let (gain, sweeps, cond) = match method {
        Method::Ackermann => (ackermann(a, &b_used, values)?, 0, None),
        // rank B = n: any X works; with X = I, K = B⁻¹(A − Λ_R), Λ_R the real block-diagonal form.
        _ if r == n => (direct(a, &b_used, values)?, 0, None),
        Method::Matlab => {
            let es = Eigenstructure::new(a, &b_used, values)?;
            let x0 = initial_x(&es, false);
            let (x, sweeps) = knv0(&es, x0, Sweeps::Exactly(5));
            (es.gain(a, &x)?, sweeps, Some(kappa(&x)))
        }
        Method::Knv0 => {
            let es = Eigenstructure::new(a, &b_used, values)?;
            let x0 = initial_x(&es, true);
            let (x, sweeps) = knv0(
                &es,
                x0,
                Sweeps::UntilConverged {
                    rtol: 1e-3,
                    max: 30,
                },
            );
            (es.gain(a, &x)?, sweeps, Some(kappa(&x)))
        }
        Method::YangTits => {
            let es = Eigenstructure::new(a, &b_used, values)?;
            let x0 = initial_x(&es, true);
            let (x, sweeps) = yang_tits(&es, x0, 1e-3, 30);
            (es.gain(a, &x)?, sweeps, Some(kappa(&x)))
        }
    };
    let gain = match w {
        Some(w) => w * gain,
        None => gain,
    };
    let achieved = eigenvalues(&(a - b * &gain))?;
    let error = match_error(values, &achieved);
    if error.is_nan() || error > PLACEMENT_RTOL {
        let mut how = format!("max |gain entry| {}", crate::eig::sig(gain.amax()));
        if let Some(c) = cond {
            how.push_str(&format!(
                ", eigenvector condition number κ(X) = {}",
                crate::eig::sig(c)
            ));
        }
        return Err(LtiError::PlacementMissed {
            requested: format_list(values),
            achieved: format_list(&achieved),
            error,
            how,
        });
    }
    Ok(Placed {
        gain,
        achieved,
        sweeps,
    })
}

/// K = B⁻¹(A − Λ_R) for an invertible B, with Λ_R block-diagonal: a real pole on the diagonal,
/// a pair a ± jb as the block [a −b; b a].
fn direct(a: &DMatrix<f64>, b: &DMatrix<f64>, values: &[C64]) -> Result<DMatrix<f64>> {
    let n = a.nrows();
    let mut lambda = DMatrix::<f64>::zeros(n, n);
    let mut i = 0;
    while i < n {
        let p = values[i];
        lambda[(i, i)] = p.re;
        if p.im != 0.0 {
            lambda[(i, i + 1)] = -p.im;
            lambda[(i + 1, i)] = p.im;
            lambda[(i + 1, i + 1)] = p.re;
            i += 1;
        }
        i += 1;
    }
    b.clone()
        .lu()
        .solve(&(a - lambda))
        .ok_or(LtiError::Singular("B"))
}

/// Initial eigenvectors: the first basis vector of each 𝒮ⱼ (MATLAB), or, for the robust
/// methods, the normalised sum of the basis vectors (scipy: no structurally zero row, and a
/// genuinely complex start for complex poles).
fn initial_x(es: &Eigenstructure, summed: bool) -> DMatrix<C64> {
    let n = es.poles.len();
    let mut x = DMatrix::<C64>::zeros(n, n);
    for j in 0..n {
        let v = if summed {
            es.s[j].column_sum()
        } else {
            es.s[j].column(0).into_owned()
        };
        let norm = v.norm();
        x.set_column(j, &(v / C64::new(norm, 0.0)));
    }
    x
}

/// Real poles ascending, then complex pairs by (re, |im|), each pair as (λ, λ̄) with Im λ > 0.
fn scipy_order(values: &[C64]) -> Vec<C64> {
    let mut real: Vec<C64> = values.iter().copied().filter(|p| p.im == 0.0).collect();
    real.sort_by(|a, b| a.re.total_cmp(&b.re));
    let mut upper: Vec<C64> = values.iter().copied().filter(|p| p.im > 0.0).collect();
    upper.sort_by(|a, b| a.re.total_cmp(&b.re).then(b.im.total_cmp(&a.im)));
    real.into_iter()
        .chain(upper.into_iter().flat_map(|p| [p, p.conj()]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::poles::PoleSpec;

    fn poles(v: &[f64]) -> Poles {
        Poles::new(v.iter().map(|&x| PoleSpec::Real(x))).unwrap()
    }

    #[test]
    fn every_method_places_a_single_input_pair() {
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 3.0]);
        let b = DMatrix::from_row_slice(3, 1, &[0.0, 0.0, 1.0]);
        let p = poles(&[-1.0, -2.0, -3.0]);
        let gains: Vec<_> = [
            Method::Ackermann,
            Method::Matlab,
            Method::Knv0,
            Method::YangTits,
        ]
        .iter()
        .map(|&m| place(&a, &b, &p, m).unwrap().gain)
        .collect();
        // Single input: the gain is unique, so all methods agree.
        for g in &gains[1..] {
            assert!((g - &gains[0]).norm() < 1e-9 * gains[0].norm());
        }
    }

    #[test]
    fn uncontrollable_pair_is_named() {
        let a = DMatrix::from_row_slice(2, 2, &[-1.0, 0.0, 0.0, -2.0]);
        let b = DMatrix::from_row_slice(2, 1, &[1.0, 0.0]);
        let err = place(&a, &b, &poles(&[-3.0, -4.0]), Method::YangTits).unwrap_err();
        assert!(err.to_string().contains("-2"), "{err}");
    }

    #[test]
    fn too_many_repeats_are_refused() {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        assert!(matches!(
            place(&a, &b, &poles(&[-1.0, -1.0]), Method::Knv0),
            Err(LtiError::InvalidPoles(_))
        ));
    }
}
