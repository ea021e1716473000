//! Supervision that does not stop healthy runs. A component that publishes
//! nothing is judged by what the kernel says of it: stopped or blocked, it is named after 5 s;
//! running, or waiting for a core, it is waited for up to the stall limit (`stall_timeout`,
//! `--stall-timeout`), and the message says which limit was hit.

use std::time::Duration;

use tests::*;

/// seed002-sine in open loop with a Python observer `slow` that spins for `busy_s` seconds of
/// wall time in its step 100 (a step that computes for long, or waits for a core).
fn with_busy_observer(s: &Scratch, busy_s: f64, extra: &str) -> std::path::PathBuf {
    std::fs::write(
        s.join("busy.py"),
        format!(
            "import time\nimport uio_component\n\ndef step(k, inputs):\n    if k == 100:\n        until = time.monotonic() + {busy_s}\n        while time.monotonic() < until:\n            pass\n    return inputs[0][:3].copy()\n\nuio_component.run(step)\n"
        ),
    )
    .unwrap();
    let text = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let text = text
        .split("\n[controller]")
        .next()
        .unwrap()
        .replace("duration = 20.0", "duration = 0.5");
    let text = format!(
        "{extra}{text}\n[[observer]]\nname = \"slow\"\nkind = \"process\"\ncommand = [\"python3\", \"busy.py\"]\n"
    );
    let p = s.join("slow.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// A step that runs for 8 s, longer than the 5 s after which a blocked component is named, is
/// waited for: the run completes.
#[test]
fn a_component_that_runs_long_is_waited_for() {
    let s = Scratch::new("busy-ok");
    let path = with_busy_observer(&s, 8.0, "");
    let (code, err, took) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(0), "{err}");
    assert!(took >= Duration::from_secs(8), "took {took:?}");
}

/// The same step under a stall limit it exceeds — from the command line, and from the
/// scenario — is named with the limit that was hit; the command line wins over the file.
#[test]
fn a_component_past_the_stall_limit_is_named_with_the_limit() {
    for (extra, args) in [
        ("", &["--stall-timeout", "5"][..]),
        ("stall_timeout = 5.0\n", &[][..]),
        ("stall_timeout = 5.0\n", &["--stall-timeout", "30"][..]),
    ] {
        let s = Scratch::new("busy-limit");
        let path = with_busy_observer(&s, 12.0, extra);
        let (code, err, took) = run_checked(&s, &path, args);
        if args.contains(&"30") {
            assert_eq!(code, Some(0), "{err}");
            continue;
        }
        assert_eq!(code, Some(3), "{err}");
        assert!(err.contains("observer 'slow' (pid") && err.contains("published no sample for step 100 within 5 s although it ran or waited for a core") && err.contains("stall limit"), "{err}");
        assert!(took < Duration::from_secs(11), "took {took:?}");
    }
    // A limit below the 5 s of the blocked check is refused, naming the option.
    let s = Scratch::new("busy-bad-limit");
    let path = with_busy_observer(&s, 0.0, "");
    let (code, err, _) = run_checked(&s, &path, &["--stall-timeout", "1"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--stall-timeout: 1 s must be between 5 s"),
        "{err}"
    );
}

/// Busy loops of our own, one per core, starve the ring: the seed-002 runs (cut to 3 s of
/// simulated time: the load makes them ~30× slower) and a Python plant's still finish, and the
/// seed-002 ones record what the same run records in one process, bit for bit.
#[test]
fn seed002_runs_finish_under_a_cpu_hog_on_both_cores() {
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
    let mut hogs: Vec<std::process::Child> = (0..cores)
        .map(|_| {
            std::process::Command::new("sh")
                .args(["-c", "while :; do :; done"])
                .spawn()
                .unwrap()
        })
        .collect();
    let result = std::panic::catch_unwind(|| {
        for (name, seconds) in [
            ("seed002-sine", 3.0),
            ("seed002-actuator-faults", 3.0),
            ("cartpole-python-plant", 1.0),
        ] {
            let s = Scratch::new(&format!("hog-{name}"));
            let path = variant(&s, name, seconds, false);
            // The variant lives in the scratch directory: its components by absolute path.
            let text = std::fs::read_to_string(&path).unwrap().replace(
                "\"../components/",
                &format!("\"{}/components/", repo().display()),
            );
            std::fs::write(&path, text).unwrap();
            let (code, err, _) = run_checked(&s, &path, &[]);
            assert_eq!(code, Some(0), "{name} under load: {err}");
            if name.starts_with("cartpole") {
                continue;
            }
            let ip = launcher(&s)
                .arg("run")
                .arg(&path)
                .args(["--mode", "in-process", "--out"])
                .arg(s.join("ip"))
                .output()
                .unwrap();
            assert!(
                ip.status.success(),
                "{name}: {}",
                String::from_utf8_lossy(&ip.stderr)
            );
            let cmp = launcher(&s)
                .arg("compare")
                .arg(s.join(&format!("out/{name}.rrd")))
                .arg(s.join(&format!("ip/{name}.rrd")))
                .output()
                .unwrap();
            assert!(
                String::from_utf8_lossy(&cmp.stdout).contains("bit for bit"),
                "{name}: {}",
                String::from_utf8_lossy(&cmp.stdout)
            );
        }
    });
    for h in &mut hogs {
        let _ = h.kill();
        let _ = h.wait();
    }
    if let Err(e) = result {
        std::panic::resume_unwind(e);
    }
}
