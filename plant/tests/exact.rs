//! The plant integrates exactly: against scipy (solve_ivp DOP853 at rtol 1e-12 and the direct
//! matrix exponential, lti/tests/fixtures/reference.json) and against closed-form solutions.

use lti::signal::Signal;
use lti::{Mat, MatData};
use plant::{Plant, PlantConfig};

#[path = "../../fixtures/reader.rs"]
mod reader;

fn md(rows: usize, cols: usize, v: &[f64]) -> MatData {
    (&Mat::from_row_slice(rows, cols, v)).into()
}

#[test]
fn sinusoidal_disturbance_matches_scipy() {
    let r = reader::load("../lti/tests/fixtures/reference.json");
    let r = &r["sine_step"];
    let cfg = PlantConfig {
        a: md(3, 3, &[0.0, 1.0, 0.0, -2.0, -3.0, 0.0, 0.0, 0.0, -2.0]),
        b: md(3, 2, &[0.0, 0.0, 4.0, 0.0, 0.0, 1.0]),
        c: md(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
        e: md(3, 1, &[2.0, 0.0, 0.5]),
        d: md(2, 0, &[]),
        x0: vec![1.0, -1.0, 2.0],
        disturbances: vec![Signal::Sine { amplitude: 1.0, frequency_hz: 0.5, phase: 0.3, offset: 0.25 }],
        measurement_disturbances: vec![],
        inputs: vec![Signal::Constant { value: 0.5 }, Signal::Constant { value: -0.2 }],
        dt: 1e-3,
        steps: 1000,
        state_bound: 1e9,
    };
    let mut plant = Plant::new(&cfg).unwrap();
    let u = [0.5, -0.2];
    let mut worst: f64 = 0.0;
    for k in 0..=1000u64 {
        let x = plant.sample(k)[0..3].to_vec();
        if let Some(want) = r["x_at_step_solve_ivp"].get(k.to_string()) {
            for (i, w) in want.as_array().unwrap().iter().enumerate() {
                worst = worst.max((x[i] - w.as_f64().unwrap()).abs());
            }
        }
        plant.advance(k, &u).unwrap();
    }
    assert!(worst < 3e-13, "max difference from solve_ivp: {worst:e}");
}

/// ẋ = −x + w with w stepping 0 → 1 at t_b = 1.5 ms, inside the second step: the split step
/// lands on x(t) = 1 − e^{−(t − t_b)} exactly.
#[test]
fn switching_inside_a_step_is_integrated_exactly() {
    let cfg = PlantConfig {
        a: md(1, 1, &[-1.0]),
        b: md(1, 1, &[0.0]),
        c: md(1, 1, &[1.0]),
        e: md(1, 1, &[1.0]),
        d: md(1, 0, &[]),
        x0: vec![0.0],
        disturbances: vec![Signal::Piecewise { times: vec![0.0, 1.5e-3, 2.7e-3], values: vec![0.0, 1.0, -2.0] }],
        measurement_disturbances: vec![],
        inputs: vec![Signal::Constant { value: 0.0 }],
        dt: 1e-3,
        steps: 10,
        state_bound: 1e9,
    };
    let mut plant = Plant::new(&cfg).unwrap();
    let exact = |t: f64| {
        let x_at = 1.0 - (-(2.7e-3f64 - 1.5e-3)).exp();
        if t <= 1.5e-3 {
            0.0
        } else if t <= 2.7e-3 {
            1.0 - (-(t - 1.5e-3)).exp()
        } else {
            -2.0 + (x_at + 2.0) * (-(t - 2.7e-3)).exp()
        }
    };
    for k in 0..10u64 {
        let x = plant.sample(k)[0];
        assert!((x - exact(k as f64 * 1e-3)).abs() < 1e-15, "k = {k}: {x} vs {}", exact(k as f64 * 1e-3));
        plant.advance(k, &[0.0]).unwrap();
    }
}

#[test]
fn divergence_names_the_state_and_step() {
    let cfg = PlantConfig {
        a: md(2, 2, &[1000.0, 0.0, 0.0, -1.0]),
        b: md(2, 1, &[0.0, 0.0]),
        c: md(1, 2, &[1.0, 0.0]),
        e: md(2, 0, &[]),
        d: md(1, 0, &[]),
        x0: vec![1.0, 1.0],
        disturbances: vec![],
        measurement_disturbances: vec![],
        inputs: vec![Signal::Constant { value: 0.0 }],
        dt: 1e-2,
        steps: 100,
        state_bound: 1e6,
    };
    let mut plant = Plant::new(&cfg).unwrap();
    let mut k = 0;
    let err = loop {
        plant.sample(k);
        if let Err(e) = plant.advance(k, &[0.0]) {
            break e;
        }
        k += 1;
    };
    assert_eq!(err.state, 0);
    assert!(err.to_string().starts_with("x[0] = "), "{err}");
    assert_eq!(err.step, 1); // e^{10} ≈ 2.2e4, e^{20} ≈ 4.9e8 > 1e6
    assert!(err.to_string().contains("step 2"), "{err}");
}
