//! A sweep's realisations that fail are counted as failed (not in the statistics) and
//! make the sweep fail; an interrupted sweep writes the statistics of what it finished, marked
//! partial.

use std::process::Stdio;
use std::time::{Duration, Instant};

use tests::*;

fn sweep_json(s: &Scratch, name: &str) -> serde_json::Value {
    let p = s.join("out").join(format!("{name}.sweep.json"));
    serde_json::from_str(
        &std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())),
    )
    .unwrap()
}

/// seed002-sine in open loop, 2 s, with an observer `bad` that breaks the protocol as told.
fn with_bad_observer(s: &Scratch, fault: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let text = text
        .split("\n[controller]")
        .next()
        .unwrap()
        .replace("duration = 20.0", "duration = 2.0");
    let text = format!(
        "{text}\n[[observer]]\nname = \"bad\"\nkind = \"process\"\ncommand = [\"faulty_observer\"]\nparams = {{ fault = \"{fault}\" }}\n"
    );
    let p = s.join("bad.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// Every realisation's component fails (exits, hangs): each is counted as failed with its
/// reason, none is in the statistics, the summary is written, and the sweep exits 3.
#[test]
fn failed_realisations_are_counted_and_fail_the_sweep() {
    for (fault, runs, why) in [
        ("exit", 2, "exited with status 7"),
        ("hang", 1, "published no sample for step 100"),
    ] {
        let s = Scratch::new(&format!("sweep-{fault}"));
        let path = with_bad_observer(&s, fault);
        let child = launcher(&s)
            .arg("sweep")
            .arg(&path)
            .args(["--mode", "processes", "--runs", &runs.to_string(), "--out"])
            .arg(s.join("out"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let pid = child.id();
        let o = child.wait_with_output().unwrap();
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(3), "{fault}: {err}");
        assert!(
            err.contains(&format!("{runs} of {runs} realisations failed")) && err.contains(why),
            "{fault}: {err}"
        );
        let sw = sweep_json(&s, "seed002-sine");
        assert_eq!(
            (
                sw["runs"].as_u64(),
                sw["requested"].as_u64(),
                sw["finished"].as_u64()
            ),
            (Some(0), Some(runs), Some(runs)),
            "{fault}: {sw}"
        );
        let failed = sw["failed"].as_array().unwrap();
        assert_eq!(failed.len() as u64, runs, "{fault}: {sw}");
        assert!(
            failed.iter().all(|f| f["kind"] == "failed"
                && f["reason"].as_str().unwrap().contains("observer 'bad'")),
            "{fault}: {sw}"
        );
        assert_eq!(sw["partial"], false);
        assert_clean(&s, pid);
    }
}

/// SIGINT during a long sweep: the realisations finished so far are written, marked partial,
/// and the sweep exits 130.
#[test]
fn an_interrupted_sweep_writes_what_it_finished() {
    let name = "seed002-fault-free";
    let s = Scratch::new("sweep-interrupted");
    let child = launcher(&s)
        .arg("sweep")
        .arg(scenario(name))
        .args(["--runs", "100000", "--jobs", "1", "--out"])
        .arg(s.join("out"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    // Until its first realisations are done (a realisation takes well under a second).
    std::thread::sleep(Duration::from_secs(4));
    signal(pid as i32, libc::SIGINT);
    let started = Instant::now();
    let o = child.wait_with_output().unwrap();
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(130), "{out}\n{err}");
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "took {:?} to stop",
        started.elapsed()
    );
    assert!(
        err.contains("sweep interrupted by SIGINT after") && err.contains("marked partial"),
        "{err}"
    );
    let sw = sweep_json(&s, name);
    assert_eq!(sw["partial"], true, "{sw}");
    assert_eq!(sw["interrupted_by"], "SIGINT", "{sw}");
    let finished = sw["finished"].as_u64().unwrap();
    assert!((1..100_000).contains(&finished), "{sw}");
    assert_eq!(
        sw["runs"].as_u64().unwrap() + sw["failed"].as_array().unwrap().len() as u64,
        finished,
        "{sw}"
    );
    // The statistics are of those realisations: their fault-free samples were counted.
    assert!(
        sw["residuals"]
            .as_array()
            .unwrap()
            .iter()
            .all(|r| r["fault_free_steps"].as_u64().unwrap() > 0),
        "{sw}"
    );
    assert!(out.contains("PARTIAL: interrupted after"), "{out}");
}
