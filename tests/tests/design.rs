//! Issue 3: `launcher design` reports conditions, matrices and poles (text and JSON), and a model
//! without an unknown-input observer is refused with the condition named, exit 2, by both
//! `launcher design` and `launcher run`.

use tests::*;

#[test]
fn design_json_has_the_documented_shape() {
    let s = Scratch::new("design-json");
    let out = launcher(&s).args(["design", "--json"]).arg(scenario("seed002-sine")).output().unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["scenario"], "seed002-sine");
    let uio = &j["observers"][0];
    assert_eq!(uio["kind"], "chen-patton-uio");
    for m in ["H", "T", "K1", "K2", "F"] {
        assert!(uio["matrices"][m].is_array(), "{m}");
    }
    let c = &uio["conditions"][0];
    assert_eq!(c["name"], "rank(CE) = rank(E)");
    assert_eq!(c["ok"], true);
    assert_eq!(c["detail"], "1 = 1");
    let poles: Vec<f64> = uio["poles"].as_array().unwrap().iter().map(|p| p[0].as_f64().unwrap()).collect();
    assert_eq!(poles.len(), 3);
    assert!(poles.iter().zip([-3.0, -2.0, -1.0]).all(|(a, b)| (a - b).abs() < 1e-9), "{poles:?}");
    assert_eq!(uio["discrete_poles"].as_array().unwrap().len(), 3);
    assert_eq!(j["controller"]["stable"], true);
    assert!(j["controller"]["matrices"]["G"].is_array());
    assert!(j["warnings"].is_array());
}

#[test]
fn design_reports_the_unstable_printed_gain() {
    let s = Scratch::new("design-printed");
    let out = launcher(&s).args(["design", "--json"]).arg(scenario("seed000-printed-gain")).output().unwrap();
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["controller"]["stable"], false);
    let w = j["warnings"].as_array().unwrap();
    assert!(w.iter().any(|w| w.as_str().unwrap().contains("122.271")), "{w:?}");
}

/// Seed-002 text with its model replaced.
fn variant(s: &Scratch, tag: &str, from: &[(&str, &str)]) -> std::path::PathBuf {
    let mut text = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    for (a, b) in from {
        assert!(text.contains(a), "{a}");
        text = text.replace(a, b);
    }
    let p = s.join(&format!("{tag}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn models_without_an_unknown_input_observer_are_refused_by_design_and_run() {
    let s = Scratch::new("design-refused");
    let cases = [
        // rank(CE) = 1 ≠ rank(E) = 2.
        (
            variant(&s, "rank", &[("E = [[2.0], [0.0], [0.5]]", "E = [[2.0, 0.0], [0.0, 1.0], [0.5, 0.0]]"), ("[[disturbance]]     # d(t) = sin(2π·0.5·t)", "[[disturbance]]\nkind = \"constant\"\nvalue = 1.0\n\n[[disturbance]]")]),
            "rank(CE) = rank(E)",
        ),
        // y = x2 − x1 sees the disturbance through a zero at +1... built on a 2-state plant.
        (
            {
                let text = "name = \"zero\"\ndt = 0.001\nduration = 1.0\n[plant]\nA = [[0.0, 1.0], [-2.0, -3.0]]\nB = [[0.0], [1.0]]\nC = [[-1.0, 1.0]]\nE = [[0.0], [1.0]]\nx0 = [0.0, 0.0]\n[[disturbance]]\nkind = \"constant\"\nvalue = 1.0\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n[[observer]]\nname = \"uio\"\nkind = \"chen-patton-uio\"\npoles = [-1.0]\n";
                let p = s.join("zero.toml");
                std::fs::write(&p, text).unwrap();
                p
            },
            "invariant zeros of (A, E, C) stable",
        ),
        // (A, C) with an unobservable, unstable mode: no Luenberger observer.
        (
            {
                let text = "name = \"unobservable\"\ndt = 0.001\nduration = 1.0\n[plant]\nA = [[1.0, 0.0], [0.0, -1.0]]\nB = [[1.0], [1.0]]\nC = [[0.0, 1.0]]\nx0 = [0.0, 0.0]\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n[[observer]]\nname = \"l\"\nkind = \"luenberger\"\npoles = [-1.0, -2.0]\n";
                let p = s.join("unobservable.toml");
                std::fs::write(&p, text).unwrap();
                p
            },
            "(A, C) detectable",
        ),
    ];
    for (path, condition) in cases {
        let out = launcher(&s).arg("design").arg(&path).output().unwrap();
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "design {}: {stdout}{stderr}", path.display());
        assert!(stdout.contains(condition), "design: {condition} not named:\n{stdout}");
        let out = run(&s, &path, &[]);
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(2), "run {}: {err}", path.display());
        assert!(err.contains(condition) && err.contains(path.file_name().unwrap().to_str().unwrap()), "run: {err}");
    }
}
