//! `xhat0` sets an observer's first estimate, in both run modes alike.

use tests::*;

/// Seed 002 with both observers started at the true x(0): the UIO's error then stays at the
/// rounding of the sampled sine (its decoupling is exact for inputs held over a step), where its
/// default start x̂₀ = Hy₀ leaves an error of order 1 to decay; and the two modes record the same
/// run bit for bit.
#[test]
fn xhat0_starts_the_estimate_in_both_modes() {
    let s = Scratch::new("xhat0");
    let text = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let x0 = text
        .lines()
        .find_map(|l| l.strip_prefix("x0 = "))
        .expect("x0")
        .to_string();
    let started = text
        .replacen(
            "name = \"uio\"\n",
            &format!("name = \"uio\"\nxhat0 = {x0}\n"),
            1,
        )
        .replacen(
            "name = \"luenberger\"\n",
            &format!("name = \"luenberger\"\nxhat0 = {x0}\n"),
            1,
        );
    let path = s.join("started.toml");
    std::fs::write(&path, started).unwrap();
    let max_error = |dir: &str, file: &std::path::Path, mode: &str| {
        let out = launcher(&s)
            .args(["run", "--mode", mode, "--out"])
            .arg(s.join(dir))
            .arg(file)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let p = s.join(dir).join("seed002-sine.summary.json");
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        let of = |name: &str| {
            v["observers"]
                .as_array()
                .unwrap()
                .iter()
                .find(|o| o["name"] == name)
                .unwrap()["max_abs_error"]
                .as_f64()
                .unwrap()
        };
        (of("uio"), of("luenberger"))
    };
    let (uio, luenberger) = max_error("a", &path, "in-process");
    let (uio_default, luenberger_default) = max_error("b", &scenario("seed002-sine"), "in-process");
    assert!(uio <= 1e-6, "UIO started at x(0): max error {uio}");
    assert!(
        uio_default >= 0.1,
        "UIO from x̂₀ = Hy₀: max error {uio_default}"
    );
    assert!(
        luenberger < luenberger_default,
        "{luenberger} vs {luenberger_default}"
    );
    max_error("c", &path, "processes");
    let out = launcher(&s)
        .arg("compare")
        .arg(s.join("a/seed002-sine.rrd"))
        .arg(s.join("c/seed002-sine.rrd"))
        .output()
        .unwrap();
    assert!(
        out.status.success() && String::from_utf8_lossy(&out.stdout).contains("bit for bit"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    // A wrong length is refused with the field.
    std::fs::write(
        &path,
        text.replacen(
            "name = \"uio\"\n",
            "name = \"uio\"\nxhat0 = [1.0, 2.0]\n",
            1,
        ),
    )
    .unwrap();
    let out = launcher(&s).arg("design").arg(&path).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("observer[1].xhat0") && err.contains("one per state"),
        "{err}"
    );
}
