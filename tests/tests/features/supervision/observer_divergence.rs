//! An observer whose error leaves the plant's state bound stops the run as a
//! diverging plant does — exit 4, the observer named, the recording and summary finalised,
//! nothing left behind — instead of a run that exits 0 with a figure of 1e12. Here the error
//! starts beyond the bound (x̂₀ is 50 off, the bound is 10): the check is the same at any step.

use tests::*;

const PLANT: &str = concat!(
    r#"
name = "observer-divergence"
dt = 0.001
duration = 1.0

[plant]
"#,
    // The seed-002 plant (scenarios/seed002-*.toml), shared by the tests that need a small UIO plant.
    include_str!("../../../../fixtures/seed002_plant.toml"),
    r#"x0 = [1.0, -1.0, 2.0]
state_bound = 10.0

[[disturbance]]
kind = "constant"
value = 0.0

[[input]]
kind = "constant"
value = 0.0

[[input]]
kind = "constant"
value = 0.0

[[observer]]
name = "sound"
kind = "luenberger"
poles = [-1.0, -2.0, -3.0]

[[observer]]
name = "far-off"
kind = "luenberger"
poles = [-1.0, -2.0, -3.0]
xhat0 = [1.0, 49.0, 2.0]
"#
);

#[test]
fn an_observer_whose_error_leaves_the_state_bound_stops_the_run_with_exit_4_naming_it() {
    for mode in ["processes", "in-process"] {
        let s = Scratch::new(&format!("observer-divergence-{mode}"));
        let path = s.join("observer-divergence.toml");
        std::fs::write(&path, PLANT).unwrap();
        let (code, err, _) = run_checked(&s, &path, &["--mode", mode]);
        assert_eq!(code, Some(4), "{mode}: {err}");
        assert!(
            err.contains("observer 'far-off'") && err.contains("x̂2 − x2"),
            "{mode}: {err}"
        );
        assert!(!err.contains("'sound'"), "{mode}: {err}");
        let sum = summary(&s, "observer-divergence");
        assert!(
            sum["stopped"].as_str().unwrap().contains("far-off"),
            "{mode}: {sum}"
        );
    }
}
