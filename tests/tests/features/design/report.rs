//! `uio-launcher design` reports conditions, matrices and poles (text and JSON), and a model
//! without an unknown-input observer is refused with the condition named, exit 2, by both
//! `uio-launcher design` and `uio-launcher run`.

use tests::*;

#[test]
fn design_json_has_the_documented_shape() {
    let s = Scratch::new("design-json");
    let out = launcher(&s)
        .args(["design", "--json"])
        .arg(scenario("seed002-sine"))
        .output()
        .unwrap();
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
    let poles: Vec<f64> = uio["poles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p[0].as_f64().unwrap())
        .collect();
    assert_eq!(poles.len(), 3);
    assert!(
        poles
            .iter()
            .zip([-3.0, -2.0, -1.0])
            .all(|(a, b)| (a - b).abs() < 1e-9),
        "{poles:?}"
    );
    assert_eq!(uio["discrete_poles"].as_array().unwrap().len(), 3);
    assert_eq!(j["controller"]["stable"], true);
    assert!(j["controller"]["matrices"]["G"].is_array());
    assert!(j["warnings"].is_array());
}

#[test]
fn design_reports_the_unstable_printed_gain() {
    let s = Scratch::new("design-printed");
    let out = launcher(&s)
        .args(["design", "--json"])
        .arg(scenario("seed000-printed-gain"))
        .output()
        .unwrap();
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["controller"]["stable"], false);
    // The run would refuse it (without --allow-unstable): design exits as it would.
    assert_eq!(out.status.code(), Some(2));
    let w = j["warnings"].as_array().unwrap();
    assert!(
        w.iter().any(|w| w.as_str().unwrap().contains("122.271")),
        "{w:?}"
    );
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
            variant(
                &s,
                "rank",
                &[
                    (
                        "E = [[2.0], [0.0], [0.5]]",
                        "E = [[2.0, 0.0], [0.0, 1.0], [0.5, 0.0]]",
                    ),
                    (
                        "[[disturbance]]     # d(t) = sin(2π·0.5·t)",
                        "[[disturbance]]\nkind = \"constant\"\nvalue = 1.0\n\n[[disturbance]]",
                    ),
                ],
            ),
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
        assert_eq!(
            out.status.code(),
            Some(2),
            "design {}: {stdout}{stderr}",
            path.display()
        );
        assert!(
            stdout.contains(condition),
            "design: {condition} not named:\n{stdout}"
        );
        let out = run(&s, &path, &[]);
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(2), "run {}: {err}", path.display());
        assert!(
            err.contains(condition) && err.contains(path.file_name().unwrap().to_str().unwrap()),
            "run: {err}"
        );
    }
}

/// `design --json` gives the sampled observer that runs. Replaying its
/// F, G, K, P, Q on a run's recorded y and u reproduces the recorded estimates.
#[test]
fn design_json_sampled_matrices_reproduce_the_recorded_estimates() {
    let s = Scratch::new("design-sampled");
    let out = launcher(&s)
        .args(["design", "--json"])
        .arg(scenario("seed002-sine"))
        .output()
        .unwrap();
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let run_out = run(&s, &scenario("seed002-sine"), &["--mode", "in-process"]);
    assert!(run_out.status.success(), "{:?}", text(&run_out));
    let r = read(&s.join("out/seed002-sine.rrd")).unwrap();
    let mat = |v: &serde_json::Value| {
        let rows: Vec<Vec<f64>> = v
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                r.as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect()
            })
            .collect();
        let cols = rows.first().map_or(0, |r| r.len());
        lti::Mat::from_fn(rows.len(), cols, |i, k| rows[i][k])
    };
    // Entities are numbered from 1 (y1 is /plant/y/1); find each signal's series in order.
    let series = |prefix: &str| -> Vec<Vec<f64>> {
        let mut v: Vec<(usize, Vec<f64>)> = r
            .series
            .iter()
            .filter_map(|(p, s)| {
                p.strip_prefix(prefix)
                    .and_then(|i| i.parse().ok())
                    .map(|i: usize| (i, s.values.clone()))
            })
            .collect();
        v.sort_by_key(|(i, _)| *i);
        v.into_iter().map(|(_, s)| s).collect()
    };
    let (y, u) = (series("/plant/y/"), series("/controller/u/"));
    for o in j["observers"].as_array().unwrap() {
        let name = o["name"].as_str().unwrap();
        let sm = &o["sampled"];
        let (f, g, k, p, q) = (
            mat(&sm["F"]),
            mat(&sm["G"]),
            mat(&sm["K"]),
            mat(&sm["P"]),
            mat(&sm["Q"]),
        );
        // eig(F) are the reported discrete poles.
        let want = complex_list(&o["discrete_poles"]);
        assert!(
            lti::eig::match_error(&want, &lti::eig::eigenvalues(&f).unwrap()) < 1e-12,
            "{name}"
        );
        let xhat = series(&format!("/observer/{name}/xhat/"));
        let mut z = lti::Mat::zeros(f.nrows(), 1);
        let col = |sig: &[Vec<f64>], k: usize| lti::Mat::from_fn(sig.len(), 1, |i, _| sig[i][k]);
        let mut worst: f64 = 0.0;
        for step in 0..xhat[0].len() {
            if step > 0 {
                z = &f * &z + &g * col(&u, step - 1) + &k * col(&y, step - 1);
            }
            let est = &p * &z + &q * col(&y, step);
            for i in 0..xhat.len() {
                worst =
                    worst.max((est[(i, 0)] - xhat[i][step]).abs() / (1.0 + xhat[i][step].abs()));
            }
        }
        assert!(
            worst < 1e-9,
            "{name}: replayed estimate differs by {worst:e}"
        );
    }
}

/// `uio-launcher design` exits non-zero whenever something the run needs cannot be designed: an
/// observer whose condition fails, like a bank member or an unstable loop, and 0 otherwise.
#[test]
fn design_exits_non_zero_when_an_observer_fails() {
    let s = Scratch::new("design-exit");
    let failing = variant(
        &s,
        "rank",
        &[
            (
                "C = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]",
                "C = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]",
            ),
            ("E = [[2.0], [0.0], [0.5]]", "E = [[0.0], [0.0], [1.0]]"),
        ],
    );
    for json in [false, true] {
        let out = launcher(&s)
            .arg("design")
            .args(json.then_some("--json"))
            .arg(&failing)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(2),
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(String::from_utf8_lossy(&out.stdout).contains("rank(CE) = rank(E)"));
    }
    let out = launcher(&s)
        .arg("design")
        .arg(scenario("seed002-sine"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
}

/// A discrete-time plant (`time = "discrete"`, seed 002's exact sampling at
/// 10 ms) designed by every family shows the sampled names only — (Φ, Γ_E, C), TΦ − K1C,
/// Φ − KCΦ, HΦF − KCΦF, LᵍΦL — and every pole list says s or z.
#[test]
fn a_discrete_plant_is_designed_in_sampled_names_only() {
    let s = Scratch::new("design-discrete");
    let model = lti::Model {
        a: lti::Mat::from_row_slice(3, 3, &[0.0, 1.0, 0.0, -2.0, -3.0, 0.0, 0.0, 0.0, -2.0]),
        b: lti::Mat::from_row_slice(3, 2, &[0.0, 0.0, 4.0, 0.0, 0.0, 1.0]),
        c: lti::Mat::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
        e: lti::Mat::from_row_slice(3, 1, &[2.0, 0.0, 0.5]),
        d: lti::Mat::zeros(2, 0),
    };
    let dm = model.discretize(0.01);
    let rows = |m: &lti::Mat| {
        format!(
            "[{}]",
            m.row_iter()
                .map(|r| format!(
                    "[{}]",
                    r.iter()
                        .map(|v| format!("{v:?}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let toml = format!(
        "name = \"disc\"\ndt = 0.01\nduration = 1.0\n[plant]\ntime = \"discrete\"\nPhi = {}\nGamma_B = {}\nGamma_E = {}\nC = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]\nx0 = [1.0, -1.0, 2.0]\n[[disturbance]]\nkind = \"sine\"\namplitude = 1.0\nfrequency_hz = 0.5\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n",
        rows(&dm.a),
        rows(&dm.b),
        rows(&dm.e)
    );
    let families = [
        ("lu", "luenberger", "poles = [-1.0, -2.0, -3.0]"),
        ("cp", "chen-patton-uio", "poles = [-1.0, -2.0, -3.0]"),
        ("cplqe", "chen-patton-uio", "gain = \"lqe\""),
        ("dg", "das-ghosal", "poles = [-2.0]"),
        ("dgu", "das-ghosal-uio", "poles = [-2.0]"),
        ("gi", "gi-full-order", "poles = [-1.0, -2.0, -3.0]"),
        ("cum", "cumming", "poles = [-2.0]"),
        ("hz", "hui-zak-uio", "gain = \"lqe\""),
    ];
    // Four observers a scenario (a run holds at most seven observer processes).
    let mut stdout = String::new();
    for (part, group) in families.chunks(4).enumerate() {
        let mut toml = toml.clone();
        for (name, kind, gain) in group {
            toml += &format!("[[observer]]\nname = \"{name}\"\nkind = \"{kind}\"\n{gain}\n");
        }
        let path = s.join(&format!("disc{part}.toml"));
        std::fs::write(&path, toml).unwrap();
        let out = launcher(&s).arg("design").arg(&path).output().unwrap();
        let (o, e) = text(&out);
        assert!(out.status.success(), "{o}\n{e}");
        stdout += &o;
    }
    assert_eq!(stdout.matches("\nobserver '").count(), 8, "{stdout}");
    for continuous in [
        "TA", "(A,", "A −", "KCA", "HAF", "CAF", "LgAL", "CAL", "rank(CE)", "CEd", "LgEd",
    ] {
        assert!(
            !stdout.contains(continuous),
            "{continuous:?} in a discrete design:\n{stdout}"
        );
    }
    for line in stdout.lines().filter(|l| {
        l.trim_start().starts_with("poles") || l.trim_start().starts_with("fixed modes")
    }) {
        assert!(
            line.contains("(s)") || line.contains("(z"),
            "a list without its domain: {line}"
        );
    }
}
