//! No damage to a recording crashes a reader. Every byte of the first and the
//! last 8 KiB of a finished recording (and every 37th in between) is flipped in turn and the
//! file read in process: it must be reported damaged, or read to exactly the clean file's data
//! (damage outside what the digest covers: row ids, legends, the blueprint) — never read as
//! incomplete, never a panic, never an abort (which would end this test process). Cuts, a
//! killed writer's shape, must read as incomplete prefixes of the clean data. A few flips go through the real
//! inspect, compare, export and plot, which must exit 6 naming the file.

use std::path::Path;
use std::time::Instant;

use recording::Integrity;
use tests::*;

/// What a read of a damaged copy gave, when it is not acceptable.
fn unacceptable(clean: &Recording, path: &Path) -> Option<String> {
    let outcome = std::panic::catch_unwind(|| read(path));
    match outcome {
        Err(_) => Some("the reader panicked".into()),
        Ok(Err(e)) => Some(format!("refused as unreadable ({e}), not damaged")),
        Ok(Ok(r)) => match &r.integrity {
            Integrity::Damaged(_) => None,
            Integrity::Verified
                if r.complete && r.series == clean.series && r.scenario == clean.scenario =>
            {
                None
            }
            other => Some(format!(
                "read as {other:?}, complete {}, {} series",
                r.complete,
                r.series.len()
            )),
        },
    }
}

/// Whether `r`, read from a cut copy, is incomplete and holds a prefix of the clean data (its
/// digest verified when the cut left it and all the data).
fn a_clean_prefix(clean: &Recording, r: &Recording) -> bool {
    !r.complete
        && matches!(r.integrity, Integrity::Absent | Integrity::Verified)
        && r.series.iter().all(|(k, s)| {
            clean
                .series
                .get(k)
                .is_some_and(|c| c.steps.starts_with(&s.steps) && c.values.starts_with(&s.values))
        })
}

#[test]
fn no_flipped_byte_crashes_the_reader() {
    let s = Scratch::new("fuzz");
    let scenario = variant(&s, "seed002-sine", 0.05, false);
    let out = run(&s, &scenario, &["--mode", "in-process"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let clean_path = s.join("out/seed002-sine.rrd");
    let bytes = std::fs::read(&clean_path).unwrap();
    let clean = read(&clean_path).unwrap();
    assert_eq!(clean.integrity, Integrity::Verified);
    let n = bytes.len();
    assert!(
        n > 3 * 8192,
        "a recording of {n} bytes is too small for the test"
    );
    let mut positions: Vec<usize> = (0..8192)
        .chain((8192..n - 8192).step_by(37))
        .chain(n - 8192..n)
        .collect();
    positions.dedup();

    let started = Instant::now();
    let threads = std::thread::available_parallelism()
        .map_or(2, |p| p.get())
        .min(4);
    let failures: Vec<String> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|t| {
                let (bytes, clean, positions, s) = (&bytes, &clean, &positions, &s);
                scope.spawn(move || {
                    let path = s.join(&format!("flip-{t}.rrd"));
                    let mut copy = bytes.clone();
                    let mut failures = Vec::new();
                    for &i in positions.iter().skip(t).step_by(threads) {
                        copy[i] ^= 0xff;
                        std::fs::write(&path, &copy).unwrap();
                        copy[i] ^= 0xff;
                        if let Some(why) = unacceptable(clean, &path) {
                            failures
                                .push(format!("byte {i} (of {n}, {} from the end): {why}", n - i));
                        }
                    }
                    // Every single-bit flip of the stream footer and the RRD footer's last bytes.
                    for i in (n - 64..n).skip(t).step_by(threads) {
                        for bit in 0..8 {
                            copy[i] ^= 1 << bit;
                            std::fs::write(&path, &copy).unwrap();
                            copy[i] ^= 1 << bit;
                            if let Some(why) = unacceptable(clean, &path) {
                                failures.push(format!(
                                    "bit {bit} of byte {i} ({} from the end): {why}",
                                    n - i
                                ));
                            }
                        }
                    }
                    failures
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    let flips = positions.len() + 64 * 8;
    eprintln!(
        "{flips} flipped copies of a {n}-byte recording read in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    assert!(
        failures.is_empty(),
        "{} of {flips} flips:\n{}",
        failures.len(),
        failures
            .iter()
            .take(40)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );

    // Cut like a killed writer, anywhere in the stream footer and the last bytes of the RRD
    // footer, and at a sample before: incomplete.
    let cut = s.join("cut.rrd.partial");
    for at in (12..n - 512).step_by(251).chain(n - 512..n) {
        std::fs::write(&cut, &bytes[..at]).unwrap();
        let r = read(&cut).unwrap_or_else(|e| panic!("cut at {at}: {e}"));
        assert!(
            a_clean_prefix(&clean, &r),
            "cut at {at} of {n}: {:?}, complete {}",
            r.integrity,
            r.complete
        );
    }
}

#[test]
fn the_tools_report_flipped_bytes_as_damage() {
    let s = Scratch::new("fuzz-cli");
    let scenario = variant(&s, "seed002-sine", 0.05, false);
    assert!(
        run(&s, &scenario, &["--mode", "in-process"])
            .status
            .success()
    );
    let clean = s.join("out/seed002-sine.rrd");
    let bytes = std::fs::read(&clean).unwrap();
    let n = bytes.len();
    for from_end in [1, 2, 4, 200, 5000, n] {
        let i = n - from_end;
        let mut copy = bytes.clone();
        copy[i] ^= 0xff;
        let bad = s.join(&format!("flip-{from_end}.rrd"));
        std::fs::write(&bad, &copy).unwrap();
        let (csv, png) = (
            s.join(&format!("csv-{from_end}")),
            s.join(&format!("png-{from_end}")),
        );
        let runs: [(&str, Vec<&std::ffi::OsStr>); 4] = [
            ("inspect", vec![bad.as_os_str()]),
            ("compare", vec![clean.as_os_str(), bad.as_os_str()]),
            (
                "export",
                vec![bad.as_os_str(), "--csv".as_ref(), csv.as_os_str()],
            ),
            (
                "plot",
                vec![bad.as_os_str(), "--out".as_ref(), png.as_os_str()],
            ),
        ];
        for (cmd, args) in runs {
            let out = launcher(&s).arg(cmd).args(args).output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(
                out.status.code(),
                Some(6),
                "byte {i} ({from_end} from the end), {cmd}: {err}"
            );
            assert!(
                err.contains("damaged") && err.contains(&format!("flip-{from_end}.rrd")),
                "{cmd}: {err}"
            );
            assert_eq!(err.trim_end().lines().count(), 1, "{cmd}: {err}");
        }
        assert!(
            !csv.exists() && !png.exists(),
            "output written from a damaged recording"
        );
    }
}
