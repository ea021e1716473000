//! The command line's rough edges — a closed stdout, scenarios named
//! instead of pathed, `list`'s checks, progress on a terminal, and thinned or restricted
//! recordings.

use std::io::Read;
use std::os::fd::{FromRawFd, OwnedFd};
use std::process::Stdio;

use tests::*;

/// A pipe whose read end is already closed: every write to the other end fails with EPIPE.
fn broken_pipe() -> Stdio {
    let mut fds = [0; 2];
    // SAFETY: pipe(2) fills two fds we then own.
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
    // SAFETY: both fds are fresh and owned here; the read end is closed at once.
    let (read, write) = unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
    drop(read);
    Stdio::from(write)
}

#[test]
fn a_closed_stdout_is_not_a_panic() {
    let s = Scratch::new("epipe");
    let rrd = s.join("out/seed003-charlie-open-loop.rrd");
    assert!(
        run(
            &s,
            &scenario("seed003-charlie-open-loop"),
            &["--mode", "in-process"]
        )
        .status
        .success()
    );
    let commands: Vec<Vec<std::ffi::OsString>> = vec![
        vec!["list".into()],
        vec!["design".into(), scenario("seed002-sine").into()],
        vec!["inspect".into(), rrd.clone().into()],
        vec!["compare".into(), rrd.clone().into(), rrd.clone().into()],
    ];
    for args in commands {
        let out = launcher(&s)
            .args(&args)
            .stdout(broken_pipe())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn a_shipped_scenario_is_run_by_its_name() {
    let s = Scratch::new("by-name");
    // The name `list` prints, from a directory with no scenarios/ of its own.
    let out = launcher(&s)
        .args([
            "run",
            "seed003-charlie-open-loop",
            "--mode",
            "in-process",
            "--out",
        ])
        .arg(s.join("out"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    assert!(s.join("out/seed003-charlie-open-loop.rrd").is_file());
    let out = launcher(&s)
        .args(["design", "seed002-sine"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    // An unknown name says so, and where it looked.
    let out = launcher(&s)
        .args(["run", "no-such-scenario"])
        .output()
        .unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no-such-scenario") && err.contains("uio-launcher list"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn list_flags_duplicates_and_refuses_a_missing_directory() {
    let s = Scratch::new("list");
    let dir = s.join("scenarios");
    std::fs::create_dir_all(&dir).unwrap();
    let text_ = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    std::fs::write(dir.join("a.toml"), &text_).unwrap();
    std::fs::write(dir.join("b.toml"), &text_).unwrap();
    std::fs::write(
        dir.join("c.toml"),
        text_.replace("name = \"seed002-sine\"", "name = \"other\""),
    )
    .unwrap();
    let out = launcher(&s)
        .arg("list")
        .arg("--dir")
        .arg(&dir)
        .output()
        .unwrap();
    let (stdout, err) = text(&out);
    assert!(out.status.success(), "{err}");
    let dup: Vec<&str> = stdout.lines().filter(|l| l.contains("duplicate")).collect();
    assert_eq!(dup.len(), 2, "{stdout}");
    assert!(
        dup.iter()
            .all(|l| l.contains("a.toml") && l.contains("b.toml")),
        "{stdout}"
    );
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("other") && !l.contains("duplicate")),
        "{stdout}"
    );
    let out = launcher(&s)
        .args(["list", "--dir", "/nonexistent-uio-dir"])
        .output()
        .unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("/nonexistent-uio-dir"), "{err}");
}

/// Opens a pseudo-terminal; returns (master, slave).
fn pty() -> (std::fs::File, OwnedFd) {
    let (mut master, mut slave) = (0, 0);
    // SAFETY: openpty fills two fds we then own; the name, termios and winsize are not wanted.
    let rc = unsafe {
        libc::openpty(
            &mut master,
            &mut slave,
            std::ptr::null_mut(),
            std::ptr::null(),
            std::ptr::null(),
        )
    };
    assert_eq!(rc, 0, "openpty");
    // SAFETY: fresh fds owned here.
    unsafe {
        (
            std::fs::File::from_raw_fd(master),
            OwnedFd::from_raw_fd(slave),
        )
    }
}

#[test]
fn a_long_run_shows_progress_on_a_terminal_only() {
    let s = Scratch::new("progress");
    // Long enough to take more than a second across processes; thinly recorded.
    let path = variant(&s, "seed002-sine", 600.0, false);
    let args = ["--record-every", "1000", "--out"];
    // stderr on a terminal: a progress bar.
    let (mut master, slave) = pty();
    let reader = std::thread::spawn(move || {
        let mut seen = Vec::new();
        let mut buf = [0u8; 4096];
        // Until the last holder of the slave (the launcher) is gone: EIO.
        while let Ok(n) = master.read(&mut buf) {
            if n == 0 {
                break;
            }
            seen.extend_from_slice(&buf[..n]);
        }
        String::from_utf8_lossy(&seen).into_owned()
    });
    let status = launcher(&s)
        .arg("run")
        .arg(&path)
        .args(args)
        .arg(s.join("tty"))
        .stdout(Stdio::null())
        .stderr(Stdio::from(slave))
        .status()
        .unwrap();
    let seen = reader.join().unwrap();
    assert!(status.success(), "{seen}");
    assert!(
        seen.contains("/600000 steps"),
        "no progress shown: {seen:?}"
    );
    // stderr not a terminal: nothing but what a run always says.
    let out = launcher(&s)
        .arg("run")
        .arg(&path)
        .args(args)
        .arg(s.join("pipe"))
        .output()
        .unwrap();
    let (_, err) = text(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.is_empty(), "{err:?}");
}

#[test]
fn recording_can_be_thinned_and_restricted() {
    let s = Scratch::new("record-every");
    let name = "seed002-sine";
    let full = s.join("full");
    let out = launcher(&s)
        .arg("run")
        .arg(scenario(name))
        .args(["--mode", "in-process", "--out"])
        .arg(&full)
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let thin = s.join("thin");
    let out = launcher(&s)
        .arg("run")
        .arg(scenario(name))
        .args(["--mode", "in-process", "--record-every", "10", "--out"])
        .arg(&thin)
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let (a, b) = (
        read(&full.join(format!("{name}.rrd"))).unwrap(),
        read(&thin.join(format!("{name}.rrd"))).unwrap(),
    );
    let x = a
        .series
        .keys()
        .find(|k| k.starts_with("/plant/x/"))
        .unwrap()
        .clone();
    assert_eq!(a.series[&x].values.len(), 20_000);
    assert_eq!(b.series[&x].values.len(), 2_000);
    assert!(b.series[&x].steps.iter().all(|k| k % 10 == 0));
    for (i, k) in b.series[&x].steps.iter().enumerate() {
        assert_eq!(
            b.series[&x].values[i].to_bits(),
            a.series[&x].values[*k as usize].to_bits()
        );
    }
    // The figures are computed on every step all the same.
    let sum = |dir: &std::path::Path| -> serde_json::Value {
        serde_json::from_str(
            &std::fs::read_to_string(dir.join(format!("{name}.summary.json"))).unwrap(),
        )
        .unwrap()
    };
    let (sa, sb) = (sum(&full), sum(&thin));
    assert_eq!(sa["observers"], sb["observers"]);
    assert_eq!(sa["differences"], sb["differences"]);
    assert!(
        std::fs::metadata(thin.join(format!("{name}.rrd")))
            .unwrap()
            .len()
            * 5
            < std::fs::metadata(full.join(format!("{name}.rrd")))
                .unwrap()
                .len()
    );

    // Only what matches a --record glob is written.
    let some = s.join("some");
    let out = launcher(&s)
        .arg("run")
        .arg(scenario(name))
        .args([
            "--mode",
            "in-process",
            "--record",
            "/plant/x/*",
            "--record",
            "/observer/uio/**",
            "--out",
        ])
        .arg(&some)
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let r = read(&some.join(format!("{name}.rrd"))).unwrap();
    assert!(!r.series.is_empty());
    for k in r.series.keys() {
        assert!(
            k.starts_with("/plant/x/") || k.starts_with("/observer/uio/"),
            "{k} recorded"
        );
    }
    let wanted: Vec<&String> = a
        .series
        .keys()
        .filter(|k| k.starts_with("/plant/x/") || k.starts_with("/observer/uio/"))
        .collect();
    assert_eq!(r.series.keys().collect::<Vec<_>>(), wanted);
    assert_eq!(
        r.series
            .keys()
            .filter(|k| k.starts_with("/plant/x/"))
            .count(),
        3
    );
    assert_eq!(sum(&some)["observers"], sa["observers"]);
    assert!(
        !text(&out).1.contains("matches no signal"),
        "{:?}",
        text(&out)
    );

    // A glob that selects nothing (a typo) is warned of.
    let out = launcher(&s)
        .arg("run")
        .arg(scenario(name))
        .args(["--mode", "in-process", "--record", "/plant/z/*", "--out"])
        .arg(s.join("none"))
        .output()
        .unwrap();
    assert!(
        out.status.success()
            && text(&out)
                .1
                .contains("warning: --record '/plant/z/*': matches no signal"),
        "{:?}",
        text(&out)
    );

    // A bad glob and a zero step are bad input, before any output.
    for (args, what) in [
        (["--record", "/plant/[x"], "/plant/[x"),
        (["--record-every", "0"], "record-every"),
    ] {
        let dir = s.join("bad");
        let out = launcher(&s)
            .arg("run")
            .arg(scenario(name))
            .args(args)
            .arg("--out")
            .arg(&dir)
            .output()
            .unwrap();
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(what), "{err}");
        assert!(!dir.exists());
    }
}
