//! `uio-launcher bench` measures its floor — a bare three-process ring over the same
//! transport — in the same session, and gives the multi-process figures as ratios to it.

use tests::*;

#[test]
fn bench_runs_its_floor_and_reports_ratios_to_it() {
    let s = Scratch::new("bench-floor");
    let child = launcher(&s)
        .args([
            "bench",
            "--steps",
            "3000",
            "--mode",
            "processes",
            "--recording",
            "off",
            "--repeat",
            "2",
            "--json",
        ])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    assert_clean(&s, pid);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let runs = v["runs"].as_array().unwrap();
    let floors: Vec<&serde_json::Value> = runs.iter().filter(|r| r["mode"] == "floor").collect();
    assert_eq!(floors.len(), 2, "{runs:?}");
    for f in &floors {
        assert_eq!(f["steps"], 3000);
        // A step of the bare ring takes three hops: more than nothing, less than a millisecond.
        let p50 = f["step_ns"]["p50"].as_u64().unwrap();
        assert!(p50 > 100 && p50 < 1_000_000, "{f}");
    }
    let ratio = &v["ratios"]["processes (no recording) / floor, steps/s"];
    assert_eq!(ratio["repetitions"], 2, "{v}");
    let median = ratio["median"].as_f64().unwrap();
    assert!(median > 0.0 && median.is_finite(), "{ratio}");
}

/// `--states N,…` measures random plants of those sizes (UIO and Luenberger observer, closed
/// loop): a row per size and configuration, recorded runs with their bytes per step, and a
/// bigger model costs more per step.
#[test]
fn bench_states_measures_each_size() {
    let s = Scratch::new("bench-states");
    let out = launcher(&s)
        .args([
            "bench",
            "--states",
            "3,20",
            "--steps",
            "2000",
            "--mode",
            "in-process",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let runs = v["states"].as_array().unwrap();
    assert_eq!(runs.len(), 4, "{runs:?}");
    let get = |n: u64, rec: bool| {
        runs.iter()
            .find(|r| r["n"] == n && r["recording"] == rec)
            .unwrap()
    };
    for n in [3, 20] {
        assert!(get(n, false)["bytes_per_step"].is_null());
        assert!(get(n, true)["bytes_per_step"].as_f64().unwrap() > 0.0);
    }
    assert!(
        get(20, true)["bytes_per_step"].as_f64().unwrap()
            > get(3, true)["bytes_per_step"].as_f64().unwrap()
    );
    let bad = launcher(&s)
        .args([
            "bench",
            "--states",
            "0",
            "--steps",
            "10",
            "--mode",
            "in-process",
        ])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2), "{:?}", text(&bad));
}
