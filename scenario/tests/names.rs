//! Names and units of every signal: optional, one per component, checked for length with a
//! one-line error naming the file and the field; defaults x1…, y1…, r1…, w1…, v1….

use std::path::Path;

use scenario::{Named, Scenario};

const BASE: &str = concat!(
    r#"name = "names"
dt = 0.01
duration = 1.0

[plant]
"#,
    // The seed-002 plant (scenarios/seed002-*.toml), shared by the tests that need a small UIO plant.
    include_str!("../../fixtures/seed002_plant.toml"),
    r#"D = [[1.0], [0.0]]
x0 = [1.0, -1.0, 2.0]

[[disturbance]]
kind = "constant"
value = 0.0

[[measurement_disturbance]]
kind = "constant"
value = 0.0

[[input]]
kind = "constant"
value = 0.0

[[input]]
kind = "constant"
value = 0.0
"#
);

fn with(lines: &str) -> Result<Scenario, String> {
    let text = BASE.replace(
        "x0 = [1.0, -1.0, 2.0]",
        &format!("x0 = [1.0, -1.0, 2.0]\n{lines}"),
    );
    Scenario::parse(Path::new("names.toml"), &text).map_err(|e| e.to_string())
}

fn names(v: &[Named]) -> Vec<String> {
    v.iter().map(Named::with_unit).collect()
}

#[test]
fn defaults_number_every_signal_from_one() {
    let s = with("").unwrap();
    assert_eq!(names(&s.names.state), ["x1", "x2", "x3"]);
    assert_eq!(names(&s.names.output), ["y1", "y2"]);
    assert_eq!(names(&s.names.input), ["r1", "r2"]);
    assert_eq!(names(&s.names.disturbance), ["w1"]);
    assert_eq!(names(&s.names.measurement_disturbance), ["v1"]);
}

#[test]
fn given_names_and_units_are_kept() {
    let s = with(
        "state_names = [\"p\", \"v\", \"u\"]\nstate_units = [\"m\", \"m/s\", \"V\"]\noutput_names = [\"p_m\", \"u_m\"]\noutput_units = [\"m\", \"V\"]\n\
         input_names = [\"f\", \"e\"]\ninput_units = [\"N\", \"V\"]\ndisturbance_names = [\"gust\"]\ndisturbance_units = [\"N\"]\n\
         measurement_disturbance_names = [\"noise\"]\nmeasurement_disturbance_units = [\"m\"]",
    )
    .unwrap();
    assert_eq!(names(&s.names.state), ["p [m]", "v [m/s]", "u [V]"]);
    assert_eq!(names(&s.names.output), ["p_m [m]", "u_m [V]"]);
    assert_eq!(names(&s.names.input), ["f [N]", "e [V]"]);
    assert_eq!(names(&s.names.disturbance), ["gust [N]"]);
    assert_eq!(names(&s.names.measurement_disturbance), ["noise [m]"]);
    // Units alone keep the default names.
    assert_eq!(
        names(&with("output_units = [\"m\", \"V\"]").unwrap().names.output),
        ["y1 [m]", "y2 [V]"]
    );
}

#[test]
fn a_wrong_length_or_an_empty_name_is_one_line_naming_file_and_field() {
    for (line, field, reason) in [
        (
            "state_names = [\"a\", \"b\"]",
            "plant.state_names",
            "the plant has 3 states",
        ),
        (
            "state_units = [\"m\"]",
            "plant.state_units",
            "the plant has 3 states",
        ),
        (
            "output_names = [\"a\"]",
            "plant.output_names",
            "C has 2 rows",
        ),
        (
            "output_units = [\"m\", \"m\", \"m\"]",
            "plant.output_units",
            "C has 2 rows",
        ),
        (
            "input_names = [\"a\"]",
            "plant.input_names",
            "B has 2 columns",
        ),
        ("input_units = []", "plant.input_units", "B has 2 columns"),
        (
            "disturbance_names = [\"a\", \"b\"]",
            "plant.disturbance_names",
            "E has 1 column (unknown inputs)",
        ),
        (
            "disturbance_units = []",
            "plant.disturbance_units",
            "E has 1 column (unknown inputs)",
        ),
        (
            "measurement_disturbance_names = [\"a\", \"b\"]",
            "plant.measurement_disturbance_names",
            "D has 1 column (",
        ),
        (
            "measurement_disturbance_units = [\"a\", \"b\"]",
            "plant.measurement_disturbance_units",
            "D has 1 column (",
        ),
        (
            "output_names = [\"a\", \" \"]",
            "plant.output_names[2]",
            "must not be empty",
        ),
    ] {
        let e = with(line).unwrap_err();
        assert!(
            e.starts_with("names.toml:") && e.contains(field) && e.contains(reason),
            "{line}: {e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn the_shared_plant_fixture_is_the_shipped_seed002_plant() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let fixture = std::fs::read_to_string(root.join("fixtures/seed002_plant.toml")).unwrap();
    for shipped in ["seed002-sine.toml", "seed002-piecewise.toml"] {
        let text = std::fs::read_to_string(root.join("scenarios").join(shipped)).unwrap();
        assert!(
            text.contains(&fixture),
            "{shipped} no longer holds fixtures/seed002_plant.toml"
        );
    }
}
