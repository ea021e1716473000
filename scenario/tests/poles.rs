//! Where a design takes no free poles, `poles = []` — or no `poles` key for
//! `das-ghosal-uio` — is accepted (today's "must not be empty" refusal is gone), and the design
//! itself says how many poles a pair needs.

use std::path::Path;

use scenario::Scenario;

/// A plant whose reduced-order UIO pair has only fixed modes (x1 reaches y only through the
/// channel the unknown input uses): das-ghosal-uio takes no free poles.
const BASE: &str = r#"name = "no-free-poles"
dt = 0.001
duration = 1.0

[plant]
A = [[-1.0, 0.0, 0.0], [1.0, -2.0, 0.0], [0.0, 1.0, -3.0]]
B = [[1.0], [0.0], [0.0]]
C = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
E = [[0.0], [1.0], [0.0]]
x0 = [1.0, 0.0, 0.0]

[[disturbance]]
kind = "constant"
value = 1.0

[[input]]
kind = "constant"
value = 0.0

[[observer]]
name = "dgo"
kind = "das-ghosal-uio"
"#;

fn empty_poles(s: &Scenario) -> bool {
    matches!(&s.observers[0].spec, Some(observer::Spec::DasGhosalUio { h: None, gain: Some(observer::design::Gain::Place { poles: p, .. }) }) if p.is_empty())
}

#[test]
fn an_empty_pole_list_and_a_missing_key_both_mean_no_free_poles() {
    let with_empty =
        Scenario::parse(Path::new("empty.toml"), &format!("{BASE}poles = []\n")).unwrap();
    assert!(empty_poles(&with_empty));
    let without = Scenario::parse(Path::new("none.toml"), BASE).unwrap();
    assert!(empty_poles(&without));
    // And the design of either exists: its only mode is the fixed one, −1.
    let d = observer::design(
        &without.model,
        without.observers[0].spec.as_ref().unwrap(),
        without.dt,
    )
    .unwrap();
    assert!(
        d.report
            .poles
            .iter()
            .all(|p| (p.re + 1.0).abs() < 1e-9 && p.im == 0.0),
        "{:?}",
        d.report.poles
    );
}

#[test]
fn an_empty_list_is_accepted_for_every_kind_and_the_design_says_what_it_needs() {
    let text = BASE.replace(
        "kind = \"das-ghosal-uio\"",
        "kind = \"luenberger\"\npoles = []",
    );
    let s = Scenario::parse(Path::new("luenberger.toml"), &text).unwrap();
    let e = observer::design(&s.model, s.observers[0].spec.as_ref().unwrap(), s.dt).unwrap_err();
    assert!(e.detail.contains("give 3 pole(s)"), "{e}");
}
