//! Each kind of bad input gets exit code 2, one line naming the file and the field
//! (with line:column where the parser knows it) and the reason, no panic, and no output files.

use std::ffi::OsStr;

use tests::*;

const BASE: &str = concat!(
    r#"name = "bad"
dt = 0.001
duration = 1.0

[plant]
"#,
    // The seed-002 plant (scenarios/seed002-*.toml), shared by the tests that need a small UIO plant.
    include_str!("../../../../fixtures/seed002_plant.toml"),
    r#"x0 = [1.0, -1.0, 2.0]

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
"#
);

/// (case, edit of BASE, text the message must contain besides the file name).
fn cases() -> Vec<(&'static str, String, &'static str)> {
    let r = |a: &str, b: &str| {
        assert!(BASE.contains(a), "{a}");
        BASE.replacen(a, b, 1)
    };
    vec![
        (
            "malformed-toml",
            r("dt = 0.001", "dt = = 0.001"),
            "malformed TOML",
        ),
        (
            "unknown-key",
            r(
                "x0 = [1.0, -1.0, 2.0]",
                "x0 = [1.0, -1.0, 2.0]\ncolour = \"red\"",
            ),
            "colour",
        ),
        (
            "unknown-key-observer",
            r("name = \"uio\"", "name = \"uio\"\ngain = 3"),
            "gain",
        ),
        (
            "A-not-square",
            r(
                "A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]]",
                "A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0]]",
            ),
            "plant.A",
        ),
        (
            "B-size",
            r(
                "B = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]",
                "B = [[0.0, 0.0], [4.0, 0.0]]",
            ),
            "plant.B",
        ),
        (
            "C-size",
            r(
                "C = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]",
                "C = [[1.0, 0.0], [0.0, 1.0]]",
            ),
            "plant.C",
        ),
        (
            "E-size",
            r("E = [[2.0], [0.0], [0.5]]", "E = [[2.0], [0.0]]"),
            "plant.E",
        ),
        (
            "D-size",
            r(
                "x0 = [1.0, -1.0, 2.0]",
                "D = [[1.0], [2.0], [3.0]]\nx0 = [1.0, -1.0, 2.0]",
            ),
            "plant.D",
        ),
        (
            "x0-size",
            r("x0 = [1.0, -1.0, 2.0]", "x0 = [1.0, -1.0]"),
            "plant.x0",
        ),
        (
            "H-size",
            r(
                "kind = \"chen-patton-uio\"\npoles = [-1.0, -2.0, -3.0]",
                "kind = \"das-ghosal-uio\"\nH = [[1.0, 2.0, 3.0]]",
            ),
            "observer[1].H",
        ),
        (
            "gain-size",
            r("poles = [-4.0, -5.0, -6.0]", "gain = [[1.0, 2.0, 3.0]]"),
            "controller.gain",
        ),
        (
            "ragged",
            r(
                "A = [[0.0, 1.0, 0.0], [-2.0, -3.0, 0.0], [0.0, 0.0, -2.0]]",
                "A = [[0.0, 1.0, 0.0], [-2.0, -3.0], [0.0, 0.0, -2.0]]",
            ),
            "plant.A[2]",
        ),
        (
            "empty-B",
            r("B = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]", "B = []"),
            "plant.B",
        ),
        (
            "empty-rows",
            r(
                "B = [[0.0, 0.0], [4.0, 0.0], [0.0, 1.0]]",
                "B = [[], [], []]",
            ),
            "plant.B",
        ),
        (
            "nan-in-matrix",
            r("[-2.0, -3.0, 0.0]", "[-2.0, nan, 0.0]"),
            "plant.A[2]",
        ),
        (
            "inf-amplitude",
            r("amplitude = 1.0", "amplitude = inf"),
            "disturbance[1].amplitude",
        ),
        (
            "inf-pole",
            r("poles = [-1.0, -2.0, -3.0]", "poles = [-1.0, -inf, -3.0]"),
            "observer[1].poles[2]",
        ),
        ("dt-zero", r("dt = 0.001", "dt = 0.0"), "dt"),
        ("dt-negative", r("dt = 0.001", "dt = -0.001"), "dt"),
        ("dt-nan", r("dt = 0.001", "dt = nan"), "dt"),
        (
            "duration-zero",
            r("duration = 1.0", "duration = 0.0"),
            "duration",
        ),
        (
            "duration-below-dt",
            r("duration = 1.0", "duration = 0.0005"),
            "duration",
        ),
        (
            "too-many-disturbances",
            r(
                "[[input]]\nkind = \"constant\"\nvalue = 0.0\n\n[[input]]",
                "[[disturbance]]\nkind = \"constant\"\nvalue = 1.0\n\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n\n[[input]]",
            ),
            "disturbance",
        ),
        (
            "too-few-inputs",
            r(
                "[[input]]\nkind = \"constant\"\nvalue = 0.0\n\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n",
                "[[input]]\nkind = \"constant\"\nvalue = 0.0\n",
            ),
            "input",
        ),
        (
            "pole-not-a-pair",
            r(
                "poles = [-1.0, -2.0, -3.0]",
                "poles = [-1.0, [-2.0, 3.0, 1.0]]",
            ),
            "observer[1].poles[2]",
        ),
        (
            "conjugate-written-twice",
            r(
                "poles = [-1.0, -2.0, -3.0]",
                "poles = [-1.0, [-2.0, 3.0], [-2.0, -3.0]]",
            ),
            "observer[1].poles[3]",
        ),
        (
            "poles-repeated",
            r(
                "name = \"luenberger\"\nkind = \"luenberger\"\npoles = [-1.0, -2.0, -3.0]",
                "name = \"luenberger\"\nkind = \"luenberger\"\npoles = [-1.0, -1.0, -1.0]",
            ),
            "observer[2].poles",
        ),
        (
            "missing-observer",
            r("observer = \"uio\"", "observer = \"ghost\""),
            "controller.observer",
        ),
        (
            "duplicate-names",
            r("name = \"luenberger\"", "name = \"uio\""),
            "observer[2].name",
        ),
        ("missing-field", r("x0 = [1.0, -1.0, 2.0]\n", ""), "x0"),
        // E = [0, 1, 0]ᵀ is invisible to y = [x1, x3]: CE = 0, rank 0 ≠ 1.
        (
            "existence-condition",
            r("E = [[2.0], [0.0], [0.5]]", "E = [[0.0], [1.0], [0.0]]"),
            "rank(CE) = rank(E)",
        ),
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
        let err = refused(&s, case, &body);
        assert!(err.contains(field), "{case}: '{field}' not named: {err}");
    }
}

/// Runs `body` as `<case>.toml`: asserts exit 2, one line naming the file, no panic, and no
/// output directory created; returns the line.
fn refused(s: &Scratch, case: &str, body: &str) -> String {
    let path = s.join(&format!("{case}.toml"));
    std::fs::write(&path, body).unwrap();
    let out_dir = s.join(&format!("out-{case}"));
    let out = launcher(s)
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(&out_dir)
        .output()
        .unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{case}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{case}: not one line: {err}"
    );
    assert!(
        err.contains(&format!("{case}.toml")),
        "{case}: file not named: {err}"
    );
    assert!(!err.contains("panicked"), "{case}: {err}");
    assert!(!out_dir.exists(), "{case}: output written");
    err
}

#[test]
fn parser_errors_carry_line_and_column() {
    let s = Scratch::new("bad-input-lines");
    let body = BASE.replacen(
        "x0 = [1.0, -1.0, 2.0]",
        "x0 = [1.0, -1.0, 2.0]\ncolour = \"red\"",
        1,
    );
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
    let out = launcher(&s)
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(&file)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("not-a-dir") && err.contains("output directory"),
        "{err}"
    );
    // An existing recording: refused, then accepted with --force.
    let out = run(&s, &path, &[]);
    assert!(out.status.success());
    let before = std::fs::metadata(s.join("out/bad.rrd"))
        .unwrap()
        .modified()
        .unwrap();
    let out = run(&s, &path, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.rrd") && err.contains("--force"), "{err}");
    assert_eq!(
        std::fs::metadata(s.join("out/bad.rrd"))
            .unwrap()
            .modified()
            .unwrap(),
        before
    );
    assert!(run(&s, &path, &["--force"]).status.success());
}

/// Runs `launcher <args>` and kills it if it has not finished within 10 s (a blocked read).
fn run_bounded(s: &Scratch, args: &[&OsStr]) -> std::process::Output {
    use std::process::Stdio;
    let mut child = launcher(s)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while child.try_wait().unwrap().is_none() {
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!("launcher {args:?} blocked: {:?}", text(&out));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

#[test]
fn names_are_bounded_before_anything_is_created() {
    let s = Scratch::new("long-names");
    for (case, body, field) in [
        (
            "name-250",
            BASE.replacen(
                "name = \"bad\"",
                &format!("name = \"{}\"", "n".repeat(250)),
                1,
            ),
            "name",
        ),
        (
            "observer-name-300",
            BASE.replacen(
                "name = \"luenberger\"",
                &format!("name = \"{}\"", "l".repeat(300)),
                1,
            ),
            "observer[2].name",
        ),
    ] {
        let err = refused(&s, case, &body);
        assert!(
            err.contains(&format!("{field}:")) && err.contains("64"),
            "{case}: {err}"
        );
        assert!(
            err.len() < 400,
            "{case}: the message repeats the whole name: {err}"
        );
    }
}

#[test]
fn untrusted_text_is_escaped_in_messages() {
    let s = Scratch::new("escapes");
    let evil = r#"x\n\u001b[2J\u001b]0;owned\u0007"#;
    let r = |a: &str, b: String| {
        assert!(BASE.contains(a), "{a}");
        BASE.replacen(a, &b, 1)
    };
    let cases = [
        ("name", r("name = \"bad\"", format!("name = \"{evil}\""))),
        (
            "observer-name",
            r("name = \"uio\"", format!("name = \"{evil}\"")),
        ),
        (
            "kind",
            r("kind = \"luenberger\"", format!("kind = \"{evil}\"")),
        ),
        (
            "controller-observer",
            r("observer = \"uio\"", format!("observer = \"{evil}\"")),
        ),
        (
            "unknown-key",
            r(
                "x0 = [1.0, -1.0, 2.0]",
                format!("x0 = [1.0, -1.0, 2.0]\n\"{evil}\" = 1"),
            ),
        ),
        (
            "expect-key",
            format!("{BASE}\n[expect]\ntail_max_abs_error = {{ \"{evil}\" = 1.0 }}\n"),
        ),
        (
            "description-in-list",
            r(
                "name = \"bad\"",
                format!("name = \"bad\"\ndescription = \"{evil}\""),
            ),
        ),
    ];
    for (case, body) in cases {
        let path = s.join(&format!("{case}.toml"));
        std::fs::write(&path, &body).unwrap();
        let out = if case == "description-in-list" {
            let dir = s.join("list");
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join("d.toml"), &body).unwrap();
            launcher(&s)
                .arg("list")
                .arg("--dir")
                .arg(&dir)
                .output()
                .unwrap()
        } else {
            launcher(&s).arg("run").arg(&path).output().unwrap()
        };
        let (stdout, err) = text(&out);
        let shown = if case == "description-in-list" {
            stdout
        } else {
            err
        };
        assert!(
            !shown.contains('\u{1b}') && !shown.contains('\u{7}'),
            "{case}: raw control characters: {shown:?}"
        );
        assert_eq!(shown.trim_end().lines().count(), 1, "{case}: {shown:?}");
        assert!(
            shown.contains(r"\u{1b}"),
            "{case}: escape not shown: {shown:?}"
        );
        if case != "description-in-list" {
            assert_eq!(out.status.code(), Some(2), "{case}: {shown}");
        }
    }
    // A file name with a newline and an escape in it.
    let path = s.join("evil\n\u{1b}[31m.toml");
    std::fs::write(&path, BASE.replacen("dt = 0.001", "dt = 0.0", 1)).unwrap();
    let out = launcher(&s).arg("run").arg(&path).output().unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        !err.contains('\u{1b}') && err.trim_end().lines().count() == 1,
        "{err:?}"
    );
}

#[test]
fn only_regular_files_of_bounded_size_are_read() {
    let s = Scratch::new("special-files");
    let fifo = s.join("fifo.toml");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo with a valid C path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let dir = s.join("dir.toml");
    std::fs::create_dir_all(&dir).unwrap();
    let big = s.join("big.toml");
    std::fs::write(
        &big,
        format!(
            "{}{BASE}",
            "# padding padding padding padding padding padding\n".repeat(40_000)
        ),
    )
    .unwrap();
    for (file, why) in [
        (&fifo, "not a regular file"),
        (&dir, "not a regular file"),
        (&big, "1 MiB"),
    ] {
        let out_dir = s.join("out");
        let run_args = [
            OsStr::new("run"),
            file.as_os_str(),
            OsStr::new("--out"),
            out_dir.as_os_str(),
        ];
        let design_args = [OsStr::new("design"), file.as_os_str()];
        for args in [&run_args[..], &design_args[..]] {
            let out = run_bounded(&s, args);
            let (_, err) = text(&out);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
            assert!(
                err.contains(file.file_name().unwrap().to_str().unwrap()) && err.contains(why),
                "{args:?}: {err}"
            );
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
            assert!(!out_dir.exists());
        }
    }
    // Recordings: a FIFO or a directory is refused by every tool, at once.
    let fifo_rrd = s.join("fifo.rrd");
    let c = std::ffi::CString::new(fifo_rrd.to_str().unwrap()).unwrap();
    // SAFETY: as above.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    for file in [&fifo_rrd, &dir] {
        let (f, outs) = (file.as_os_str(), s.join("tool-out"));
        let o = outs.as_os_str();
        let commands: [&[&OsStr]; 4] = [
            &[OsStr::new("inspect"), f],
            &[OsStr::new("compare"), f, f],
            &[OsStr::new("export"), f, OsStr::new("--csv"), o],
            &[OsStr::new("plot"), f, OsStr::new("--out"), o],
        ];
        for args in commands {
            let out = run_bounded(&s, args);
            let (_, err) = text(&out);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
            assert!(err.contains("not a regular file"), "{args:?}: {err}");
            assert!(!outs.exists(), "{args:?}: output written");
        }
    }
}

/// An unknown key is located at its own line (not its table's header), and an unknown
/// key, kind or shipped scenario name close to a known one gets "did you mean …".
#[test]
fn unknown_keys_point_at_their_line_and_near_misses_are_suggested() {
    let s = Scratch::new("did-you-mean");
    // The second [[observer]]'s `poles` misspelt, on line 38 of the file.
    let body = BASE.replacen(
        "name = \"luenberger\"\nkind = \"luenberger\"\npoles",
        "name = \"luenberger\"\nkind = \"luenberger\"\npoels",
        1,
    );
    let line = body.lines().position(|l| l.starts_with("poels")).unwrap() + 1;
    let err = refused(&s, "key", &body);
    assert!(
        err.contains(&format!("key.toml:{line}:"))
            && err.contains("unknown field `poels`")
            && err.contains("(did you mean 'poles'?)"),
        "{err}"
    );
    let err = refused(
        &s,
        "kind",
        &BASE.replacen("kind = \"luenberger\"", "kind = \"luenburger\"", 1),
    );
    assert!(
        err.contains("observer[2].kind") && err.contains("(did you mean 'luenberger'?)"),
        "{err}"
    );
    let err = refused(
        &s,
        "far",
        &BASE.replacen("kind = \"luenberger\"", "kind = \"xyz\"", 1),
    );
    assert!(!err.contains("did you mean"), "{err}");
    let out = launcher(&s)
        .args(["design", "seed002-sin"])
        .output()
        .unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("(did you mean 'seed002-sine'?)"), "{err}");
}
