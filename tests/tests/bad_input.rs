//! Issue 6: each kind of bad input gets exit code 2, one line naming the file and the field
//! (with line:column where the parser knows it) and the reason, no panic, and no output files.

use tests::*;

const BASE: &str = r#"name = "bad"
dt = 0.001
duration = 1.0

[plant]
A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]]
B = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]
C = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
E = [[2.0], [0.0], [0.5]]
x0 = [1.0, -1.0, 2.0]

[[disturbance]]
kind = "sine"
amplitude = 1.0
frequency_hz = 0.5

[[input]]
kind = "constant"
value = 0.0

[[input]]
kind = "constant"
value = 0.0

[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = [-1.0, -2.0, -3.0]

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-1.0, -2.0, -3.0]

[controller]
kind = "state-feedback"
observer = "uio"
poles = [-4.0, -5.0, -6.0]
"#;

/// (case, edit of BASE, text the message must contain besides the file name).
fn cases() -> Vec<(&'static str, String, &'static str)> {
    let r = |a: &str, b: &str| {
        assert!(BASE.contains(a), "{a}");
        BASE.replacen(a, b, 1)
    };
    vec![
        ("malformed-toml", r("dt = 0.001", "dt = = 0.001"), "malformed TOML"),
        ("unknown-key", r("x0 = [1.0, -1.0, 2.0]", "x0 = [1.0, -1.0, 2.0]\ncolour = \"red\""), "colour"),
        ("unknown-key-observer", r("name = \"uio\"", "name = \"uio\"\ngain = 3"), "gain"),
        ("A-not-square", r("A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]]", "A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0]]"), "plant.A"),
        ("B-size", r("B = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]", "B = [[0.0, 0.0], [4.0, 0.0]]"), "plant.B"),
        ("C-size", r("C = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]", "C = [[1.0, 0.0], [0.0, 1.0]]"), "plant.C"),
        ("E-size", r("E = [[2.0], [0.0], [0.5]]", "E = [[2.0], [0.0]]"), "plant.E"),
        ("D-size", r("x0 = [1.0, -1.0, 2.0]", "D = [[1.0], [2.0], [3.0]]\nx0 = [1.0, -1.0, 2.0]"), "plant.D"),
        ("x0-size", r("x0 = [1.0, -1.0, 2.0]", "x0 = [1.0, -1.0]"), "plant.x0"),
        ("H-size", r("kind = \"chen-patton-uio\"\npoles = [-1.0, -2.0, -3.0]", "kind = \"das-ghosal-uio\"\nH = [[1.0, 2.0, 3.0]]"), "observer[0].H"),
        ("gain-size", r("poles = [-4.0, -5.0, -6.0]", "gain = [[1.0, 2.0, 3.0]]"), "controller.gain"),
        ("ragged", r("A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]]", "A = [[0.0, 1.0, 0.0], [-2.0, -3.0], [0.0, 0.0, -2.0]]"), "plant.A[1]"),
        ("empty-B", r("B = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]", "B = []"), "plant.B"),
        ("empty-rows", r("B = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]", "B = [[], [], []]"), "plant.B"),
        ("nan-in-matrix", r("[-2.0, -3.0, 0.0]", "[-2.0, nan, 0.0]"), "plant.A[1]"),
        ("inf-amplitude", r("amplitude = 1.0", "amplitude = inf"), "disturbance[0].amplitude"),
        ("inf-pole", r("poles = [-1.0, -2.0, -3.0]", "poles = [-1.0, -inf, -3.0]"), "observer[0].poles[1]"),
        ("dt-zero", r("dt = 0.001", "dt = 0.0"), "dt"),
        ("dt-negative", r("dt = 0.001", "dt = -0.001"), "dt"),
        ("dt-nan", r("dt = 0.001", "dt = nan"), "dt"),
        ("duration-zero", r("duration = 1.0", "duration = 0.0"), "duration"),
        ("duration-below-dt", r("duration = 1.0", "duration = 0.0005"), "duration"),
        ("too-many-disturbances", r("[[input]]\nkind = \"constant\"\nvalue = 0.0\n\n[[input]]", "[[disturbance]]\nkind = \"constant\"\nvalue = 1.0\n\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n\n[[input]]"), "disturbance"),
        ("too-few-inputs", r("[[input]]\nkind = \"constant\"\nvalue = 0.0\n\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n", "[[input]]\nkind = \"constant\"\nvalue = 0.0\n"), "input"),
        ("pole-not-a-pair", r("poles = [-1.0, -2.0, -3.0]", "poles = [-1.0, [-2.0, 3.0, 1.0]]"), "observer[0].poles[1]"),
        ("conjugate-written-twice", r("poles = [-1.0, -2.0, -3.0]", "poles = [-1.0, [-2.0, 3.0], [-2.0, -3.0]]"), "observer[0].poles[2]"),
        ("poles-repeated", r("name = \"luenberger\"\nkind = \"luenberger\"\npoles = [-1.0, -2.0, -3.0]", "name = \"luenberger\"\nkind = \"luenberger\"\npoles = [-1.0, -1.0, -1.0]"), "observer[1].poles"),
        ("missing-observer", r("observer = \"uio\"", "observer = \"ghost\""), "controller.observer"),
        ("duplicate-names", r("name = \"luenberger\"", "name = \"uio\""), "observer[1].name"),
        ("missing-field", r("x0 = [1.0, -1.0, 2.0]\n", ""), "x0"),
        // E = [0, 1, 0]ᵀ is invisible to y = [x1, x3]: CE = 0, rank 0 ≠ 1.
        ("existence-condition", r("E = [[2.0], [0.0], [0.5]]", "E = [[0.0], [1.0], [0.0]]"), "rank(CE) = rank(E)"),
    ]
}

#[test]
fn every_bad_scenario_is_refused_with_its_field() {
    let s = Scratch::new("bad-input");
    // The base scenario itself is fine.
    let good = s.join("good.toml");
    std::fs::write(&good, BASE).unwrap();
    let out = launcher(&s).arg("design").arg(&good).output().unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    for (case, body, field) in cases() {
        let path = s.join(&format!("{case}.toml"));
        std::fs::write(&path, &body).unwrap();
        let out_dir = s.join(&format!("out-{case}"));
        let out = launcher(&s).arg("run").arg(&path).arg("--out").arg(&out_dir).output().unwrap();
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{case}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{case}: not one line: {err}");
        assert!(err.contains(&format!("{case}.toml")), "{case}: file not named: {err}");
        assert!(err.contains(field), "{case}: '{field}' not named: {err}");
        assert!(!err.contains("panicked"), "{case}: {err}");
        assert!(!out_dir.exists(), "{case}: output written");
    }
}

#[test]
fn parser_errors_carry_line_and_column() {
    let s = Scratch::new("bad-input-lines");
    let body = BASE.replacen("x0 = [1.0, -1.0, 2.0]", "x0 = [1.0, -1.0, 2.0]\ncolour = \"red\"", 1);
    let path = s.join("colour.toml");
    std::fs::write(&path, body).unwrap();
    let out = launcher(&s).arg("run").arg(&path).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("colour.toml:11:1"), "{err}");
    let body = BASE.replacen("[-2.0, -3.0, 0.0]", "[-2.0, -3.0]", 1);
    let path = s.join("ragged.toml");
    std::fs::write(&path, body).unwrap();
    let out = launcher(&s).arg("run").arg(&path).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("ragged.toml:6:"), "{err}");
}

#[test]
fn outputs_in_the_way_are_refused() {
    let s = Scratch::new("bad-output");
    let path = s.join("ok.toml");
    std::fs::write(&path, BASE).unwrap();
    // An output "directory" that is a file.
    let file = s.join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    let out = launcher(&s).arg("run").arg(&path).arg("--out").arg(&file).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("not-a-dir") && err.contains("output directory"), "{err}");
    // An existing recording: refused, then accepted with --force.
    let out = run(&s, &path, &[]);
    assert!(out.status.success());
    let before = std::fs::metadata(s.join("out/bad.rrd")).unwrap().modified().unwrap();
    let out = run(&s, &path, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.rrd") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::metadata(s.join("out/bad.rrd")).unwrap().modified().unwrap(), before);
    assert!(run(&s, &path, &["--force"]).status.success());
}
