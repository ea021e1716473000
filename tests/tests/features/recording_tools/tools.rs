//! Inspect, compare, export and plot recordings — complete ones and one whose writer
//! was killed.

use std::process::Stdio;
use std::time::Duration;

use tests::*;

fn inspect_json(s: &Scratch, rrd: &std::path::Path) -> (serde_json::Value, String) {
    let out = launcher(s)
        .arg("inspect")
        .arg(rrd)
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    (
        serde_json::from_slice(&out.stdout).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The observer named `name` in an inspection's JSON.
fn observer_of<'a>(ins: &'a serde_json::Value, name: &serde_json::Value) -> &'a serde_json::Value {
    ins["observers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["name"] == *name)
        .unwrap()
}

#[test]
fn inspect_recomputes_the_summary() {
    let s = Scratch::new("inspect");
    assert!(run(&s, &scenario("seed002-sine"), &[]).status.success());
    let sum = summary(&s, "seed002-sine");
    let (ins, warnings) = inspect_json(&s, &s.join("out/seed002-sine.rrd"));
    assert!(warnings.is_empty(), "{warnings}");
    assert_eq!(ins["complete"], true);
    assert_eq!(ins["steps_recorded"], 20_000);
    for o in sum["observers"].as_array().unwrap() {
        let i = observer_of(&ins, &o["name"]);
        for f in ["tail_max_abs_error", "tail_max_abs_residual"] {
            let (a, b) = (o[f].as_f64().unwrap(), i[f].as_f64().unwrap());
            assert!(
                (a - b).abs() <= 1e-12 * a.abs().max(1e-300),
                "{} {f}: summary {a:e}, inspect {b:e}",
                o["name"]
            );
        }
    }
    assert_eq!(sum["latency_ns"]["step"], ins["latency_ns"]["step"]);
    assert_eq!(sum["latency_ns"]["hops"], ins["latency_ns"]["hops"]);
    // Recorded in µs (so the viewer's latency axes read µs), timed in ns: inspect's percentiles
    // above are the recorded values × 1000, equal to the run's own.
    let r = recording::read::read(&s.join("out/seed002-sine.rrd")).unwrap();
    assert_eq!(r.latency_unit.as_deref(), Some("µs"));
    assert_eq!(r.latency_ns_per_value(), 1000.0);
    // ŵ's figure too, from the recorded ŵ and w at the same steps: the same numbers, bit for
    // bit, for every observer that estimates w and none for the others.
    for name in ["seed002-sine", "dc-motor-load-torque"] {
        if name != "seed002-sine" {
            assert!(run(&s, &scenario(name), &[]).status.success());
        }
        let sum = summary(&s, name);
        let (ins, _) = inspect_json(&s, &s.join(&format!("out/{name}.rrd")));
        let mut estimated = 0;
        for o in sum["observers"].as_array().unwrap() {
            let i = observer_of(&ins, &o["name"]);
            let f = "tail_max_abs_input_error";
            assert_eq!(o[f].as_f64(), i[f].as_f64(), "{name} {}", o["name"]);
            estimated += usize::from(o[f].is_f64());
        }
        assert!(estimated >= 1, "{name}: no observer estimates w");
    }
    let entities = ins["entities"].as_array().unwrap();
    let x0 = entities.iter().find(|e| e["path"] == "/plant/x/1").unwrap();
    assert_eq!(x0["rows"], 20_000);
    assert_eq!(x0["sim_time"][1].as_f64().unwrap(), 19.999);
}

#[test]
fn compare_demands_bits_and_names_the_first_difference() {
    let s = Scratch::new("compare");
    let name = "seed003-charlie-open-loop";
    for (dir, mode) in [("a", "processes"), ("b", "in-process")] {
        let out = launcher(&s)
            .arg("run")
            .arg(scenario(name))
            .args(["--out", dir, "--mode", mode])
            .output()
            .unwrap();
        assert!(out.status.success(), "{:?}", text(&out));
    }
    let (a, b) = (
        s.join(&format!("a/{name}.rrd")),
        s.join(&format!("b/{name}.rrd")),
    );
    let out = launcher(&s)
        .arg("compare")
        .arg(&a)
        .arg(&b)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    // One value changed, by one unit in the last place.
    let mut r = read(&b).unwrap();
    let series = r.series.get_mut("/observer/dgo/xhat/2").unwrap();
    series.values[4321] = f64::from_bits(series.values[4321].to_bits() + 1);
    let changed = s.join("changed.rrd");
    recording::read::write(&changed, &r).unwrap();
    let out = launcher(&s)
        .arg("compare")
        .arg(&a)
        .arg(&changed)
        .output()
        .unwrap();
    let (stdout, _) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("/observer/dgo/xhat/2") && stdout.contains("step 4321"),
        "{stdout}"
    );
    // Within a tolerance it agrees.
    let out = launcher(&s)
        .arg("compare")
        .arg(&a)
        .arg(&changed)
        .args(["--rel-tol", "1e-12"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    // An unreadable file.
    let junk = s.join("junk.rrd");
    std::fs::write(&junk, b"not a recording").unwrap();
    let out = launcher(&s)
        .arg("compare")
        .arg(&a)
        .arg(&junk)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{:?}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("junk.rrd"));
}

#[test]
fn export_round_trips_every_bit() {
    let s = Scratch::new("export");
    let name = "seed004-projection-uio-sine";
    assert!(
        run(&s, &scenario(name), &["--mode", "in-process"])
            .status
            .success()
    );
    let rrd = s.join(&format!("out/{name}.rrd"));
    let out = launcher(&s)
        .arg("export")
        .arg(&rrd)
        .arg("--csv")
        .arg(s.join("csv"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let r = read(&rrd).unwrap();
    let scenario = recording::tools::recorded_scenario(&r);
    let mut checked = 0;
    for (group, members) in recording::export::groups(&r) {
        let csv = std::fs::read_to_string(s.join("csv").join(recording::export::file_name(&group)))
            .unwrap();
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(&header[..2], &["step", "sim_time"]);
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        for (col, (member, series)) in members.iter().enumerate() {
            assert_eq!(
                header[2 + col],
                recording::export::header(scenario.as_ref(), &r, &group, member)
            );
            let by_step: std::collections::HashMap<i64, &Vec<&str>> =
                rows.iter().map(|r| (r[0].parse().unwrap(), r)).collect();
            for (k, v) in series.steps.iter().zip(&series.values) {
                let parsed: f64 = by_step[k][2 + col].parse().unwrap();
                assert_eq!(
                    parsed.to_bits(),
                    v.to_bits(),
                    "{group}/{member} at step {k}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 14_000 * 20, "{checked}");
}

fn non_white_fraction(png: &std::path::Path) -> f64 {
    let img = image::open(png).unwrap().to_rgb8();
    let total = (img.width() * img.height()) as f64;
    img.pixels().filter(|p| p.0 != [255, 255, 255]).count() as f64 / total
}

#[test]
fn plot_draws_one_png_per_view() {
    let s = Scratch::new("plot");
    let name = "seed000-missile-dgo-uio";
    assert!(run(&s, &scenario(name), &[]).status.success());
    let out = launcher(&s)
        .arg("plot")
        .arg(s.join(&format!("out/{name}.rrd")))
        .arg("--out")
        .arg(s.join("png"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let mut files: Vec<String> = std::fs::read_dir(s.join("png"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    // 4 states, max |e| of both observers, error and residual for 2 observers, the UIO's ŵ,
    // unknown inputs, inputs, outputs, latency (the second observer, off the ring in open loop,
    // apart).
    let expected = [
        "error_dgo-uio.png",
        "error_luenberger.png",
        "errors_log.png",
        "input_estimate_dgo-uio.png",
        "inputs.png",
        "latency.png",
        "latency_followers.png",
        "outputs.png",
        "residual_dgo-uio.png",
        "residual_luenberger.png",
        "state_1_gamma_dot.png",
        "state_2_q.png",
        "state_3_eta.png",
        "state_4_eta_dot.png",
        "unknown_inputs.png",
    ];
    assert_eq!(files, expected);
    for f in &files {
        let frac = non_white_fraction(&s.join("png").join(f));
        assert!(frac > 0.02, "{f} looks blank ({frac})");
    }
}

#[test]
fn a_killed_writers_recording_is_read_with_a_warning() {
    let s = Scratch::new("killed-writer");
    let text_ = std::fs::read_to_string(scenario("seed002-sine"))
        .unwrap()
        .replace("duration = 20.0", "duration = 600.0");
    let path = s.join("long.toml");
    std::fs::write(&path, text_.split("\n[expect]").next().unwrap()).unwrap();
    let mut child = launcher(&s)
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(s.join("out"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Let it write a few batches, then kill the launcher outright.
    let partial = s.join("out/seed002-sine.rrd.partial");
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    while std::fs::metadata(&partial).map_or(0, |m| m.len()) < 3_000_000 {
        assert!(
            std::time::Instant::now() < deadline,
            "the run wrote nothing"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let r = read(&partial).unwrap();
    assert!(!r.complete);
    assert!(!r.series["/plant/x/1"].values.is_empty());
    let (ins, warnings) = inspect_json(&s, &partial);
    assert_eq!(ins["complete"], false);
    assert!(warnings.contains("incomplete"), "{warnings}");
    for cmd in [vec!["export", "--csv", "csv"], vec!["plot", "--out", "png"]] {
        let out = launcher(&s)
            .arg(cmd[0])
            .arg(&partial)
            .args(&cmd[1..])
            .output()
            .unwrap();
        let (_, err) = text(&out);
        assert!(out.status.success(), "{cmd:?}: {err}");
        assert!(err.contains("incomplete"), "{cmd:?}: {err}");
    }
    assert!(std::fs::read_dir(s.join("png")).unwrap().count() >= 8);
}
