//! State-feedback designs of the seed papers (reference: fixtures/seed-models.json).

use controller::design::{design, FeedbackSpec};
use lti::place::Method;
use lti::{Mat, Model, PoleSpec, Poles, C64};

#[path = "../../fixtures/reader.rs"]
mod reader;
use reader::{mat, seeds};

#[test]
fn seed003_ackermann_gain() {
    let m = &seeds()["seed_003"]["model"];
    let model = Model { a: mat(&m["A"]), b: mat(&m["B"]), c: mat(&m["C"]), e: Mat::zeros(4, 0), d: Mat::zeros(2, 0) };
    let poles = Poles::new([-4.0, -5.0, -6.0, -7.0].map(PoleSpec::Real)).unwrap();
    let fb = design(&model, &FeedbackSpec::Poles { poles, placement: Method::Ackermann }, 1e-3).unwrap();
    let want = [6.00762691997, -28.0996201851, 14.6870142616, -1.54712121541];
    for (i, w) in want.iter().enumerate() {
        assert!((fb.g[(0, i)] - w).abs() < 1e-9, "G[{i}] = {}", fb.g[(0, i)]);
    }
    assert!(fb.stable());
}

#[test]
fn seed000_printed_gain_is_reported_unstable() {
    let m = &seeds()["seed_000"]["model_primary_open_loop"];
    let model = Model { a: mat(&m["A"]), b: mat(&m["B"]), c: mat(&m["C"]), e: mat(&m["Ed"]), d: Mat::zeros(2, 0) };
    let g = Mat::from_row_slice(1, 4, &[5.86, 0.99, 0.0, 0.0]);
    let fb = design(&model, &FeedbackSpec::Gain(g), 1e-4).unwrap();
    assert!(!fb.stable());
    assert_eq!(fb.unstable.len(), 1);
    assert!((fb.unstable[0] - C64::new(122.2708754065, 0.0)).norm() < 1e-6, "{:?}", fb.unstable);
    let why = fb.instability().unwrap();
    assert!(why.contains("122.271"), "{why}");
}
