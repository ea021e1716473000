//! A crashed component, an interrupted launcher, a stale run, parallel runs, and
//! components started by hand — with real processes, checked from outside.

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use tests::*;

/// seed002-sine stretched to `seconds` of simulated time (1000 steps per second).
fn long_scenario(s: &Scratch, seconds: u32) -> PathBuf {
    let text = std::fs::read_to_string(scenario("seed002-sine"))
        .unwrap()
        .replace("duration = 20.0", &format!("duration = {seconds}.0"));
    let text = text.split("\n[expect]").next().unwrap().to_string();
    let p = s.join("long.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn start(s: &Scratch, scenario: &PathBuf, extra: &[&str]) -> Child {
    launcher(s)
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(s.join("out"))
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// A reproducible pseudo-random delay (ms) in [lo, hi).
fn delay(seed: u64, lo: u64, hi: u64) -> Duration {
    let x = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407)
        >> 33;
    Duration::from_millis(lo + x % (hi - lo))
}

/// Waits for the launcher, returning its output and how long it took after `since`.
fn finish(child: Child, since: Instant) -> (std::process::Output, Duration) {
    let out = child.wait_with_output().unwrap();
    (out, since.elapsed())
}

#[test]
fn a_killed_component_stops_the_run_cleanly() {
    let names = ["plant", "uio", "luenberger", "controller"];
    for (i, victim) in names.iter().enumerate() {
        for trial in 0..2u64 {
            let s = Scratch::new(&format!("kill-{victim}-{trial}"));
            let path = long_scenario(&s, 600);
            let child = start(&s, &path, &[]);
            let lpid = child.id();
            wait_running(lpid, &names);
            wait_stepping(&s.join("out/seed002-sine.rrd.partial"));
            std::thread::sleep(delay(i as u64 * 10 + trial, 50, 500));
            let pid = component_pid(lpid, victim).expect("victim running");
            signal(pid, libc::SIGKILL);
            let killed = Instant::now();
            let (out, took) = finish(child, killed);
            let (_, err) = text(&out);
            assert!(
                took < Duration::from_secs(2),
                "{victim}: the launcher took {took:?}"
            );
            assert_eq!(out.status.code(), Some(3), "{victim}: {err}");
            let label = match *victim {
                "uio" | "luenberger" => format!("observer '{victim}'"),
                other => other.to_string(),
            };
            assert!(
                err.contains(&label)
                    && err.contains("SIGKILL")
                    && err.contains("last completed step"),
                "{victim}: {err}"
            );
            assert_clean(&s, lpid);
            let r = read(&s.join("out/seed002-sine.rrd")).unwrap();
            assert!(r.complete, "{victim}: recording not finalised");
            let steps = r.series["/plant/x/1"].values.len();
            assert!(
                steps > 0 && steps < 600_000,
                "{victim}: {steps} steps recorded"
            );
            let sum = summary(&s, "seed002-sine");
            assert!(
                sum["stopped"].as_str().unwrap().contains("SIGKILL"),
                "{sum}"
            );
        }
    }
}

/// Kills a launcher with SIGKILL mid-run (`shared`: with the machine's /dev/shm) and waits for
/// its components to die with it; returns the dead launcher's pid.
fn kill_mid_run(s: &Scratch, path: &PathBuf, shared: bool) -> u32 {
    let mut cmd = launcher(s);
    cmd.arg("run")
        .arg(path)
        .arg("--out")
        .arg(s.join("out"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if shared {
        cmd.env(lockstep::private_shm::SHARED_ENV, "1");
    }
    let child = cmd.spawn().unwrap();
    let dead = child.id();
    wait_running(dead, &["plant", "uio", "luenberger", "controller"]);
    signal(dead as i32, libc::SIGKILL);
    let _ = child.wait_with_output();
    // The components die with their launcher.
    let deadline = Instant::now() + Duration::from_secs(2);
    while !processes_of(dead).is_empty() {
        assert!(
            Instant::now() < deadline,
            "components outlived their launcher: {:?}",
            processes_of(dead)
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    dead
}

#[test]
fn a_run_killed_with_sigkill_leaves_no_shared_memory_on_the_machine() {
    // As root the run's /dev/shm is a tmpfs of its own mount namespace: it goes with the last
    // process in it. Elsewhere the run uses the machine's and the next test's cleanup applies.
    if unsafe { libc::geteuid() } != 0 {
        tests::skip(
            "a_run_killed_with_sigkill_leaves_no_shared_memory_on_the_machine",
            "needs root (a private /dev/shm)",
        );
        return;
    }
    let s = Scratch::new("killed");
    let path = long_scenario(&s, 100);
    let dead = kill_mid_run(&s, &path, false);
    assert!(
        shm_of(dead).is_empty(),
        "shared memory left on the machine: {:?}",
        shm_of(dead)
    );
    assert!(s.join("out/seed002-sine.rrd.partial").exists());
}

#[test]
fn a_run_after_a_dead_one_cleans_up_and_succeeds() {
    let s = Scratch::new("stale");
    let path = long_scenario(&s, 100);
    // With the machine's /dev/shm, what a killed run leaves stays until the next run.
    let dead = kill_mid_run(&s, &path, true);
    assert!(
        !shm_of(dead).is_empty(),
        "the killed run should have left shared memory to clean"
    );
    assert!(s.join("out/seed002-sine.rrd.partial").exists());
    // Same scenario, same output directory.
    let next = start(&s, &path, &[]);
    let npid = next.id();
    let out = next.wait_with_output().unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    assert!(
        shm_of(dead).is_empty(),
        "stale shared memory left: {:?}",
        shm_of(dead)
    );
    assert_clean(&s, npid);
    assert!(read(&s.join("out/seed002-sine.rrd")).unwrap().complete);
    // And the killed run's partial recording is still readable, marked incomplete.
}

#[test]
fn four_parallel_runs_give_what_each_gives_alone() {
    let names = [
        "seed002-sine",
        "seed003-charlie-open-loop",
        "seed004-projection-uio-piecewise",
        "seed001-missile-full-order",
    ];
    let runs: Vec<(Scratch, Child)> = names
        .iter()
        .map(|n| {
            let s = Scratch::new(&format!("parallel-{n}"));
            let c = start(&s, &scenario(n), &[]);
            (s, c)
        })
        .collect();
    let mut done = Vec::new();
    for (s, c) in runs {
        let pid = c.id();
        let out = c.wait_with_output().unwrap();
        assert!(out.status.success(), "{:?}", text(&out));
        assert_clean(&s, pid);
        done.push(s);
    }
    for (n, s) in names.iter().zip(&done) {
        let alone = Scratch::new(&format!("alone-{n}"));
        let out = run(&alone, &scenario(n), &["--mode", "in-process"]);
        assert!(out.status.success());
        let (a, b) = (
            read(&s.join(&format!("out/{n}.rrd"))).unwrap(),
            read(&alone.join(&format!("out/{n}.rrd"))).unwrap(),
        );
        let (ta, tb) = (trajectories(&a), trajectories(&b));
        assert_eq!(ta.len(), tb.len());
        for ((ka, sa), (_, sb)) in ta.iter().zip(&tb) {
            assert!(
                sa.values
                    .iter()
                    .zip(&sb.values)
                    .all(|(x, y)| x.to_bits() == y.to_bits())
                    && sa.values.len() == sb.values.len(),
                "{n}: {ka} differs"
            );
        }
    }
}

#[test]
fn components_started_by_hand_say_how_to_start_them() {
    for kind in ["plant", "observer", "controller"] {
        let bin = lockstep::programs::builtin(kind);
        for args in [&[][..], &["--run", "nosuchrun1", "--name", "x"][..]] {
            let started = Instant::now();
            let out = Command::new(bin_dir().join(&bin))
                .args(args)
                .stdin(Stdio::null())
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(started.elapsed() < Duration::from_secs(1));
            assert_eq!(out.status.code(), Some(2), "{bin} {args:?}: {err}");
            assert!(
                err.contains("started by the launcher"),
                "{bin} {args:?}: {err}"
            );
            if !args.is_empty() {
                assert!(err.contains("no run 'nosuchrun1'"), "{err}");
            }
        }
    }
}

/// A signal to the launcher stops the run like a failed component — components stopped,
/// recording closed, nothing left behind — with exit code `code`, in both modes.
fn a_signal_stops_the_run_cleanly(sig: i32, name: &str, code: i32) {
    for mode in ["processes", "in-process"] {
        let s = Scratch::new(&format!("{name}-{mode}"));
        let path = long_scenario(&s, if mode == "in-process" { 20_000 } else { 600 });
        let child = start(&s, &path, &["--mode", mode]);
        let lpid = child.id();
        if mode == "processes" {
            wait_running(lpid, &["plant", "uio", "luenberger", "controller"]);
        }
        wait_stepping(&s.join("out/seed002-sine.rrd.partial"));
        signal(lpid as i32, sig);
        let sent = Instant::now();
        let (out, took) = finish(child, sent);
        let (_, err) = text(&out);
        assert!(
            took < Duration::from_secs(2),
            "{name} {mode}: took {took:?}"
        );
        assert_eq!(out.status.code(), Some(code), "{name} {mode}: {err}");
        assert!(err.contains(name), "{name} {mode}: {err}");
        assert_clean(&s, lpid);
        let r = read(&s.join("out/seed002-sine.rrd")).unwrap();
        assert!(
            r.complete && !r.series["/plant/x/1"].values.is_empty(),
            "{name} {mode}"
        );
        let sum = summary(&s, "seed002-sine");
        assert!(sum["stopped"].as_str().unwrap().contains(name), "{sum}");
    }
}

#[test]
fn sigint_and_sigterm_stop_the_run_cleanly() {
    a_signal_stops_the_run_cleanly(libc::SIGINT, "SIGINT", 130);
    a_signal_stops_the_run_cleanly(libc::SIGTERM, "SIGTERM", 130);
}

/// A closed terminal (SIGHUP) or Ctrl-\ (SIGQUIT) stops the run like
/// SIGTERM, with exit code 128 + the signal's number.
#[test]
fn sighup_and_sigquit_stop_the_run_cleanly() {
    a_signal_stops_the_run_cleanly(libc::SIGHUP, "SIGHUP", 129);
    a_signal_stops_the_run_cleanly(libc::SIGQUIT, "SIGQUIT", 131);
}

/// Mounts a tmpfs of `size` at `dir`; the error says why it could not.
fn mount_tmpfs(dir: &std::path::Path, size: &str) -> Result<(), String> {
    std::fs::create_dir_all(dir).unwrap();
    let out = Command::new("mount")
        .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
        .arg(dir)
        .output()
        .map_err(|e| format!("cannot run mount: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "mount -t tmpfs at {} failed ({}): {}",
            dir.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

/// Fills the file system of `dir` with one file until `leave` bytes are free.
fn fill(dir: &std::path::Path, leave: u64) {
    let c = std::ffi::CString::new(dir.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: statvfs writes into the struct we own.
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    assert_eq!(unsafe { libc::statvfs(c.as_ptr(), &mut st) }, 0);
    let free = st.f_bavail as u64 * st.f_frsize as u64;
    let f = std::fs::File::create(dir.join("filler")).unwrap();
    use std::os::fd::AsRawFd;
    // SAFETY: allocates blocks for our own open file.
    assert_eq!(
        unsafe {
            libc::posix_fallocate(f.as_raw_fd(), 0, free.saturating_sub(leave) as libc::off_t)
        },
        0
    );
}

/// A full disk stops the run cleanly, naming the file and saying what of
/// the recording was kept.
#[test]
fn a_full_disk_stops_the_run_and_says_what_was_kept() {
    // Mounting needs root; as root a mount that fails is a failure of the test, not a skip.
    if unsafe { libc::geteuid() } != 0 {
        tests::skip(
            "a_full_disk_stops_the_run_and_says_what_was_kept",
            "mounting a tmpfs needs root",
        );
        return;
    }
    // The run's recording must fit the disk when it starts (the launcher refuses one that
    // cannot, exit 2), so the disk fills while it runs: a 128 MB tmpfs, a paced run, and after
    // 0.7 s — before its first batch of 4096 steps reaches the file — a filler leaves 200 kB
    // (no whole step: the partial file is removed) or 3 MB (a few thousand steps: kept).
    for (mode, leave) in [
        ("processes", 200u64 << 10),
        ("in-process", 200 << 10),
        ("processes", 3 << 20),
        ("in-process", 3 << 20),
    ] {
        let size = if leave < 1 << 20 { "200k" } else { "3m" };
        let s = Scratch::new(&format!("disk-full-{mode}-{size}"));
        let full = s.join("full");
        if let Err(why) = mount_tmpfs(&full, "128m") {
            panic!("{mode}, {size}: {why}");
        }
        let path = long_scenario(&s, 60);
        let child = launcher(&s)
            .arg("run")
            .arg(&path)
            .args(["--mode", mode, "--realtime", "--speed", "2", "--out"])
            .arg(&full)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let lpid = child.id();
        std::thread::sleep(Duration::from_millis(700));
        fill(&full, leave);
        let out = child.wait_with_output().unwrap();
        let (_, err) = text(&out);
        let listing: Vec<String> = std::fs::read_dir(&full)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        let partial = full.join("seed002-sine.rrd.partial");
        let kept = partial.exists().then(|| read(&partial));
        let _ = Command::new("umount").arg(&full).status();
        assert_eq!(out.status.code(), Some(3), "{mode}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{mode}: {err}");
        assert!(
            err.contains("seed002-sine.rrd.partial") && err.contains("No space left on device"),
            "{mode}: {err}"
        );
        assert_clean(&s, lpid);
        assert!(
            !listing.contains(&"seed002-sine.rrd".to_string()),
            "{mode}: {listing:?}"
        );
        match kept {
            Some(r) => {
                assert!(err.contains("was kept") && size == "3m", "{mode}: {err}");
                let r = r.expect("the kept partial recording is readable");
                assert!(
                    !r.complete && r.series.values().any(|s| !s.values.is_empty()),
                    "{mode}"
                );
            }
            None => assert!(
                err.contains("was removed") && size == "200k",
                "{mode}: {err}"
            ),
        }
    }
}
