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

/// With recording, every repetition measures the disk's own synced write rate into the
/// recordings' folder, and each recorded run its bytes per step and its rate as a share of it.
#[test]
fn bench_gives_a_recordings_write_rate_against_the_disks_in_the_same_run() {
    let s = Scratch::new("bench-disk");
    let tmp = s.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let out = launcher(&s)
        .env("TMPDIR", &tmp)
        .args([
            "bench",
            "--steps",
            "3000",
            "--mode",
            "in-process",
            "--recording",
            "on",
            "--repeat",
            "2",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let runs = v["runs"].as_array().unwrap();
    let disks: Vec<f64> = runs
        .iter()
        .filter(|r| r["mode"] == "disk")
        .map(|r| r["write_bytes_per_s"].as_f64().unwrap())
        .collect();
    let recorded: Vec<&serde_json::Value> =
        runs.iter().filter(|r| r["mode"] == "in-process").collect();
    assert_eq!((disks.len(), recorded.len()), (2, 2), "{runs:?}");
    // A disk takes more than 1 MB/s and less than 100 GB/s.
    assert!(disks.iter().all(|&d| d > 1e6 && d < 1e11), "{disks:?}");
    let shares: Vec<f64> = recorded
        .iter()
        .zip(&disks)
        .map(|(r, d)| {
            // A step of seed 002 records tens of values of 8 bytes: 100 … 10 000 bytes.
            let b = r["bytes_per_step"].as_f64().unwrap();
            assert!(b > 100.0 && b < 10_000.0, "{r}");
            r["write_bytes_per_s"].as_f64().unwrap() / d
        })
        .collect();
    let ratio = &v["ratios"]["in-process (recording): write rate / disk's"];
    assert_eq!(ratio["repetitions"], 2, "{v}");
    let (lo, hi) = (shares[0].min(shares[1]), shares[0].max(shares[1]));
    assert_eq!(ratio["min"].as_f64().unwrap(), lo);
    assert_eq!(ratio["max"].as_f64().unwrap(), hi);
    // The recordings and the disk's test file went with the bench's folder.
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().flatten().collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// Every repetition also runs a 32-sensor plant with and without a 32-member bank in each mode:
/// a member's cost per step is the two runs' difference in time per step over 32, and the
/// printed ratio is the cost across processes over the cost in one process.
#[test]
fn bench_gives_a_bank_members_cost_in_each_mode_and_their_ratio() {
    let s = Scratch::new("bench-bank");
    let out = launcher(&s)
        .args(["bench", "--steps", "3000", "--recording", "off", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let banks = v["banks"].as_array().unwrap();
    assert_eq!(banks.len(), 1, "{v}");
    let rep = banks[0].as_array().unwrap();
    assert_eq!(rep.len(), 4, "{rep:?}");
    let cost = |mode: &str| {
        let sps = |members: u64| {
            rep.iter()
                .find(|r| r["mode"] == mode && r["members"] == members)
                .unwrap()["steps_per_s"]
                .as_f64()
                .unwrap()
        };
        (1e6 / sps(32) - 1e6 / sps(0)) / 32.0
    };
    let (i, p) = (cost("in-process"), cost("processes"));
    // The costs themselves are not asserted: on a loaded machine a 3000-step run across
    // processes without the bank can be the slower one.
    for (name, c) in [
        ("bank member (in-process), µs per step", i),
        ("bank member (processes), µs per step", p),
    ] {
        let got = v["ratios"][name]["median"].as_f64().unwrap();
        assert!((got - c).abs() <= 1e-9 * c.abs(), "{name}: {got} {c}");
    }
    let r = &v["ratios"]["bank member: processes / in-process, cost per step"];
    assert_eq!(r["repetitions"], 1, "{v}");
    assert!(
        (r["median"].as_f64().unwrap() - p / i).abs() <= 1e-9 * (p / i).abs(),
        "{r} against {p} / {i}"
    );
}
