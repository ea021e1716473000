//! Φ = e^{Ah} and the augmented Γ blocks of every seed plant against 40-digit values
//! (fixtures/expm-reference.json, made by scripts/fixtures/expm_reference.py with mpmath).
//!
//! The bound is 1 ulp of each entry, however small beside the rest of the matrix: expm works in
//! double-double and rounds once, so its error is its final rounding (≤ 0.5 ulp) plus ~10⁻³⁰
//! relative; 1 ulp leaves room for a value within that of a rounding midpoint, and for
//! regenerated references, while nalgebra's double-precision `exp()` (the previous code, shown
//! for comparison with --nocapture) misses it by thousands of ulps on the stiff missile.

#[path = "../../fixtures/reader.rs"]
mod reader;

use lti::discretize::{exp_upper, zoh};
use lti::{Mat, Model};
use serde_json::Value;

/// Spacing of doubles just below |x| (the smaller one at a power of two: conservative).
fn ulp(x: f64) -> f64 {
    let a = x.abs();
    a - a.next_down()
}

/// Largest |ours − exact| in ulps of the exact value, with the exact value as hi + lo; an exact
/// zero must come out exactly zero (infinite error otherwise).
fn max_ulps(ours: &Mat, hi: &Mat, lo: &Mat) -> (f64, (usize, usize)) {
    assert_eq!(ours.shape(), hi.shape());
    let mut worst = (0.0, (0, 0));
    for i in 0..hi.nrows() {
        for j in 0..hi.ncols() {
            let (o, h, l) = (ours[(i, j)], hi[(i, j)], lo[(i, j)]);
            let e = if h == 0.0 {
                if o == 0.0 { 0.0 } else { f64::INFINITY }
            } else {
                ((o - h) - l).abs() / ulp(h)
            };
            if e > worst.0 {
                worst = (e, (i, j));
            }
        }
    }
    worst
}

/// [[A, G], [0, W]] (the block the code exponentiates), for nalgebra's exp().
fn augmented(a: &Mat, g: &Mat, w: &Mat) -> Mat {
    let (n, k) = (a.nrows(), w.nrows());
    let mut big = Mat::zeros(n + k, n + k);
    big.view_mut((0, 0), (n, n)).copy_from(a);
    big.view_mut((0, n), (n, k)).copy_from(g);
    big.view_mut((n, n), (k, k)).copy_from(w);
    big
}

/// (name, ours, nalgebra's) for every block the fixture tabulates.
fn blocks(case: &Value) -> Vec<(String, Mat, Mat)> {
    let (a, b, e) = (
        reader::mat(&case["A"]),
        reader::mat(&case["B"]),
        reader::mat(&case["E"]),
    );
    let h = case["h"].as_f64().unwrap();
    let n = a.nrows();
    let e = if e.ncols() == 0 { Mat::zeros(n, 0) } else { e };
    let old = |g: &Mat, w: &Mat| (augmented(&a, g, w) * h).exp();
    let mut out = Vec::new();
    // Φ, B_d, E_d through the path the plant and every observer design use.
    let dm = Model {
        a: a.clone(),
        b: b.clone(),
        c: Mat::zeros(0, n),
        e: e.clone(),
        d: Mat::zeros(0, 0),
    }
    .discretize(h);
    let ob = old(&b, &Mat::zeros(b.ncols(), b.ncols()));
    out.push((
        "Phi".into(),
        dm.a.clone(),
        ob.view((0, 0), (n, n)).into_owned(),
    ));
    out.push((
        "Gamma_B".into(),
        dm.b.clone(),
        ob.view((0, n), (n, b.ncols())).into_owned(),
    ));
    assert_eq!(zoh(&a, &b, h).1, dm.b);
    if e.ncols() > 0 {
        let oe = old(&e, &Mat::zeros(e.ncols(), e.ncols()));
        out.push((
            "Gamma_E".into(),
            dm.e.clone(),
            oe.view((0, n), (n, e.ncols())).into_owned(),
        ));
    }
    // The sine generator's block, built as plant::Plant::new builds it.
    for s in case["sines"].as_array().unwrap() {
        let i = s["disturbance"].as_u64().unwrap() as usize;
        let (amp, omega) = (
            s["amplitude"].as_f64().unwrap(),
            s["omega"].as_f64().unwrap(),
        );
        let mut g = Mat::zeros(n, 2);
        g.set_column(0, &(e.column(i) * amp));
        let w = Mat::from_row_slice(2, 2, &[0.0, omega, -omega, 0.0]);
        let (_, gj) = exp_upper(&a, &g, &w, h);
        out.push((
            format!("Gamma_S{i}"),
            gj,
            old(&g, &w).view((0, n), (n, 2)).into_owned(),
        ));
    }
    out
}

#[test]
fn exponentials_are_within_an_ulp_of_40_digit_values() {
    let r = reader::load("../fixtures/expm-reference.json");
    let mut failures = Vec::new();
    println!(
        "{:<26} {:<9} {:>14} {:>16}",
        "case", "block", "ulps (expm)", "ulps (nalgebra)"
    );
    for case in r["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let mut seen = 0;
        for (key, ours, old) in blocks(case) {
            let (hi, lo) = (
                reader::mat(&case[key.as_str()]),
                reader::mat(&case[format!("{key}_lo").as_str()]),
            );
            let (e, at) = max_ulps(&ours, &hi, &lo);
            let (eo, _) = max_ulps(&old, &hi, &lo);
            println!("{name:<26} {key:<9} {e:>14.2} {eo:>16.2}");
            if e > 1.0 {
                failures.push(format!(
                    "{name} {key}{at:?}: {e:.2} ulps ({} vs {})",
                    ours[at], hi[at]
                ));
            }
            seen += 1;
        }
        // Every block the fixture has was checked.
        let tabulated = case
            .as_object()
            .unwrap()
            .keys()
            .filter(|k| (k.starts_with("Phi") || k.starts_with("Gamma")) && !k.ends_with("_lo"))
            .count();
        assert_eq!(seen, tabulated, "{name}");
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The fixture covers the stiff seeds it is meant to: both missile plants, a full step and a piece.
#[test]
fn fixture_covers_the_stiff_seeds() {
    let r = reader::load("../fixtures/expm-reference.json");
    let names: Vec<&str> = r["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    for want in [
        "seed000-missile",
        "seed001-missile",
        "seed000-missile-h0.3dt",
        "seed002",
        "seed003-charlie",
        "seed004",
    ] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
}
