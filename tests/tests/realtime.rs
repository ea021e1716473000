//! `--realtime [--speed X]` paces a run — step k starts at k·dt/X of wall
//! time — with waits that sleep, and counts and records the steps that end late.

use std::time::{Duration, Instant};

use tests::*;

/// utime + stime of a process, in clock ticks (/proc/<pid>/stat fields 14 and 15).
/// (user, system) CPU ticks of `pid`.
fn cpu_ticks(pid: i32) -> Option<(u64, u64)> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    Some((
        f.get(11)?.parse::<u64>().ok()?,
        f.get(12)?.parse::<u64>().ok()?,
    ))
}

/// How long `n` sleeps of `period` take here, now: the machine's own floor for a paced step
/// (a sleep's wake-up latency is the host's: 0.1–0.2 ms on a quiet day, 0.5 ms on 2026-11-28
/// afternoon, when 1 000 sleeps of 0.5 ms took 1.02 s).
fn sleep_floor(n: u32, period: Duration) -> f64 {
    let t = Instant::now();
    for _ in 0..n {
        std::thread::sleep(period);
    }
    t.elapsed().as_secs_f64()
}

#[test]
fn a_paced_run_keeps_wall_time_and_its_processes_idle() {
    let s = Scratch::new("realtime");
    // Long enough that the recording has grown (its first batch is 4 096 steps, 4.1 s paced)
    // with seconds to spare.
    let seconds = 8.0;
    let path = variant(&s, "seed002-sine", seconds, false);
    let child = launcher(&s)
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(s.join("out"))
        .arg("--realtime")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let names = ["plant", "uio", "luenberger", "controller"];
    wait_running(pid, &names);
    // Only once the run is stepping: start-up (joining the ports, the handshake) is not the
    // paced waiting this measures, and on a loaded machine it ran into the window (CI saw the
    // uio at 18 % of a core where its steady state is 5–6 % here).
    wait_stepping(&s.join("out").join("seed002-sine.rrd.partial"));
    // CPU use of every component over one second in the middle of the run.
    let pids: Vec<i32> = names
        .iter()
        .map(|n| component_pid(pid, n).unwrap())
        .collect();
    let before: Vec<(u64, u64)> = pids.iter().map(|&p| cpu_ticks(p).unwrap()).collect();
    let t = Instant::now();
    std::thread::sleep(Duration::from_secs(1));
    let after: Vec<Option<(u64, u64)>> = pids.iter().map(|&p| cpu_ticks(p)).collect();
    let secs = t.elapsed().as_secs_f64();
    // SAFETY: sysconf has no preconditions.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64;
    // Idle means waiting in the kernel, not spinning: a spinning wait takes a whole core. The
    // user share is the component's own work (5–6 % for the uio); the system share is the
    // blocking socket calls of iceoryx2's event waits, whose cost is the host's (13–29 % of a
    // core for the plant on 2026-11-28, all of it in recvfrom/sendto, user time ~0).
    for ((name, b), a) in names.iter().zip(&before).zip(&after) {
        let a = a.expect("still running");
        let (user, total) = (
            (a.0 - b.0) as f64 / hz / secs,
            ((a.0 + a.1) - (b.0 + b.1)) as f64 / hz / secs,
        );
        assert!(
            user < 0.10 && total < 0.5,
            "{name} used {:.0} % of a core ({:.0} % in user space) in a paced run",
            100.0 * total,
            100.0 * user
        );
    }
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    assert_clean(&s, pid);
    let sum = summary(&s, "seed002-sine");
    let rt = &sum["realtime"];
    let (paced, scheduled) = (
        rt["paced_wall_s"].as_f64().unwrap(),
        rt["scheduled_s"].as_f64().unwrap(),
    );
    assert!((scheduled - seconds).abs() < 1e-9, "{rt}");
    assert!(
        (paced / scheduled - 1.0).abs() < 0.01,
        "paced {paced} s for {scheduled} s"
    );
    assert_eq!(rt["steps"], 8000);
    let rec = read(&s.join("out").join("seed002-sine.rrd")).unwrap();
    let overrun = &rec.series["/latency/overrun"];
    assert_eq!(overrun.values.len(), 8000);
    let late = overrun.values.iter().filter(|&&v| v > 0.0).count() as u64;
    assert_eq!(
        rt["overruns"], late,
        "the summary counts what the recording shows"
    );
}

#[test]
fn speed_scales_the_pace_and_an_impossible_pace_is_reported() {
    // Four times real time, in-process: 2 s of simulated time in 0.5 s.
    let s = Scratch::new("realtime-speed");
    let path = variant(&s, "seed002-sine", 2.0, false);
    let out = run(
        &s,
        &path,
        &["--mode", "in-process", "--realtime", "--speed", "4"],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    let rt = &summary(&s, "seed002-sine")["realtime"];
    let paced = rt["paced_wall_s"].as_f64().unwrap();
    assert!((paced / 0.5 - 1.0).abs() < 0.01, "{rt}");
    // A million times real time at dt = 1 ms is a step per ns: no step can keep up, and the
    // summary says so.
    let t = Scratch::new("realtime-too-fast");
    let out = run(
        &t,
        &path,
        &[
            "--mode",
            "in-process",
            "--realtime",
            "--speed",
            "1e6",
            "--force",
        ],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    let (stdout, _) = text(&out);
    assert!(stdout.contains("cannot keep up"), "{stdout}");
    let rt = &summary(&t, "seed002-sine")["realtime"];
    assert!(rt["overruns"].as_u64().unwrap() > 1000, "{rt}");
    for bad in ["0", "-1", "nan", "inf"] {
        let out = run(
            &t,
            &path,
            &[
                "--mode",
                "in-process",
                "--realtime",
                "--speed",
                bad,
                "--force",
            ],
        );
        assert_eq!(
            out.status.code(),
            Some(2),
            "--speed {bad}: {:?}",
            text(&out)
        );
    }
}

/// A Python plant (the Python kit) paces itself from the same `pace_s` as the Rust kit.
#[test]
fn a_python_plant_is_paced_too() {
    let s = Scratch::new("realtime-python");
    // The same run unpaced first: how long this machine, now, takes for it (~1.3 s usually;
    // 2.6 s seen in a slow phase of the machine).
    let out = run(&s, &scenario("cartpole-python-plant"), &[]);
    assert!(out.status.success(), "{:?}", text(&out));
    let unpaced = summary(&s, "cartpole-python-plant")["wall_s"]
        .as_f64()
        .unwrap();
    // 10 s of simulated time in real time: a 1 ms period. At five times (0.2 ms) the
    // Python plant's step (~0.12 ms) and its sleep's wake-up latency (~0.1–0.2 ms here) no longer
    // fit in a period: on 2026-11-28 every one of 10 000 steps overran and the paced run took
    // 2.8–4.2 s for the 2 s scheduled, with this change and without it (the same binaries of the
    // commit before, rebuilt and run); at twice (0.5 ms) 70 % of the steps still overran once.
    let out = run(
        &s,
        &scenario("cartpole-python-plant"),
        &["--realtime", "--speed", "1", "--force"],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    let rt = &summary(&s, "cartpole-python-plant")["realtime"];
    let (paced, scheduled) = (
        rt["paced_wall_s"].as_f64().unwrap(),
        rt["scheduled_s"].as_f64().unwrap(),
    );
    // Paced means never ahead of the schedule; a late finish is the machine's, not the
    // pacing's: at 0.2 ms a step the Python plant needs long to catch up after one stall (the
    // page cache's writeback stalled it 50–120 ms in CI after the tests before it wrote their
    // recordings), so the upper bound is loose, and relative to the unpaced run where the
    // machine is slower than the schedule.
    // And where a sleep's wake-up latency no longer fits in the period, the machine's own
    // floor: a sleep of one period per step (1 000 of them measured here, now, scaled to the
    // 10 000 steps) plus the unpaced run's work.
    let floor = sleep_floor(1000, Duration::from_millis(1)) * 10.0 + unpaced;
    assert!(
        (scheduled - 10.0).abs() < 1e-9
            && paced >= scheduled * 0.999
            && paced <= scheduled.max(unpaced).max(floor) * 1.25,
        "{rt}, unpaced {unpaced} s, sleep floor {floor} s"
    );
}
