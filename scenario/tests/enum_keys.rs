//! Every enum-like key refuses a value it does not know in one way: the field, "<value> is not a
//! <what> (<the values it takes>)", and the closest value when one is close enough — and takes
//! each value it lists. The shipped scenarios are the bases; one key is changed at a time.

use std::path::{Path, PathBuf};

use scenario::Scenario;

fn shipped(name: &str) -> toml::Table {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    std::fs::read_to_string(path).unwrap().parse().unwrap()
}

/// The table a path such as `controller` or `diagnoser[1]` names.
fn table<'a>(t: &'a mut toml::Table, path: &str) -> &'a mut toml::Table {
    match path.split_once('[') {
        None => t.get_mut(path).unwrap().as_table_mut().unwrap(),
        Some((key, index)) => {
            let i: usize = index.trim_end_matches(']').parse().unwrap();
            t.get_mut(key).unwrap().as_array_mut().unwrap()[i - 1]
                .as_table_mut()
                .unwrap()
        }
    }
}

/// `base` with `path.key = value`, validated.
fn with(
    base: &str,
    path: &str,
    key: &str,
    value: &str,
) -> Result<Scenario, scenario::ScenarioError> {
    let mut t = shipped(base);
    table(&mut t, path).insert(key.into(), toml::Value::String(value.into()));
    Scenario::parse(Path::new("edited.toml"), &toml::to_string(&t).unwrap())
}

/// An enum-like key: where it is (a shipped scenario, a table, the key), what the message calls
/// it, the values it takes, and a near miss with the value it is near.
struct Key {
    base: &'static str,
    table: &'static str,
    key: &'static str,
    what: &'static str,
    values: &'static [&'static str],
    near: &'static str,
    meant: &'static str,
}

const KEYS: [Key; 7] = [
    Key {
        base: "seed002-sine",
        table: "plant",
        key: "time",
        what: "time domain",
        values: &["continuous", "discrete"],
        near: "discret",
        meant: "discrete",
    },
    Key {
        base: "seed002-sine",
        table: "observer[1]",
        key: "placement",
        what: "placement",
        values: &["robust", "knv0", "matlab", "ackermann"],
        near: "matlb",
        meant: "matlab",
    },
    Key {
        base: "seed004-projection-uio-sine",
        table: "observer[1]",
        key: "path",
        what: "design path",
        values: &["placement", "lmi"],
        near: "placment",
        meant: "placement",
    },
    Key {
        base: "seed002-sine",
        table: "controller",
        key: "kind",
        what: "controller kind",
        values: &["state-feedback", "lqr", "process"],
        near: "state_feedback",
        meant: "state-feedback",
    },
    Key {
        base: "seed002-sine",
        table: "controller",
        key: "domain",
        what: "domain",
        values: &["sampled", "continuous"],
        near: "continous",
        meant: "continuous",
    },
    Key {
        base: "seed002-actuator-faults",
        table: "diagnoser[1]",
        key: "scheme",
        what: "scheme",
        values: &["generalized", "dedicated"],
        near: "dedicatd",
        meant: "dedicated",
    },
    Key {
        base: "seed002-actuator-faults",
        table: "diagnoser[1]",
        key: "faults",
        what: "channel class",
        values: &["actuator", "sensor", "component"],
        near: "actuators",
        meant: "actuator",
    },
];

#[test]
fn an_unknown_value_of_an_enum_like_key_is_named_with_the_values_it_takes_and_the_closest() {
    for Key {
        base,
        table: path,
        key,
        what,
        values,
        near,
        meant,
    } in KEYS
    {
        let field = format!("{path}.{key}");
        for (given, hint) in [
            (near, format!(" (did you mean '{meant}'?)")),
            ("xyzzy-qwerty", String::new()),
        ] {
            let e = with(base, path, key, given).expect_err(&field);
            assert_eq!(e.field, field, "{base}: {given}");
            assert_eq!(
                e.reason,
                format!("'{given}' is not a {what} ({}){hint}", values.join(", ")),
                "{base}: {field} = {given}"
            );
        }
    }
}

#[test]
fn each_value_an_enum_like_key_lists_is_taken_as_that_value() {
    for Key {
        base,
        table: path,
        key,
        values,
        ..
    } in KEYS
    {
        for v in values {
            // A value may be refused later for what it implies (a discrete plant needs Phi, a
            // process controller a command, an LMI path the solver, sensor channels a sensor
            // bank): never as an unknown value of this key.
            if let Err(e) = with(base, path, key, v) {
                assert!(
                    !(e.field == format!("{path}.{key}") && e.reason.contains("is not a")),
                    "{base}: {path}.{key} = {v}: {e}"
                );
            }
        }
    }
}
