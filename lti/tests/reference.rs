//! The math core against independent numpy/scipy values
//! (tests/fixtures/reference.json, made by scripts/fixtures/make_reference.py).

#[path = "../../fixtures/reader.rs"]
mod common;

use common::{complex_list, load, mat, max_diff};
use lti::discretize::zoh;
use lti::eig::match_error;
use lti::pinv::{pinv, rank};
use lti::staircase::{ctrb, obsv};
use lti::zeros::decoupling;
use lti::{Mat, lyapunov};

fn rel(a: &Mat, b: &Mat) -> f64 {
    max_diff(a, b) / b.amax().max(f64::MIN_POSITIVE)
}

#[test]
fn zero_order_hold_matches_scipy_expm() {
    let r = load("tests/fixtures/reference.json");
    for case in r["zoh"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let dt = case["dt"].as_f64().unwrap();
        let (a, b, e) = (mat(&case["A"]), mat(&case["B"]), mat(&case["E"]));
        let (ad, bd) = zoh(&a, &b, dt);
        let (_, ed) = zoh(&a, &e, dt);
        assert!(rel(&ad, &mat(&case["Ad"])) < 1e-13, "{name} Ad");
        assert!(
            rel(&bd, &mat(&case["Bd"])) < 1e-12,
            "{name} Bd {}",
            rel(&bd, &mat(&case["Bd"]))
        );
        assert!(rel(&ed, &mat(&case["Ed"])) < 1e-12, "{name} Ed");
    }
}

#[test]
fn pinv_and_rank_follow_numpy() {
    let r = load("tests/fixtures/reference.json");
    for case in r["pinv_rank"]["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let m = mat(&case["M"]);
        assert_eq!(
            rank(&m) as u64,
            case["rank"].as_u64().unwrap(),
            "{name} rank"
        );
        let want = mat(&case["pinv"]);
        assert!(
            max_diff(&pinv(&m), &want) <= 1e-12 * want.amax().max(1.0),
            "{name} pinv"
        );
    }
}

#[test]
fn lyapunov_solutions_match_scipy() {
    let r = load("tests/fixtures/reference.json");
    let c = &r["lyapunov"]["continuous"];
    let p = lyapunov::continuous(&mat(&c["A"]), &mat(&c["Q"])).unwrap();
    assert!(rel(&p, &mat(&c["P"])) < 1e-11);
    let d = &r["lyapunov"]["discrete"];
    let p = lyapunov::discrete(&mat(&d["A"]), &mat(&d["Q"])).unwrap();
    assert!(rel(&p, &mat(&d["P"])) < 1e-9, "{}", rel(&p, &mat(&d["P"])));
}

#[test]
fn controllability_and_observability_matrices() {
    let r = &load("tests/fixtures/reference.json")["ctrb_obsv"];
    let (a, b, c) = (mat(&r["A"]), mat(&r["B"]), mat(&r["C"]));
    assert!(rel(&ctrb(&a, &b), &mat(&r["ctrb"])) < 1e-13);
    assert!(rel(&obsv(&a, &c), &mat(&r["obsv"])) < 1e-13);
    assert_eq!(rank(&ctrb(&a, &b)) as u64, r["rank_ctrb"].as_u64().unwrap());
    assert_eq!(rank(&obsv(&a, &c)) as u64, r["rank_obsv"].as_u64().unwrap());
}

/// Invariant zeros as unobservable modes of (A₁, NC) equal the finite generalized eigenvalues
/// of the Rosenbrock pencil that scipy computed.
#[test]
fn invariant_zeros_match_the_rosenbrock_pencil() {
    let r = load("tests/fixtures/reference.json");
    for case in r["invariant_zeros"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let (a, b, c, d) = (
            mat(&case["A"]),
            mat(&case["B"]),
            mat(&case["C"]),
            mat(&case["D"]),
        );
        // The fixtures write the seed-004 inputs as [B2, 0] with feedthrough [0, D]; split them.
        let (e, dv) = if name.starts_with("seed004") {
            (b.columns(0, 1).into_owned(), d.columns(1, 1).into_owned())
        } else {
            (b.clone(), Mat::zeros(c.nrows(), 0))
        };
        let dec = decoupling(&a, &e, &c, &dv).unwrap();
        assert!(dec.matching(), "{name}");
        let want = complex_list(&case["zeros"]);
        assert_eq!(dec.zeros.len(), want.len(), "{name}: {:?}", dec.zeros);
        assert!(
            match_error(&want, &dec.zeros) < 1e-9,
            "{name}: {:?}",
            dec.zeros
        );
    }
}
