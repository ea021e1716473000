//! Every count and size from the user is checked before anything starts — against a
//! documented limit (docs/security.md, **Limits**) or the machine's disk
//! and memory — and refused as bad input: exit 2, one line naming the flag or the field, no
//! panic, no output.

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

use tests::*;

/// Runs the launcher with `args` (and `--out <scratch>/out` when `out`), killed after 10 s (a
/// limit not checked starts what it bounds); asserts the refusal and returns its line.
fn refused(s: &Scratch, args: &[&str], out: bool, named: &str) -> String {
    let out_dir = s.join("out");
    let mut c = launcher(s);
    c.args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    if out {
        c.arg("--out").arg(&out_dir);
    }
    let mut child = c.spawn().unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!(
                "{args:?}: not refused, still running after 10 s: {:?}",
                text(&child.wait_with_output().unwrap())
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = child.wait_with_output().unwrap();
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: not one line: {err}"
    );
    assert!(err.contains(named), "{args:?}: '{named}' not named: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(!out_dir.exists(), "{args:?}: output written");
    err
}

#[test]
fn command_line_counts_are_bounded() {
    let s = Scratch::new("limits-cli");
    let sine = scenario("seed002-sine");
    let sine = sine.to_str().unwrap();
    refused(
        &s,
        &["sweep", sine, "--runs", "18446744073709551615"],
        true,
        "--runs 18446744073709551615: at most 100000",
    );
    refused(
        &s,
        &["sweep", sine, "--runs", "1000000000000"],
        true,
        "--runs 1000000000000",
    );
    refused(
        &s,
        &["sweep", sine, "--runs", "4", "--jobs", "0"],
        true,
        "--jobs 0",
    );
    refused(
        &s,
        &["run", sine, "--realtime", "--speed", "1e-300"],
        true,
        "--speed 1e-300: must be from 0.001 to 1000000",
    );
    refused(
        &s,
        &["run", sine, "--realtime", "--speed", "1e9"],
        true,
        "--speed",
    );
    refused(&s, &["bench", "--steps", "0"], false, "--steps 0");
    refused(
        &s,
        &["bench", "--steps", "100000000000"],
        false,
        "--steps 100000000000",
    );
    refused(
        &s,
        &["bench", "--states", "3,1000000"],
        false,
        "--states 1000000",
    );
}

/// `name.toml` in the scratch directory: the shipped `base` with `edit` applied.
fn edited(s: &Scratch, base: &str, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(scenario(base)).unwrap();
    let p = s.join(&format!("{name}.toml"));
    std::fs::write(&p, edit(text)).unwrap();
    p
}

fn replace(text: String, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

/// `k` Luenberger observers named `extra<i>`.
fn observers(k: usize) -> String {
    (1..=k).map(|i| format!("\n[[observer]]\nname = \"extra{i}\"\nkind = \"luenberger\"\npoles = [-1.0, -2.0, -3.0]\n")).collect()
}

/// Asserts `path` is refused as `file:line:col: field: …`.
fn refused_scenario(s: &Scratch, path: &Path, field: &str) -> String {
    let err = refused(
        s,
        &["run", path.to_str().unwrap()],
        true,
        &format!(": {field}: "),
    );
    let file = path.file_name().unwrap().to_str().unwrap();
    let at = err.split(file).nth(1).unwrap_or_default();
    let mut parts = at.splitn(4, ':');
    let (_, line, col) = (
        parts.next(),
        parts.next().unwrap_or(""),
        parts.next().unwrap_or(""),
    );
    assert!(
        line.parse::<usize>().is_ok() && col.parse::<usize>().is_ok(),
        "no line:col: {err}"
    );
    err
}

#[test]
fn scenario_counts_are_bounded_with_their_field() {
    let s = Scratch::new("limits-scenario");
    for w in ["1000000000000", "2000000000"] {
        let rms = |t: String| {
            replace(
                t,
                "evaluation = \"chi2\"\nfalse_alarm = 1e-4",
                &format!("evaluation = \"rms\"\nwindow = {w}\nthreshold = 1.0"),
            )
        };
        let p = edited(&s, "seed002-actuator-faults", &format!("window-{w}"), rms);
        refused_scenario(&s, &p, "diagnoser[1].window");
    }
    let p = edited(&s, "seed002-actuator-faults", "calibrate-runs", |t| {
        replace(t, "false_alarm = 1e-4", "calibrate = { runs = 1000000000 }")
    });
    refused_scenario(&s, &p, "diagnoser[1].calibrate.runs");
    let many: String = (1..=65).map(|i| format!("\n[[fault]]\nname = \"f{i}\"\ntarget = \"actuator\"\nchannel = 1\nkind = \"additive\"\nvalue = 0.1\nstart = 5.0\n")).collect();
    let p = edited(&s, "seed002-actuator-faults", "faults", |t| {
        replace(t, "\n[[observer]]", &format!("{many}\n[[observer]]"))
    });
    refused_scenario(&s, &p, "fault[65]");
}

/// The subscriber cap: 7 observer processes (a bank's members share one) run across
/// processes; the 8th is refused at validation, naming the entry that goes past it.
#[test]
fn observers_are_capped_by_the_services_subscribers() {
    let s = Scratch::new("limits-observers");
    // 2 observers + 2 bank members + 3 = 7: runs.
    let seven = edited(&s, "seed002-actuator-faults", "seven", |t| {
        let t = replace(t, "duration = 20.0", "duration = 0.5");
        let t = t.split("\n[expect]").next().unwrap().to_string();
        replace(
            t,
            "\n[controller]",
            &format!("{}\n[controller]", observers(3)),
        )
    });
    let o = launcher(&s)
        .arg("run")
        .arg(&seven)
        .arg("--out")
        .arg(s.join("out-seven"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    // 2 + 5 = 7 of its own, and the bank's process is the 8th.
    let bank = edited(&s, "seed002-actuator-faults", "bank", |t| {
        replace(
            t,
            "\n[controller]",
            &format!("{}\n[controller]", observers(5)),
        )
    });
    let err = refused_scenario(&s, &bank, "diagnoser[1]");
    assert!(
        err.contains(
            "8 observer processes (7 [[observer]] + 1 for bank members, one per bank); at most 7"
        ),
        "{err}"
    );
    let own = edited(&s, "seed002-sine", "own", |t| {
        replace(
            t,
            "\n[controller]",
            &format!("{}\n[controller]", observers(6)),
        )
    });
    refused_scenario(&s, &own, "observer[8]");
}

/// A recording the output directory's file system cannot hold is refused before it is begun:
/// seed002-sine for 10⁹ steps would take about 0.5 TB.
#[test]
fn a_recording_larger_than_the_free_disk_is_refused() {
    let s = Scratch::new("limits-disk");
    let huge = edited(&s, "seed002-sine", "huge", |t| {
        replace(t, "duration = 20.0", "duration = 1000000.0")
    });
    let free = free_bytes(&s.0);
    if free > 400_000_000_000 {
        tests::skip(
            "a_recording_larger_than_the_free_disk_is_refused",
            &format!("{free} bytes free, more than the recording would take"),
        );
        return;
    }
    let err = refused(
        &s,
        &["run", huge.to_str().unwrap()],
        true,
        "the recording would take about",
    );
    // The estimate counts the signals a recording of this scenario holds.
    let short = edited(&s, "seed002-sine", "short", |t| {
        replace(t, "duration = 20.0", "duration = 0.1")
            .split("\n[expect]")
            .next()
            .unwrap()
            .to_string()
    });
    let o = launcher(&s)
        .arg("run")
        .arg(&short)
        .arg("--out")
        .arg(s.join("short"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    let signals = read(&s.join("short/seed002-sine.rrd"))
        .unwrap()
        .series
        .len();
    assert!(
        err.contains(&format!(
            "(1000000000 recorded steps × ({signals} signals × 8 bytes + "
        )) && err.contains("--record-every"),
        "{signals} signals: {err}"
    );
    // Thinned, it would fit: only the recorded steps count. (An output "directory" that is a
    // file stops it at the next check, before it runs.)
    std::fs::write(s.join("a-file"), "").unwrap();
    let o = launcher(&s)
        .arg("run")
        .arg(&huge)
        .args(["--record-every", "1000000", "--out"])
        .arg(s.join("a-file"))
        .output()
        .unwrap();
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("cannot create the output directory"), "{err}");
}

/// Free bytes of the file system holding `dir` (df, in 1K blocks).
fn free_bytes(dir: &Path) -> u64 {
    let o = std::process::Command::new("df")
        .args(["-Pk"])
        .arg(dir)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    let kib: u64 = out
        .lines()
        .nth(1)
        .and_then(|l| l.split_whitespace().nth(3))
        .and_then(|v| v.parse().ok())
        .unwrap();
    kib * 1024
}
