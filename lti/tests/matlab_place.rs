//! The MATLAB-compatible placement reproduces the gains the seed papers print, which MATLAB's
//! `place` produced (reference values: fixtures/seed-models.json, computed independently).

#[path = "../../fixtures/reader.rs"]
mod common;

use common::{mat, max_diff, seeds};
use lti::pinv::pinv;
use lti::place::{Method, place_observer};
use lti::{Mat, PoleSpec, Poles};

fn real_poles(v: &[f64]) -> Poles {
    Poles::new(v.iter().map(|&p| PoleSpec::Real(p))).unwrap()
}

#[test]
fn seed002_k1_is_matlabs() {
    let s = &seeds()["seed_002"];
    let (a, c, e) = (
        mat(&s["model"]["A"]),
        mat(&s["model"]["C"]),
        mat(&s["model"]["E"]),
    );
    let h = &e * pinv(&(&c * &e));
    let ta = (Mat::identity(3, 3) - &h * &c) * &a;
    let k1 = place_observer(&ta, &c, &real_poles(&[-1.0, -2.0, -3.0]), Method::Matlab).unwrap();
    let want = mat(&s["design"]["K1"]);
    assert!(
        max_diff(&k1.gain, &want) < 1e-9,
        "K1 =\n{}want\n{want}",
        k1.gain
    );
    assert_eq!(k1.sweeps, 5);
    // The robust methods give another, equally valid K1 (non-unique for two outputs).
    let yt = place_observer(&ta, &c, &real_poles(&[-1.0, -2.0, -3.0]), Method::YangTits).unwrap();
    assert!(max_diff(&yt.gain, &want) > 1e-3);
}

#[test]
fn seed001_k_is_matlabs() {
    let s = &seeds()["seed_001"];
    let (a, c) = (mat(&s["model"]["A"]), mat(&s["model"]["C"]));
    let ca = &c * &a;
    let k = place_observer(
        &a,
        &ca,
        &real_poles(&[-47.0, -52.0, -600.0, -700.0]),
        Method::Matlab,
    )
    .unwrap();
    let want = mat(&s["design"]["K_matlab_place (n x m)"]);
    let rel = max_diff(&k.gain, &want) / want.norm();
    assert!(rel < 1e-9, "relative difference {rel:e}\n{}", k.gain);
    // The printed magnitudes: Kᵀ rows 13 510 445 79934 and 3 23 20 95.
    let printed = [[13.0, 510.0, 445.0, 79934.0], [3.0, 23.0, 20.0, 95.0]];
    for (j, row) in printed.iter().enumerate() {
        for (i, &p) in row.iter().enumerate() {
            assert_eq!(
                k.gain[(i, j)].abs().round(),
                p,
                "K[{i},{j}] = {}",
                k.gain[(i, j)]
            );
        }
    }
}
