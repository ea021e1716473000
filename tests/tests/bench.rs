//! Issue 13: `launcher bench` measures its floor — a bare three-process ring over the same
//! transport — in the same session, and gives the multi-process figures as ratios to it.

use tests::*;

#[test]
fn bench_runs_its_floor_and_reports_ratios_to_it() {
    let s = Scratch::new("bench-floor");
    let child = launcher(&s).args(["bench", "--steps", "3000", "--mode", "processes", "--recording", "off", "--repeat", "2", "--json"]).stdout(std::process::Stdio::piped()).spawn().unwrap();
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
