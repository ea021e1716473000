//! The existence conditions of unknown-input observers: the rank (matching) condition and the
//! invariant zeros of the map from the unknown inputs to the outputs.
//!
//! System ẋ = Ax + Ew, y = Cx + Dv, with w (state disturbance) and v (measurement disturbance)
//! unknown; D may have no columns. With the projection of Hui & Żak (seed 004),
//!
//! ```text
//! M = [E 0] [CE D]⁺,   A₁ = (I − MC) A,   N = a basis of the left null space of D (N = I if D = ∅),
//! ```
//!
//! M[CE D] = [E 0] holds exactly when rank [CE D] = rank E + rank D (the matching condition;
//! for D = ∅ it is rank CE = rank E, and M is Chen & Patton's H = E(CE)⁺, A₁ = TA).
//! Under that condition the invariant zeros of (A, [E 0], C, [0 D]) are exactly the
//! unobservable modes of (A₁, NC):
//!
//! * a zero z with (zI − A)x₀ = Ew, Cx₀ + Dv = 0 gives A₁x₀ = z x₀ − zMCx₀ − (I − MC)Ew = z x₀
//!   (MD = 0, (I − MC)E = 0) and NCx₀ = −NDv = 0: an unobservable eigenvector of (A₁, NC);
//! * conversely A₁x₀ = z x₀ with NCx₀ = 0 gives Cx₀ ∈ range D and (zI − A)x₀ = −MCAx₀ ∈ range E.
//!
//! An observer gain L with LD = 0 has the form L = L̃N, so eig(A₁ − LC) always contains these
//! zeros: the observer exists iff they are stable (Darouach 1994; Hui & Żak 2005).

use nalgebra::DMatrix;

use crate::eig::C64;
use crate::error::{LtiError, Result};
use crate::pinv::rank;
use crate::staircase::{ObservabilityStaircase, observability_staircase};
use crate::subspace::left_null_space;

/// The decoupling structure of (A, E, C, D).
#[derive(Debug, Clone)]
pub struct Decoupling {
    /// rank [CE D].
    pub rank_ced: usize,
    /// rank E + rank D.
    pub rank_e_plus_d: usize,
    /// M = [E 0][CE D]⁺ (n×p).
    pub m: DMatrix<f64>,
    /// A₁ = (I − MC)A.
    pub a1: DMatrix<f64>,
    /// N: rows spanning {l : lD = 0} (p×p identity when D has no columns).
    pub n: DMatrix<f64>,
    /// Staircase of (A₁, NC).
    pub staircase: ObservabilityStaircase,
    /// Invariant zeros (unobservable modes of (A₁, NC)), sorted.
    pub zeros: Vec<C64>,
}

impl Decoupling {
    /// The matching condition rank [CE D] = rank E + rank D.
    pub fn matching(&self) -> bool {
        self.rank_ced == self.rank_e_plus_d
    }
}

/// Computes M, A₁, N and the invariant zeros. `d` may be p×0.
pub fn decoupling(
    a: &DMatrix<f64>,
    e: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
) -> Result<Decoupling> {
    let n = a.nrows();
    let p = c.nrows();
    if e.nrows() != n || c.ncols() != n || d.nrows() != p {
        return Err(LtiError::Dimension("E, C, D do not conform with A".into()));
    }
    let q = e.ncols();
    let r = d.ncols();
    let ce = c * e;
    let mut ced = DMatrix::<f64>::zeros(p, q + r);
    ced.columns_mut(0, q).copy_from(&ce);
    ced.columns_mut(q, r).copy_from(d);
    let mut e0 = DMatrix::<f64>::zeros(n, q + r);
    e0.columns_mut(0, q).copy_from(e);
    let m = crate::pinv::right_solve(&e0, &ced);
    let a1 = (DMatrix::<f64>::identity(n, n) - &m * c) * a;
    let nrows = if r == 0 {
        DMatrix::<f64>::identity(p, p)
    } else {
        left_null_space(d)
    };
    let staircase = observability_staircase(&a1, &(&nrows * c));
    let zeros = staircase.unobservable_modes()?;
    Ok(Decoupling {
        rank_ced: rank(&ced),
        rank_e_plus_d: rank(e) + rank(d),
        m,
        a1,
        n: nrows,
        staircase,
        zeros,
    })
}
