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
        disturbances: vec![Signal::Sine {
            amplitude: 1.0,
            frequency_hz: 0.5,
            phase: 0.3,
            offset: 0.25,
        }],
        measurement_disturbances: vec![],
        inputs: vec![
            Signal::Constant { value: 0.5 },
            Signal::Constant { value: -0.2 },
        ],
        dt: 1e-3,
        steps: 1000,
        state_bound: 1e9,
        ff: lti::MatData {
            rows: 0,
            cols: 0,
            data: vec![],
        },
        faults: vec![],
        noise: None,
        discrete: false,
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
    let cfg = scalar(
        Signal::Piecewise {
            times: vec![0.0, 1.5e-3, 2.7e-3],
            values: vec![0.0, 1.0, -2.0],
        },
        10,
    );
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
        assert!(
            (x - exact(k as f64 * 1e-3)).abs() < 1e-15,
            "k = {k}: {x} vs {}",
            exact(k as f64 * 1e-3)
        );
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
        ff: lti::MatData {
            rows: 0,
            cols: 0,
            data: vec![],
        },
        faults: vec![],
        noise: None,
        discrete: false,
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
    assert!(err.to_string().starts_with("x1 = "), "{err}");
    assert_eq!(err.step, 1); // e^{10} ≈ 2.2e4, e^{20} ≈ 4.9e8 > 1e6
    assert!(err.to_string().contains("step 2"), "{err}");
}

/// ẋ = −x + w, y = x, x(0) = 0, dt = 1 ms, for `steps` steps.
fn scalar(w: Signal, steps: u64) -> PlantConfig {
    PlantConfig {
        a: md(1, 1, &[-1.0]),
        b: md(1, 1, &[0.0]),
        c: md(1, 1, &[1.0]),
        e: md(1, 1, &[1.0]),
        d: md(1, 0, &[]),
        x0: vec![0.0],
        disturbances: vec![w],
        measurement_disturbances: vec![],
        inputs: vec![Signal::Constant { value: 0.0 }],
        dt: 1e-3,
        steps,
        state_bound: 1e9,
        ff: lti::MatData {
            rows: 0,
            cols: 0,
            data: vec![],
        },
        faults: vec![],
        noise: None,
        discrete: false,
    }
}

/// [`scalar`] with w a step 0 → 1 at `time`, run to sample 5001.
fn scalar_step_plant(time: f64) -> (Vec<f64>, Vec<f64>) {
    let cfg = scalar(
        Signal::Step {
            time,
            before: 0.0,
            after: 1.0,
        },
        5002,
    );
    let mut plant = Plant::new(&cfg).unwrap();
    let w_at = plant.layout().w().start;
    let (mut x, mut w) = (Vec::new(), Vec::new());
    for k in 0..=5001u64 {
        let row = plant.sample(k);
        x.push(row[0]);
        w.push(row[w_at]);
        plant.advance(k, &[0.0]).unwrap();
    }
    (x, w)
}

/// A switching time 10⁻¹³ s after sample 5000 is not on it. Sample 5000 shows
/// the old value, and step 5000 integrates the switch inside it: by hand, x(t₅₀₀₁) =
/// 1 − e^{−(dt − δ)} with δ = 10⁻¹³ (x = 0 up to the switch), which differs from the on-sample
/// value 1 − e^{−dt} by e^{−dt}·δ ≈ 10⁻¹³, a million times the tolerance.
#[test]
fn a_switch_just_after_a_sample_is_made_inside_the_step() {
    let (x, w) = scalar_step_plant(5.0000000000001);
    assert_eq!(
        w[5000], 0.0,
        "w at sample 5000 is the value before the switch"
    );
    assert_eq!(w[5001], 1.0);
    assert_eq!(x[5000], 0.0);
    let exact = -(-(1e-3 - 1e-13f64)).exp_m1();
    assert!(
        (x[5001] - exact).abs() < 1e-18,
        "x(t_5001) = {:e}, exact {exact:e}",
        x[5001]
    );
}

/// A switching time written 5.0 with dt = 0.001 is on sample 5000 (5000 × 0.001 as decimals),
/// whatever binary rounding does: w(t₅₀₀₀) = 1, and step 5000 is a whole step at w = 1.
#[test]
fn a_switch_on_a_sample_is_made_at_that_sample() {
    let (x, w) = scalar_step_plant(5.0);
    assert_eq!((w[4999], w[5000]), (0.0, 1.0));
    assert_eq!(x[5000], 0.0);
    let exact = -(-1e-3f64).exp_m1();
    assert!(
        (x[5001] - exact).abs() < 1e-18,
        "x(t_5001) = {:e}, exact {exact:e}",
        x[5001]
    );
}
