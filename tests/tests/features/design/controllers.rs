//! Controllers do what was asked — the sampled loop's poles where the file puts
//! them, integral action and disturbance cancellation that leave no steady-state error.

use controller::design::{Domain, FeedbackSpec};
use lti::C64;
use tests::*;

/// The sorted sampled closed-loop poles of `uio-launcher design --json`, against e^{p·dt} of the
/// poles the file asks for: to 1e-12 (relative to 1) for every shipped closed-loop scenario that
/// places its poles for the sampled loop (the default).
#[test]
fn shipped_closed_loops_have_the_sampled_poles_their_files_ask() {
    let s = Scratch::new("ctl-poles");
    let mut checked = 0;
    for entry in std::fs::read_dir(repo().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let Ok(sc) = scenario::Scenario::load(&path) else {
            continue;
        };
        let Some(FeedbackSpec::Poles {
            poles,
            domain: Domain::Sampled,
            ..
        }) = sc.controller.as_ref().and_then(|c| c.spec.clone())
        else {
            continue;
        };
        let out = launcher(&s)
            .args(["design", "--json"])
            .arg(&path)
            .output()
            .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let got: Vec<C64> = complex_list(&v["controller"]["discrete_closed_loop_poles"]);
        let want = poles.to_discrete(sc.dt);
        let err = lti::eig::match_error(want.values(), &got);
        assert!(
            err <= 1e-12,
            "{}: sampled poles {got:?} vs e^(p·dt) {:?}: {err:e}",
            path.display(),
            want.values()
        );
        checked += 1;
    }
    assert!(
        checked >= 4,
        "only {checked} shipped closed loops place poles"
    );
}

/// The last value of a recorded series.
fn last(r: &recording::read::Recording, path: &str) -> f64 {
    *r.series[path]
        .values
        .last()
        .unwrap_or_else(|| panic!("{path} is empty"))
}

/// Runs a scenario text in-process and reads the recording back.
fn run_text(s: &Scratch, name: &str, text: &str) -> recording::read::Recording {
    let path = s.join(&format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = launcher(s)
        .args(["run", "--mode", "in-process", "--out"])
        .arg(s.join(name))
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let scen_name = text
        .lines()
        .find_map(|l| l.strip_prefix("name = \""))
        .unwrap()
        .trim_end_matches('"');
    recording::read::read(&s.join(&format!("{name}/{scen_name}.rrd"))).unwrap()
}

/// The vehicle under a 1500 N crosswind step: with integral action on the measured offset, e_y
/// settles on the 0.5 m reference to rounding; the same LQR without it (prefilter N only) is
/// left off by the wind. Both modes give the same run.
#[test]
fn integral_action_removes_the_offset_a_step_wind_leaves() {
    let s = Scratch::new("ctl-integral");
    let text = std::fs::read_to_string(scenario("vehicle-lateral-integral")).unwrap();
    let r = run_text(&s, "with", &text);
    let e_y = last(&r, "/plant/x/1");
    assert!(
        (e_y - 0.5).abs() < 1e-9,
        "with integral action e_y ends at {e_y}"
    );
    // The wind did act on the heading: a steady heading error balances it.
    assert!(last(&r, "/plant/x/3").abs() > 1e-3);
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("integral") && !l.starts_with("Q = "))
        .map(|l| format!("{l}\n"))
        .collect::<String>();
    let r = run_text(&s, "without", &without);
    let e_y = last(&r, "/plant/x/1");
    assert!(
        (e_y - 0.5).abs() > 1e-2,
        "without integral action e_y ends at {e_y}"
    );
}

/// Seed 003 (Charlie) with an elevator-like step disturbance (E = B) and its Das–Ghosal observer,
/// which does not decouple w: integral action on the measured angle of attack still holds it at
/// the 0.1 rad reference; the prefilter alone does not.
#[test]
fn integral_action_on_seed003_under_a_step_unknown_input() {
    let s = Scratch::new("ctl-seed003");
    let text = std::fs::read_to_string(scenario("seed003-charlie-closed-loop")).unwrap();
    let text = text.split("[expect]").next().unwrap().to_string();
    let disturbed = text.replacen("C = [[", "E = [[0.0], [-0.04], [0.0], [-12.5]]\nC = [[", 1)
        + "\n[[disturbance]]\nkind = \"step\"\ntime = 4.0\nbefore = 0.0\nafter = 0.02\n";
    let integral = disturbed
        .replace(
            "poles = [-4.0, -5.0, -6.0, -7.0]",
            "integral = true\npoles = [-4.0, -5.0, -6.0, -7.0, -8.0]",
        )
        .replace("duration = 10.0", "duration = 16.0");
    assert_ne!(integral, disturbed);
    let r = run_text(&s, "integral", &integral);
    let alpha = last(&r, "/plant/x/2");
    assert!(
        (alpha - 0.1).abs() < 1e-9,
        "α ends at {alpha} with integral action"
    );
    let r = run_text(&s, "prefilter", &disturbed);
    let alpha = last(&r, "/plant/x/2");
    assert!(
        (alpha - 0.1).abs() > 1e-3,
        "α ends at {alpha} with the prefilter alone"
    );
}

/// A wind acting at the front axle enters through the steering column (Γ_E = Γ_B M): with
/// `feedforward = "what"` the UIO's ŵ cancels it and the prefilter's tracking is exact again; a
/// wind that is not matched is refused by name.
#[test]
fn feedforward_cancels_a_matched_unknown_input_and_refuses_an_unmatched_one() {
    let s = Scratch::new("ctl-ff");
    let text = std::fs::read_to_string(scenario("vehicle-lateral-integral")).unwrap();
    // E = B/(2C_f): the wind's moment arm is l_f.
    let matched = text
        .replace("E = [[0.0], [0.0006666667], [0.0], [0.00012]]", "E = [[0.0], [0.0006666666666666666], [0.0], [0.00048]]")
        .replace("integral = true", "feedforward = \"what\"")
        .lines()
        .map(|l| if l.starts_with("Q = ") { "Q = [[100.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 10.0, 0.0], [0.0, 0.0, 0.0, 1.0]]\n".to_string() } else { format!("{l}\n") })
        .collect::<String>();
    let r = run_text(&s, "ff", &matched);
    let e_y = last(&r, "/plant/x/1");
    assert!(
        (e_y - 0.5).abs() < 1e-9,
        "with the wind cancelled e_y ends at {e_y}"
    );
    let without: String = matched
        .lines()
        .filter(|l| !l.starts_with("feedforward"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(without, matched);
    let r = run_text(&s, "noff", &without);
    let e_y = last(&r, "/plant/x/1");
    assert!(
        (e_y - 0.5).abs() > 1e-3,
        "without feedforward e_y ends at {e_y}"
    );
    // The shipped wind acts 0.3 m ahead of the centre of gravity: not through the steering.
    let path = s.join("unmatched.toml");
    std::fs::write(
        &path,
        matched.replace(
            "E = [[0.0], [0.0006666666666666666], [0.0], [0.00048]]",
            "E = [[0.0], [0.0006666667], [0.0], [0.00012]]",
        ),
    )
    .unwrap();
    let out = launcher(&s).arg("design").arg(&path).output().unwrap();
    let err =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("controller.feedforward")
            && err.contains("w1 does not enter through the inputs"),
        "{err}"
    );
    // An observer without ŵ is refused too.
    let path = s.join("luenberger.toml");
    std::fs::write(
        &path,
        matched.replace("observer = \"uio\"", "observer = \"luenberger\""),
    )
    .unwrap();
    let out = launcher(&s).arg("design").arg(&path).output().unwrap();
    let err =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("'luenberger' gives no estimate ŵ"), "{err}");
}

/// A controller that reads the plant's samples (integral action on a measured output) is one
/// more subscriber to them: with 7 observers there would be 9 (the recorder too), more than a
/// service allows — refused by name before anything runs.
#[test]
fn a_controller_reading_the_plant_counts_against_the_subscriber_limit() {
    let s = Scratch::new("ctl-limit");
    let text = std::fs::read_to_string(scenario("vehicle-lateral-integral")).unwrap();
    let extra: String = (1..=5).map(|i| format!("[[observer]]\nname = \"l{i}\"\nkind = \"luenberger\"\npoles = [-8.0, -9.0, -10.0, -11.0]\n\n")).collect();
    let text = text.replacen("[controller]", &format!("{extra}[controller]"), 1);
    let path = s.join("many.toml");
    std::fs::write(&path, text.split("[expect]").next().unwrap()).unwrap();
    let out = launcher(&s)
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(s.join("out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("controller.integral") && err.contains("at most 6 observers here"),
        "{err}"
    );
    assert!(!s.join("out").exists() || std::fs::read_dir(s.join("out")).unwrap().next().is_none());
}
