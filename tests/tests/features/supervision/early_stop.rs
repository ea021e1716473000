//! A run that stops early reports the figures of the steps it completed and
//! claims no expectation; a hung component is named.

use std::process::Stdio;
use std::time::{Duration, Instant};

use tests::*;

/// max |v| over the recorded steps ≥ `from` of every series under `prefix` — recomputed here
/// from the recording, independently of the launcher's block maxima.
fn tail_max(r: &Recording, prefix: &str, from: i64) -> f64 {
    r.series
        .iter()
        .filter(|(p, _)| p.starts_with(prefix))
        .flat_map(|(_, s)| {
            s.steps
                .iter()
                .zip(&s.values)
                .filter(|(k, _)| **k >= from)
                .map(|(_, v)| v.abs())
        })
        .fold(0.0, f64::max)
}

fn steps_recorded(r: &Recording) -> i64 {
    r.series
        .iter()
        .find(|(p, _)| p.starts_with("/plant/x/"))
        .map_or(0, |(_, s)| s.values.len() as i64)
}

#[test]
fn a_hung_component_is_named_and_the_partial_run_reports_its_own_tail() {
    let s = Scratch::new("sigstop");
    // 60 s = 60 000 planned steps: the early-stop tail is exact (one step per block). Paced at
    // real time, so that the controller is stopped mid-run however slow the machine is: not
    // before the components said ready (a different failure), and not after the last step.
    let path = variant(&s, "seed002-sine", 60.0, true);
    let child = launcher(&s)
        .arg("run")
        .arg(&path)
        .arg("--realtime")
        .arg("--out")
        .arg(s.join("out"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lpid = child.id();
    wait_running(lpid, &["plant", "uio", "luenberger", "controller"]);
    wait_stepping(&s.join("out/seed002-sine.rrd.partial"));
    let victim = component_pid(lpid, "controller").expect("controller running");
    signal(victim, libc::SIGSTOP);
    let stopped = Instant::now();
    let out = child.wait_with_output().unwrap();
    let took = stopped.elapsed();
    let (stdout, err) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(took < Duration::from_secs(8), "took {took:?}");
    assert!(
        err.contains("controller (pid")
            && err.contains("stopped")
            && err.contains("published no sample for step"),
        "{err}"
    );
    assert_clean(&s, lpid);

    let r = read(&s.join("out/seed002-sine.rrd")).unwrap();
    let k = steps_recorded(&r);
    assert!(k > 4 && k < 60_000, "{k} steps");
    let from = k - k / 4;
    let sum = summary(&s, "seed002-sine");
    for o in ["uio", "luenberger"] {
        let obs = sum["observers"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == o)
            .unwrap();
        let e = obs["tail_max_abs_error"]
            .as_f64()
            .expect("a tail for a run of many steps");
        let want = tail_max(&r, &format!("/observer/{o}/error/"), from);
        assert!(
            want > 0.0 && e == want,
            "{o}: summary {e}, recording {want}"
        );
        let res = obs["tail_max_abs_residual"].as_f64().unwrap();
        assert_eq!(
            res,
            tail_max(&r, &format!("/observer/{o}/residual/"), from),
            "{o} residual"
        );
    }
    // No expectation holds for a run that did not complete.
    let ex = sum["expectations"].as_array().unwrap();
    assert!(
        !ex.is_empty() && ex.iter().all(|e| e["ok"] == false && e["value"].is_null()),
        "{ex:?}"
    );
    assert!(
        !stdout.contains(" ok\n") && stdout.contains("not checked"),
        "{stdout}"
    );

    // inspect recomputes the same tail from the recording.
    let ins = launcher(&s)
        .arg("inspect")
        .arg(s.join("out/seed002-sine.rrd"))
        .arg("--json")
        .output()
        .unwrap();
    let ins: serde_json::Value = serde_json::from_slice(&ins.stdout).unwrap();
    for o in ins["observers"].as_array().unwrap() {
        let name = o["name"].as_str().unwrap();
        let want = tail_max(&r, &format!("/observer/{name}/error/"), from);
        assert_eq!(
            o["tail_max_abs_error"].as_f64(),
            Some(want),
            "inspect {name}"
        );
    }
}

#[test]
fn an_interrupted_in_process_run_reports_the_tail_of_its_steps() {
    let s = Scratch::new("sigint-tail");
    let path = variant(&s, "seed002-sine", 20_000.0, true);
    let child = launcher(&s)
        .arg("run")
        .arg(&path)
        .args(["--mode", "in-process", "--out"])
        .arg(s.join("out"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    signal(child.id() as i32, libc::SIGINT);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{:?}", text(&out));
    let r = read(&s.join("out/seed002-sine.rrd")).unwrap();
    let k = steps_recorded(&r);
    let sum = summary(&s, "seed002-sine");
    assert_eq!(sum["steps"].as_i64(), Some(k));
    // 20 M planned steps: the start is rounded down to a block, so the launcher's tail holds
    // the exact last quarter and at most one block more.
    let block = (20_000_000f64 / 65_536.0).ceil().log2().ceil().exp2() as i64;
    let from = k - k / 4;
    for o in ["uio", "luenberger"] {
        let obs = sum["observers"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == o)
            .unwrap();
        let e = obs["tail_max_abs_error"].as_f64().unwrap();
        let (lo, hi) = (
            tail_max(&r, &format!("/observer/{o}/error/"), from),
            tail_max(&r, &format!("/observer/{o}/error/"), from - block),
        );
        assert!(lo > 0.0 && lo <= e && e <= hi, "{o}: {lo} ≤ {e} ≤ {hi}");
    }
    assert!(
        sum["expectations"]
            .as_array()
            .unwrap()
            .iter()
            .all(|e| e["ok"] == false)
    );
}

#[test]
fn a_run_of_fewer_than_four_steps_has_no_tail() {
    let s = Scratch::new("no-tail");
    let path = variant(&s, "seed002-sine", 0.003, false);
    let out = run(&s, &path, &["--mode", "in-process"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let sum = summary(&s, "seed002-sine");
    assert!(sum["observers"][0]["tail_max_abs_error"].is_null(), "{sum}");
    assert!(text(&out).0.contains("—"));
}

/// A thinned recording holds fewer rows than steps: inspect takes the completed count from the
/// recording, warns of nothing, and takes its tail from the same steps (of the rows it has).
#[test]
fn inspect_of_a_thinned_recording_knows_the_run_completed() {
    let s = Scratch::new("thinned-inspect");
    let out = run(
        &s,
        &scenario("seed002-sine"),
        &["--mode", "in-process", "--record-every", "10"],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    let rrd = s.join("out/seed002-sine.rrd");
    let ins = launcher(&s)
        .arg("inspect")
        .arg(&rrd)
        .arg("--json")
        .output()
        .unwrap();
    let j: serde_json::Value = serde_json::from_slice(&ins.stdout).unwrap();
    assert_eq!(j["steps_completed"], 20_000, "{j}");
    assert_eq!(j["steps_recorded"], 2_000, "{j}");
    assert!(
        j["warnings"].as_array().unwrap().is_empty(),
        "{}",
        j["warnings"]
    );
    let r = read(&rrd).unwrap();
    let sum = summary(&s, "seed002-sine");
    for o in j["observers"].as_array().unwrap() {
        let name = o["name"].as_str().unwrap();
        let got = o["tail_max_abs_error"].as_f64().unwrap();
        assert_eq!(
            got,
            tail_max(&r, &format!("/observer/{name}/error/"), 15_000),
            "{name}"
        );
        let full = sum["observers"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == name)
            .unwrap()["tail_max_abs_error"]
            .as_f64()
            .unwrap();
        assert!(
            got > 0.0 && got <= full,
            "{name}: thinned {got} vs every step {full}"
        );
    }
}
