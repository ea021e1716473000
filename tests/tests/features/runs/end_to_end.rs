//! The seed-002 scenarios run as separate processes and in one process, give
//! bit-identical trajectories, decode with the rerun crate, and leave nothing behind.

use std::process::Command;

use tests::*;

fn run_both(name: &str) -> (Scratch, Scratch) {
    let (a, b) = (
        Scratch::new(&format!("{name}-proc")),
        Scratch::new(&format!("{name}-inproc")),
    );
    for (s, mode) in [(&a, "processes"), (&b, "in-process")] {
        let child = launcher(s)
            .args(["run"])
            .arg(scenario(name))
            .arg("--out")
            .arg(s.join("out"))
            .args(["--mode", mode])
            .spawn()
            .unwrap();
        let pid = child.id();
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "{name} {mode}: {:?}", text(&out));
        assert_clean(s, pid);
    }
    (a, b)
}

fn check_scenario(name: &str) {
    let (proc_dir, inproc_dir) = run_both(name);
    let sp = summary(&proc_dir, name);
    let si = summary(&inproc_dir, name);
    let steps = 20_000;
    for s in [&sp, &si] {
        assert_eq!(s["steps"], steps);
        let obs = s["observers"].as_array().unwrap();
        let get = |n: &str, f: &str| {
            obs.iter().find(|o| o["name"] == n).unwrap()[f]
                .as_f64()
                .unwrap()
        };
        let (ue, le) = (
            get("uio", "tail_max_abs_error"),
            get("luenberger", "tail_max_abs_error"),
        );
        let (ur, lr) = (
            get("uio", "tail_max_abs_residual"),
            get("luenberger", "tail_max_abs_residual"),
        );
        assert!(ue <= 1e-4 * le, "{name}: uio {ue:e} vs luenberger {le:e}");
        assert!(
            ur <= 1e-4 * lr,
            "{name}: residual uio {ur:e} vs luenberger {lr:e}"
        );
        assert!(
            le > 1e-2,
            "{name}: the disturbance must visibly affect the Luenberger observer ({le:e})"
        );
    }
    // Bit-identical trajectories: every recorded f64 of every signal.
    let rp = read(&proc_dir.join("out").join(format!("{name}.rrd"))).unwrap();
    let ri = read(&inproc_dir.join("out").join(format!("{name}.rrd"))).unwrap();
    assert!(rp.complete && ri.complete);
    let (tp, ti) = (trajectories(&rp), trajectories(&ri));
    assert_eq!(tp.len(), ti.len());
    // x (3) y (2) w (1) r (2) u (2) + 2 observers × (x̂ 3 + e 3 + r 2 + log10 max|e| 1) + the
    // UIO's ŵ (1)
    assert_eq!(
        tp.len(),
        3 + 2 + 1 + 2 + 2 + 2 * 9 + 1,
        "{:?}",
        tp.iter().map(|(k, _)| k).collect::<Vec<_>>()
    );
    for ((kp, sp), (ki, si)) in tp.iter().zip(&ti) {
        assert_eq!(kp, ki);
        // Exactly one value per step (ŵ_k completes with step k + 1: none for the last step).
        let recorded = if kp.contains("/what/") {
            steps as i64 - 1
        } else {
            steps as i64
        };
        assert_eq!(sp.steps, (0..recorded).collect::<Vec<_>>(), "{kp}");
        let same = sp
            .values
            .iter()
            .zip(&si.values)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(
            same && sp.values.len() == si.values.len(),
            "{kp} differs between modes"
        );
    }
    // The latency series are there too, one per step: the last step's too, closed by the
    // plant's end sample.
    for hop in ["/latency/step", "/latency/controller_to_plant"] {
        let l = &rp.series[hop];
        assert_eq!(l.steps, (0..steps as i64).collect::<Vec<_>>(), "{hop}");
        assert!(l.values.iter().all(|&v| v > 0.0 && v < 1e9), "{hop}");
    }
}

#[test]
fn seed002_sine_end_to_end() {
    check_scenario("seed002-sine");
}

#[test]
fn seed002_piecewise_end_to_end() {
    check_scenario("seed002-piecewise");
}

#[test]
fn bad_scenarios_are_refused_with_file_field_and_exit_2() {
    let s = Scratch::new("bad");
    let good = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let cases = [
        (
            "wrong-size",
            good.replace(
                "C = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]",
                "C = [[1.0, 0.0], [0.0, 1.0]]",
            ),
            "plant.C",
        ),
        (
            "missing-field",
            good.replace("x0 = [1.0, -1.0, 2.0]\n", ""),
            "x0",
        ),
    ];
    for (tag, body, field) in cases {
        let path = s.join(&format!("{tag}.toml"));
        std::fs::write(&path, body).unwrap();
        let out = run(&s, &path, &[]);
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{tag}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{tag}: one line: {err}");
        assert!(
            err.contains(&format!("{tag}.toml")) && err.contains(field),
            "{tag}: {err}"
        );
        assert!(
            !s.join("out").exists() || std::fs::read_dir(s.join("out")).unwrap().next().is_none(),
            "{tag}: output written"
        );
    }
}

#[test]
fn default_command_runs_seed002_sine() {
    // `cargo run --release` runs the launcher with no arguments.
    let s = Scratch::new("default");
    std::fs::create_dir_all(s.join("scenarios")).unwrap();
    std::fs::copy(
        scenario("seed002-sine"),
        s.join("scenarios/seed002-sine.toml"),
    )
    .unwrap();
    let out = Command::new(bin_dir().join("uio-launcher"))
        .env(lockstep_runs_env(), s.runs())
        .current_dir(&s.0)
        .output()
        .unwrap();
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("rerun runs/seed002-sine.rrd"), "{stdout}");
    assert!(s.join("runs/seed002-sine.rrd").is_file());
}
