//! Components we did not write join a run through PROTOCOL.md — and one that breaks
//! it is named, stops the run quickly, and leaves nothing behind.

use std::process::Stdio;
use std::time::{Duration, Instant};

use tests::*;

/// seed002-sine in open loop (the observers are in the ring) with a third observer, `bad`, run by
/// the given command and params.
fn with_bad_observer(s: &Scratch, seconds: u32, command: &str, params: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let text = text
        .split("\n[controller]")
        .next()
        .unwrap()
        .replace("duration = 20.0", &format!("duration = {seconds}.0"));
    let text = format!(
        "{text}\n[[observer]]\nname = \"bad\"\nkind = \"process\"\ncommand = {command}\nparams = {params}\n"
    );
    let p = s.join("bad.toml");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_component_that_breaks_the_protocol_is_named_and_nothing_is_left() {
    let cases: [(&str, &[&str]); 10] = [
        (
            "nan",
            &["observer 'bad' broke the protocol at step 100", "is NaN"],
        ),
        (
            "wrong_step",
            &[
                "observer 'bad' broke the protocol at step 100",
                "of step 101",
            ],
        ),
        (
            "wrong_len",
            &[
                "observer 'bad' broke the protocol at step 0",
                "4 values",
                "says 3",
            ],
        ),
        (
            "protocol",
            &[
                "observer 'bad' broke the protocol at step 100",
                "protocol version 2",
            ],
        ),
        ("exit", &["observer 'bad' (pid", "exited with status 7"]),
        (
            "exit0",
            &[
                "observer 'bad' (pid",
                "exited with status 0 before the end of the run",
                "its last sample: of step 99",
            ],
        ),
        ("orphan", &["observer 'bad' (pid", "exited with status 7"]),
        (
            "no_read",
            &[
                "observer 'bad' broke the protocol at step",
                "does not read its input",
            ],
        ),
        ("kill", &["observer 'bad' (pid", "SIGKILL"]),
        (
            "refuse_version",
            &[
                "observer 'bad' (pid",
                "before the run began",
                "protocol version 1, this component 2",
            ],
        ),
    ];
    for (fault, want) in cases {
        let s = Scratch::new(&format!("bad-{fault}"));
        let path = with_bad_observer(
            &s,
            600,
            r#"["faulty_observer"]"#,
            &format!("{{ fault = \"{fault}\" }}"),
        );
        let (code, err, took) = run_checked(&s, &path, &[]);
        assert_eq!(code, Some(3), "{fault}: {err}");
        assert!(want.iter().all(|w| err.contains(w)), "{fault}: {err}");
        assert!(took < Duration::from_secs(5), "{fault}: took {took:?}");
    }
}

#[test]
fn a_hung_component_is_named_within_the_stall_timeout() {
    let s = Scratch::new("bad-hang");
    let path = with_bad_observer(&s, 600, r#"["faulty_observer"]"#, r#"{ fault = "hang" }"#);
    let (code, err, took) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("observer 'bad' (pid") && err.contains("published no sample for step 100"),
        "{err}"
    );
    assert!(took < Duration::from_secs(9), "took {took:?}");
}

#[test]
fn a_component_that_never_says_ready_is_named() {
    let s = Scratch::new("bad-never-ready");
    let path = with_bad_observer(
        &s,
        10,
        r#"["faulty_observer"]"#,
        r#"{ fault = "never_ready" }"#,
    );
    let (code, err, took) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("observer 'bad' (pid")
            && err.contains("did not report ready within 20 s and is asleep, using no CPU"),
        "{err}"
    );
    assert!(took < Duration::from_secs(25), "took {took:?}");
}

/// A component the kernel has stopped before it said ready cannot say it: it is named after the
/// run's blocked limit (5 s), not the 20 s start-up allowance.
#[test]
fn a_component_stopped_before_ready_is_named_at_the_blocked_limit() {
    let s = Scratch::new("bad-stopped-early");
    let path = with_bad_observer(
        &s,
        10,
        r#"["faulty_observer"]"#,
        r#"{ fault = "never_ready" }"#,
    );
    let child = launcher(&s)
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(s.join("out"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lpid = child.id();
    wait_running(lpid, &["bad"]);
    signal(
        component_pid(lpid, "bad").expect("bad observer running"),
        libc::SIGSTOP,
    );
    let stopped = Instant::now();
    let out = child.wait_with_output().unwrap();
    let took = stopped.elapsed();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("observer 'bad' (pid")
            && err.contains("did not report ready within")
            && err.contains("and is stopped"),
        "{err}"
    );
    assert!(took < Duration::from_secs(10), "took {took:?}");
    assert_clean(&s, lpid);
}

#[test]
fn a_command_that_does_not_exist_is_named() {
    let s = Scratch::new("bad-command");
    let path = with_bad_observer(&s, 10, r#"["./no_such_program_uio"]"#, "{}");
    let (code, err, _) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("cannot start observer 'bad'") && err.contains("no_such_program_uio"),
        "{err}"
    );
    // Nothing ran, so nothing is left: no recording, no summary, and a retry needs no --force.
    assert!(
        !s.join("out/seed002-sine.rrd").exists()
            && !s.join("out/seed002-sine.summary.json").exists()
    );
    let (code, err, _) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(!err.contains("already exists"), "{err}");
}

/// The built-in linear plant rebuilt from the protocol's configuration alone, run as an
/// external process, gives the built-in plant's recording bit for bit.
#[test]
fn an_external_rust_plant_reproduces_the_built_in_one_bit_for_bit() {
    let s = Scratch::new("external-linear");
    let body = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let body = body.replacen(
        "x0 = [1.0, -1.0, 2.0]\n",
        "x0 = [1.0, -1.0, 2.0]\n\n[plant.process]\ncommand = [\"linear_plant\"]\n",
        1,
    );
    let path = s.join("seed002-sine.toml");
    std::fs::write(&path, body).unwrap();
    let out = launcher(&s)
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(s.join("ext"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let out = launcher(&s)
        .arg("run")
        .arg(scenario("seed002-sine"))
        .arg("--out")
        .arg(s.join("builtin"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let cmp = launcher(&s)
        .arg("compare")
        .arg(s.join("ext/seed002-sine.rrd"))
        .arg(s.join("builtin/seed002-sine.rrd"))
        .output()
        .unwrap();
    let (stdout, _) = text(&cmp);
    assert!(
        cmp.status.success() && stdout.contains("bit for bit"),
        "{stdout}"
    );
}

/// In-process mode cannot run someone else's process: refused before anything is written.
#[test]
fn in_process_mode_refuses_external_components() {
    let s = Scratch::new("external-in-process");
    let out = launcher(&s)
        .arg("run")
        .arg(scenario("dc-motor-friction"))
        .args(["--mode", "in-process", "--out"])
        .arg(s.join("out"))
        .output()
        .unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("the plant is an external process"), "{err}");
    assert!(!s.join("out").exists() || std::fs::read_dir(s.join("out")).unwrap().next().is_none());
}

/// A Python component (the kit on iceoryx2's Python binding) that hangs inside its step stops
/// the run within the stall timeout, named.
#[test]
fn a_python_component_that_hangs_in_its_step_is_named() {
    let s = Scratch::new("python-hang");
    std::fs::write(
        s.join("hang.py"),
        "import time\nimport uio_component\n\ndef step(k, inputs):\n    if k == 100:\n        time.sleep(3600)\n    return inputs[0][:3]\n\nuio_component.run(step)\n",
    )
    .unwrap();
    let path = with_bad_observer(&s, 600, r#"["python3", "hang.py"]"#, "{}");
    let (code, err, took) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("observer 'bad' (pid") && err.contains("published no sample for step 100"),
        "{err}"
    );
    assert!(took < Duration::from_secs(12), "took {took:?}");
}

/// The kit's own version check: a component told the run speaks another protocol version
/// refuses to start (exit 2, one line), and the launcher names it.
#[test]
fn the_kit_refuses_another_protocol_version() {
    let s = Scratch::new("kit-version");
    let text = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let plant = bin_dir().join("linear_plant");
    let process = format!(
        "\n[plant.process]\ncommand = [\"env\", \"UIO_PROTOCOL=2\", {:?}]\n",
        plant.display().to_string()
    );
    let text = text.replacen(
        "x0 = [1.0, -1.0, 2.0]\n",
        &format!("x0 = [1.0, -1.0, 2.0]\n{process}"),
        1,
    );
    let path = s.join("version.toml");
    std::fs::write(&path, text).unwrap();
    let (code, err, _) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("plant (pid")
            && err.contains("exited with status 2")
            && err.contains("before the run began")
            && err.contains("protocol version 2, this component 1"),
        "{err}"
    );
}

/// A plant's params that JSON cannot carry are refused with the key named.
#[test]
fn params_must_be_representable_in_json() {
    let s = Scratch::new("params-json");
    let path = with_bad_observer(
        &s,
        10,
        r#"["faulty_observer"]"#,
        "{ fault = \"nan\", gain = nan }",
    );
    let out = launcher(&s).arg("run").arg(&path).output().unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("observer[3].params.gain") && err.contains("not a finite number"),
        "{err}"
    );
}

/// Stamps a component could forge are checked too — a `taken_ns` of u64::MAX (later
/// than it sent the sample, later than the launcher received it) hides that it did not read its
/// input, and a `sim_time` that is not a number is no time at all.
#[test]
fn forged_stamps_break_the_protocol() {
    for (fault, want) in [
        (
            "taken_max",
            "took its input at 18446744073709551615 ns, after it sent the sample",
        ),
        ("nan_time", "sim_time is NaN"),
    ] {
        let s = Scratch::new(&format!("bad-{fault}"));
        let path = with_bad_observer(
            &s,
            10,
            r#"["faulty_observer"]"#,
            &format!("{{ fault = \"{fault}\" }}"),
        );
        let (code, err, took) = run_checked(&s, &path, &[]);
        assert_eq!(code, Some(3), "{fault}: {err}");
        assert!(
            err.contains("observer 'bad' broke the protocol at step 100") && err.contains(want),
            "{fault}: {err}"
        );
        assert!(took < Duration::from_secs(5), "{fault}: took {took:?}");
    }
}

/// A component that closes its stdout before `ready` (and lives on) cannot report
/// ready: it is named at once, not after the 20 s the launcher waits for `ready`.
#[test]
fn a_component_that_closes_its_stdout_before_ready_is_named_at_once() {
    let s = Scratch::new("bad-close-stdout");
    let path = with_bad_observer(
        &s,
        10,
        r#"["faulty_observer"]"#,
        r#"{ fault = "close_stdout" }"#,
    );
    let (code, err, took) = run_checked(&s, &path, &[]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("observer 'bad' (pid")
            && err.contains("closed its stdout before it reported ready"),
        "{err}"
    );
    assert!(took < Duration::from_secs(3), "took {took:?}");
}
