//! The DARE solver, the steady-state Kalman filter and Van Loan's process-noise covariance
//! against independent values (fixtures/dare-reference.json, made by
//! scripts/fixtures/dare_reference.py): scipy's `solve_discrete_are` and `quad_vec`, and exact
//! values (50-digit Newton-refined DARE solutions; 50-digit series for Q_d), on the sampled seed
//! plants and seeded random systems. Run with --nocapture for the table of errors.
//!
//! Errors are normwise, max |ours − ref| / max |ref| (the measure scipy's accuracy is stated in),
//! unless called entrywise.

#[path = "../../fixtures/reader.rs"]
mod reader;

use lti::{
    LtiError, Mat, discrete_noise_covariance, process_noise_covariance, solve_dare,
    steady_state_kalman,
};
use reader::{mat, max_diff};
use serde_json::Value;

fn rel(ours: &Mat, reference: &Mat) -> f64 {
    max_diff(ours, reference) / reference.amax().max(f64::MIN_POSITIVE)
}

/// max |ours − ref| / max(|ref|, floor) over the entries: each entry against itself, down to a
/// floor (for the entries of X that are zero in exact arithmetic and come out as rounding).
fn entrywise_above(ours: &Mat, reference: &Mat, floor: f64) -> f64 {
    ours.iter()
        .zip(reference.iter())
        .map(|(o, r)| (o - r).abs() / r.abs().max(floor))
        .fold(0.0, f64::max)
}

/// max |ours − ref| / |ref| over the entries, each against itself (an exact zero must be 0).
fn entrywise(ours: &Mat, reference: &Mat) -> f64 {
    ours.iter()
        .zip(reference.iter())
        .map(|(o, r)| {
            if *r == 0.0 {
                if *o == 0.0 { 0.0 } else { f64::INFINITY }
            } else {
                (o - r).abs() / r.abs()
            }
        })
        .fold(0.0, f64::max)
}

fn fixture() -> Value {
    reader::load("../fixtures/dare-reference.json")
}

/// The bar: DARE and Kalman gains equal scipy's to 1e-9. scipy itself is off the
/// exact solution by up to 3.8e-10 here (fixture `_meta.max_rel_errors`; 1.4e-11 on the seeds),
/// and by up to 2e-7 on badly scaled random systems outside the fixture, where this solver still
/// lands on the exact solution: past ~1e-9 the comparison measures scipy.
const VS_SCIPY: f64 = 1e-9;

/// X against the exact solution, each entry against itself (down to a floor of ε‖X‖ for entries
/// that are zero in exact arithmetic). Newton's refinement with a double-double residual takes X
/// to its rounding: measured ≤ 0.93 ε per entry, most cases bit-identical to the correctly
/// rounded solution. Without it (double-precision residual) the seeds were off by up to 7.9e-13
/// normwise — the DARE's conditioning, ~1/(1 − ρ²) ≈ 10³ … 10⁴ at their ρ ≈ 0.998 … 0.9999.
const X_VS_EXACT: f64 = 4.0 * f64::EPSILON;

/// The Kalman gain L = PCᵀ(CPCᵀ + R)⁻¹ is formed in double from that P: its error is the solve's,
/// ~cond(CPCᵀ + R)·ε. Measured ≤ 1.4e-15 (seed 004) normwise.
const L_VS_EXACT: f64 = 1e-14;

#[test]
fn dare_solutions_match_scipy_and_the_exact_solution() {
    let fx = fixture();
    let (mut worst_scipy, mut worst_exact, mut worst_entry, mut worst_res): (f64, f64, f64, f64) =
        (0.0, 0.0, 0.0, 0.0);
    println!(
        "{:<34} {:>10} {:>10} {:>10} {:>10} {:>10} {:>6} {:>9}",
        "case", "vs exact", "entrywise", "vs scipy", "scipy err", "residual", "iters", "ρ(A−BK)"
    );
    for case in fx["dare"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let (a, b, q, r) = (
            mat(&case["A"]),
            mat(&case["B"]),
            mat(&case["Q"]),
            mat(&case["R"]),
        );
        let d = solve_dare(&a, &b, &q, &r).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (exact, scipy) = (mat(&case["X"]), mat(&case["X_scipy"]));
        let (e_exact, e_scipy) = (rel(&d.x, &exact), rel(&d.x, &scipy));
        let entry = entrywise_above(&d.x, &exact, f64::EPSILON * exact.amax());
        println!(
            "{name:<34} {e_exact:>10.2e} {entry:>10.2e} {e_scipy:>10.2e} {:>10.2e} {:>10.2e} {:>6} {:>9.6}",
            rel(&scipy, &exact),
            d.residual,
            format!("{}+{}", d.iterations.0, d.iterations.1),
            d.closed_loop_radius
        );
        assert!(e_scipy <= VS_SCIPY, "{name}: {e_scipy:e} from scipy");
        assert!(
            entry <= X_VS_EXACT,
            "{name}: an entry {entry:e} from the exact solution"
        );
        // The closed loop: Schur-stable, at the exact solution's radius.
        let want = case["closed_loop_radius"].as_f64().unwrap();
        assert!(
            d.closed_loop_radius < 1.0 && (d.closed_loop_radius - want).abs() <= 1e-9,
            "{name}: ρ {} vs {want}",
            d.closed_loop_radius
        );
        // The gain is the one of X, and X is exactly symmetric.
        let k = (&r + b.transpose() * &d.x * &b)
            .lu()
            .solve(&(b.transpose() * &d.x * &a))
            .unwrap();
        assert!(rel(&d.k, &k) < 1e-12, "{name}: K");
        assert_eq!(d.x, d.x.transpose(), "{name}");
        worst_scipy = worst_scipy.max(e_scipy);
        worst_exact = worst_exact.max(e_exact);
        worst_entry = worst_entry.max(entry);
        worst_res = worst_res.max(d.residual);
        // The residual of X is at rounding level.
        assert!(d.residual <= 1e-15, "{name}: residual {:e}", d.residual);
    }
    println!(
        "worst: vs exact {worst_exact:.2e} (entrywise {worst_entry:.2e}), vs scipy {worst_scipy:.2e}, relative residual {worst_res:.2e}"
    );
}

#[test]
fn kalman_gains_match_scipy_and_the_exact_solution() {
    let fx = fixture();
    println!(
        "{:<26} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "case", "P exact", "P scipy", "L exact", "L scipy", "ρ"
    );
    for case in fx["kalman"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let (a, c, qd, r) = (
            mat(&case["A"]),
            mat(&case["C"]),
            mat(&case["Qd"]),
            mat(&case["R"]),
        );
        let k = steady_state_kalman(&a, &c, &qd, &r).unwrap_or_else(|e| panic!("{name}: {e}"));
        let errs = [
            rel(&k.p, &mat(&case["P"])),
            rel(&k.p, &mat(&case["P_scipy"])),
            rel(&k.gain, &mat(&case["L"])),
            rel(&k.gain, &mat(&case["L_scipy"])),
        ];
        println!(
            "{name:<26} {:>10.2e} {:>10.2e} {:>10.2e} {:>10.2e} {:>10.6}",
            errs[0], errs[1], errs[2], errs[3], k.radius
        );
        assert!(
            errs[1] <= VS_SCIPY && errs[3] <= VS_SCIPY,
            "{name}: {errs:?} from scipy"
        );
        let p_entry = entrywise_above(&k.p, &mat(&case["P"]), f64::EPSILON * k.p.amax());
        assert!(
            p_entry <= X_VS_EXACT && errs[2] <= L_VS_EXACT,
            "{name}: {errs:?} from exact, P entrywise {p_entry:e}"
        );
        let want = case["predictor_radius"].as_f64().unwrap();
        assert!(
            k.radius < 1.0 && (k.radius - want).abs() <= 1e-9,
            "{name}: ρ {} vs {want}",
            k.radius
        );
        // The forms agree: predictor gain A L; a posteriori covariance P − L C P; S = CPCᵀ + R.
        assert_eq!(k.predictor_gain, &a * &k.gain);
        let z = &k.p - &k.gain * &c * &k.p;
        assert!(
            rel(&k.p_updated, &z) < 1e-10,
            "{name}: P⁺ {}",
            rel(&k.p_updated, &z)
        );
        assert!(rel(&k.innovation, &(&c * &k.p * c.transpose() + &r)) < 1e-15);
    }
}

/// Van Loan against the exact integral and against scipy's quad_vec (itself within 5e-16 of the
/// exact values here, fixture `_meta`). Measured: 2.4e-16 normwise from exact, 4.9e-16 from
/// quad_vec, so the bounds leave a margin of 4–8 (a few ε: the F₂₂ᵀF₁₂ product and the
/// doubling steps are double precision). Entrywise, each entry against itself, on the seed
/// plants at their own dt — the case the project samples: measured 4.2e-16. Over long steps the
/// doubling's rounding reaches the tiny entries (1.3e-12 on the missile's 500-step case), so
/// those are held to the normwise bound only.
const VL_VS_EXACT: f64 = 2e-15;
const VL_VS_QUAD: f64 = 2e-15;
const VL_ENTRYWISE_AT_DT: f64 = 2e-15;

#[test]
fn van_loan_matches_quadrature_and_the_exact_integral() {
    let fx = fixture();
    let (mut worst_exact, mut worst_quad, mut worst_entry): (f64, f64, f64) = (0.0, 0.0, 0.0);
    println!(
        "{:<28} {:>10} {:>10} {:>10} {:>10}",
        "case", "vs exact", "vs quad", "quad err", "entrywise"
    );
    for case in fx["van_loan"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let (a, g, qc, w) = (
            mat(&case["A"]),
            mat(&case["G"]),
            mat(&case["Qc"]),
            mat(&case["W"]),
        );
        let h = case["h"].as_f64().unwrap();
        let qd = discrete_noise_covariance(&a, &w, h).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (exact, quad) = (mat(&case["Qd"]), mat(&case["Qd_quad"]));
        let (e_exact, e_quad) = (rel(&qd, &exact), rel(&qd, &quad));
        let entry = entrywise(&qd, &exact);
        println!(
            "{name:<28} {e_exact:>10.2e} {e_quad:>10.2e} {:>10.2e} {entry:>10.2e}",
            rel(&quad, &exact)
        );
        assert_eq!(qd, qd.transpose(), "{name}: exactly symmetric");
        assert!(e_exact <= VL_VS_EXACT, "{name}: {e_exact:e} from exact");
        assert!(e_quad <= VL_VS_QUAD, "{name}: {e_quad:e} from quad_vec");
        if name.ends_with("-dt") {
            assert!(
                entry <= VL_ENTRYWISE_AT_DT,
                "{name}: an entry {entry:e} from exact"
            );
        }
        // From G and Q_c: the same up to the rounding of W = G Q_c Gᵀ.
        let from_g = process_noise_covariance(&a, &g, &qc, h).unwrap();
        assert!(
            rel(&from_g, &qd) < 1e-15,
            "{name}: via G {}",
            rel(&from_g, &qd)
        );
        worst_exact = worst_exact.max(e_exact);
        worst_quad = worst_quad.max(e_quad);
        if name.ends_with("-dt") {
            worst_entry = worst_entry.max(entry);
        }
    }
    println!(
        "worst: vs exact {worst_exact:.2e}, vs quad_vec {worst_quad:.2e}, entrywise at dt {worst_entry:.2e}"
    );
}

fn m(rows: usize, cols: usize, v: &[f64]) -> Mat {
    Mat::from_row_slice(rows, cols, v)
}

fn refusal(r: lti::Result<lti::Dare>) -> String {
    match r {
        Ok(d) => panic!("solved: X = {}", d.x),
        Err(e) => e.to_string(),
    }
}

#[test]
fn refuses_an_unstabilisable_pair_naming_the_mode() {
    // Mode 2 of diag(2, 0.5) is not reached by B = e₂.
    let a = m(2, 2, &[2.0, 0.0, 0.0, 0.5]);
    let b = m(2, 1, &[0.0, 1.0]);
    let e = refusal(solve_dare(
        &a,
        &b,
        &Mat::identity(2, 2),
        &Mat::identity(1, 1),
    ));
    assert_eq!(
        e,
        "no stabilising solution: (A, B) is not stabilisable: uncontrollable modes 2 not inside the unit circle"
    );
    // Seed 004's B = 0 with its unstable Jordan block (eigenvalue e^{0.5 dt}, thrice).
    let fx = fixture();
    let s4 = fx["kalman"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "seed004-kalman")
        .unwrap();
    let ad = mat(&s4["A"]);
    let e = refusal(solve_dare(
        &ad,
        &Mat::zeros(3, 1),
        &Mat::identity(3, 3),
        &Mat::identity(1, 1),
    ));
    assert!(
        e.starts_with(
            "no stabilising solution: (A, B) is not stabilisable: uncontrollable modes 1.0005"
        ),
        "{e}"
    );
    // An uncontrollable mode on the circle is as bad: the rotation [[0, 1], [−1, 0]].
    let a = m(3, 3, &[0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.5]);
    let b = m(3, 1, &[0.0, 0.0, 1.0]);
    let e = refusal(solve_dare(
        &a,
        &b,
        &Mat::identity(3, 3),
        &Mat::identity(1, 1),
    ));
    assert_eq!(
        e,
        "no stabilising solution: (A, B) is not stabilisable: uncontrollable modes 0 ± j1 not inside the unit circle"
    );
}

#[test]
fn refuses_a_mode_on_the_unit_circle_that_q_does_not_see() {
    // The integrator mode 1 is controllable but unweighted: the optimal loop leaves it at 1.
    let a = m(2, 2, &[1.0, 0.0, 0.0, 0.5]);
    let b = m(2, 1, &[1.0, 1.0]);
    let q = m(2, 2, &[0.0, 0.0, 0.0, 1.0]);
    let e = refusal(solve_dare(&a, &b, &q, &Mat::identity(1, 1)));
    assert_eq!(
        e,
        "no stabilising solution: (A, Q) has unobservable modes 1 on the unit circle"
    );
    // The filter's words for the same obstruction: noise that does not excite a marginal mode.
    let c = m(1, 2, &[1.0, 1.0]);
    let e = steady_state_kalman(&a, &c, &q, &Mat::identity(1, 1))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "no stabilising solution: the process noise does not excite the modes 1 on the unit circle ((A, Q_d) is not stabilisable there)"
    );
    // And an unobservable unstable mode for the filter.
    let a = m(2, 2, &[1.5, 0.0, 0.0, 0.5]);
    let c = m(1, 2, &[0.0, 1.0]);
    let e = steady_state_kalman(&a, &c, &Mat::identity(2, 2), &Mat::identity(1, 1))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "no stabilising solution: (A, C) is not detectable: unobservable modes 1.5 not inside the unit circle"
    );
}

#[test]
fn refuses_bad_weights_and_non_finite_input() {
    let a = m(2, 2, &[1.1, 0.2, 0.0, 0.9]);
    let b = m(2, 2, &[1.0, 0.0, 0.0, 1.0]);
    let q = Mat::identity(2, 2);
    let e = refusal(solve_dare(&a, &b, &q, &m(2, 2, &[1.0, 0.0, 0.0, 0.0])));
    assert_eq!(
        e,
        "invalid input: R is not positive definite: its eigenvalues range from 0.000e0 to 1.000e0"
    );
    let e = refusal(solve_dare(&a, &b, &q, &m(2, 2, &[1.0, 2.0, 2.0, 1.0])));
    assert_eq!(
        e,
        "invalid input: R is not positive definite: its eigenvalues range from -1.000e0 to 3.000e0"
    );
    let e = refusal(solve_dare(
        &a,
        &b,
        &m(2, 2, &[1.0, 0.0, 0.0, -1e-3]),
        &Mat::identity(2, 2),
    ));
    assert_eq!(
        e,
        "invalid input: Q is not positive semi-definite: its eigenvalues range from -1.000e-3 to 1.000e0"
    );
    let e = refusal(solve_dare(
        &a,
        &b,
        &m(2, 2, &[1.0, 0.1, 0.0, 1.0]),
        &Mat::identity(2, 2),
    ));
    assert_eq!(e, "invalid input: Q is not symmetric");
    let e = refusal(solve_dare(
        &m(2, 2, &[1.0, f64::NAN, 0.0, 1.0]),
        &b,
        &q,
        &Mat::identity(2, 2),
    ));
    assert_eq!(e, "invalid input: A has non-finite entries");
    let e = refusal(solve_dare(&a, &b, &q, &Mat::identity(3, 3)));
    assert_eq!(e, "dimension mismatch: R is 3×3, expected 2×2");
    assert!(matches!(
        solve_dare(&a, &b, &q, &Mat::zeros(2, 2)),
        Err(LtiError::InvalidInput(_))
    ));
    // Van Loan's inputs.
    let e = discrete_noise_covariance(&a, &m(2, 2, &[1.0, 0.0, 0.0, -1.0]), 0.1)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "invalid input: W is not positive semi-definite: its eigenvalues range from -1.000e0 to 1.000e0"
    );
    let e = discrete_noise_covariance(&a, &q, f64::NAN)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "invalid input: the step h = NaN is not a finite non-negative number"
    );
    let e = process_noise_covariance(&a, &m(2, 1, &[1.0, 0.0]), &m(1, 1, &[-1.0]), 0.1)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "invalid input: Q_c is not positive semi-definite: its eigenvalues range from -1.000e0 to -1.000e0"
    );
}
