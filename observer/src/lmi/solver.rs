//! The Hui–Żak LMI (seed 004) as a semidefinite feasibility problem, solved with Clarabel:
//!
//! ```text
//! find P = Pᵀ, Y   with   A₁ᵀP + PA₁ − CᵀYᵀ − YC + αP ⪯ 0,   P ⪰ 0.01 I,   YD = 0,
//! ```
//!
//! then L = P⁻¹Y. In Clarabel's form Ax + s = b, s ∈ K: the unknowns are the upper triangle of
//! P and the columns of Y; each PSD constraint is a `PSDTriangleConeT` on the upper triangle of
//! its matrix, column by column, off-diagonal entries scaled by √2; YD = 0 is a zero cone.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use lti::Mat;
use lti::pinv::pinv;

use super::LmiSolution;

/// Upper triangle of a symmetric matrix, column by column, off-diagonals × √2.
fn svec(m: &Mat) -> Vec<f64> {
    let n = m.nrows();
    let mut out = Vec::with_capacity(n * (n + 1) / 2);
    for j in 0..n {
        for i in 0..=j {
            out.push(if i == j {
                m[(i, j)]
            } else {
                m[(i, j)] * std::f64::consts::SQRT_2
            });
        }
    }
    out
}

/// Solves the LMI for the decay rate `decay`.
pub fn solve(a1: &Mat, c: &Mat, d: &Mat, decay: f64) -> Result<LmiSolution, String> {
    let (n, p, r) = (a1.nrows(), c.nrows(), d.ncols());
    let np = n * (n + 1) / 2;
    let nvar = np + n * p;
    // The value of (P, Y) for unit vector e_v of the unknowns.
    let basis = |v: usize| -> (Mat, Mat) {
        let mut pm = Mat::zeros(n, n);
        let mut ym = Mat::zeros(n, p);
        if v < np {
            let mut idx = 0;
            'outer: for j in 0..n {
                for i in 0..=j {
                    if idx == v {
                        pm[(i, j)] = 1.0;
                        pm[(j, i)] = 1.0;
                        break 'outer;
                    }
                    idx += 1;
                }
            }
        } else {
            let k = v - np;
            ym[(k % n, k / n)] = 1.0;
        }
        (pm, ym)
    };
    let lmi = |pm: &Mat, ym: &Mat| {
        a1.transpose() * pm + pm * a1 - c.transpose() * ym.transpose() - ym * c + pm * decay
    };
    let rows = 2 * np + n * r;
    let mut dense = vec![vec![0.0; nvar]; rows];
    // v indexes a column of every row, not an element of one: no iterator replaces it.
    #[allow(clippy::needless_range_loop)]
    for v in 0..nvar {
        let (pm, ym) = basis(v);
        for (i, x) in svec(&lmi(&pm, &ym)).into_iter().enumerate() {
            dense[i][v] = x; // s = −svec(M)
        }
        for (i, x) in svec(&pm).into_iter().enumerate() {
            dense[np + i][v] = -x; // s = svec(P) − 0.01·svec(I)
        }
        let yd = &ym * d;
        for (i, x) in yd.iter().enumerate() {
            dense[2 * np + i][v] = *x; // YD = 0
        }
    }
    let mut b = vec![0.0; rows];
    let eye = svec(&Mat::identity(n, n));
    for (i, x) in eye.into_iter().enumerate() {
        b[np + i] = -0.01 * x;
    }
    let a = CscMatrix::from(&dense);
    let q = vec![0.0; nvar];
    let pq = CscMatrix::zeros((nvar, nvar));
    let mut cones = vec![
        SupportedConeT::PSDTriangleConeT(n),
        SupportedConeT::PSDTriangleConeT(n),
    ];
    if n * r > 0 {
        cones.push(SupportedConeT::ZeroConeT(n * r));
    }
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .build()
        .map_err(|e| e.to_string())?;
    let mut solver =
        DefaultSolver::new(&pq, &q, &a, &b, &cones, settings).map_err(|e| format!("{e:?}"))?;
    solver.solve();
    if !matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ) {
        return Err(format!("Clarabel: {:?}", solver.solution.status));
    }
    let x = &solver.solution.x;
    let mut pm = Mat::zeros(n, n);
    let mut ym = Mat::zeros(n, p);
    for (v, &xv) in x.iter().enumerate() {
        let (bp, by) = basis(v);
        pm += bp * xv;
        ym += by * xv;
    }
    // Remove the solver's residual in YD = 0 exactly: Y ← Y(I − DD⁺).
    if r > 0 {
        ym = &ym * (Mat::identity(p, p) - d * pinv(d));
    }
    Ok(LmiSolution { p: pm, y: ym })
}
