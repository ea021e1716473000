//! A recording damaged after it was written is reported as damaged (exit
//! code 6) by inspect, compare, export and plot, which then write nothing; a clean one passes.

use std::path::{Path, PathBuf};

use tests::*;

/// Runs every tool on `rrd`; returns (command, exit code, stderr) of each.
fn tools(s: &Scratch, rrd: &Path, clean: &Path, tag: &str) -> Vec<(String, Option<i32>, String)> {
    let (csv, png) = (s.join(&format!("csv-{tag}")), s.join(&format!("png-{tag}")));
    let runs: [(&str, Vec<&std::ffi::OsStr>); 4] = [
        ("inspect", vec![rrd.as_os_str()]),
        ("compare", vec![clean.as_os_str(), rrd.as_os_str()]),
        (
            "export",
            vec![rrd.as_os_str(), "--csv".as_ref(), csv.as_os_str()],
        ),
        (
            "plot",
            vec![rrd.as_os_str(), "--out".as_ref(), png.as_os_str()],
        ),
    ];
    runs.into_iter()
        .map(|(cmd, args)| {
            let out = launcher(s).arg(cmd).args(args).output().unwrap();
            (
                cmd.to_string(),
                out.status.code(),
                String::from_utf8_lossy(&out.stderr).into_owned(),
            )
        })
        .collect()
}

/// A copy of `rrd` with one bit flipped in the first occurrence of `pattern`.
fn flipped(rrd: &Path, pattern: &[u8], to: PathBuf) -> PathBuf {
    let mut bytes = std::fs::read(rrd).unwrap();
    let at = bytes
        .windows(pattern.len())
        .position(|w| w == pattern)
        .expect("pattern in the file");
    bytes[at + 3] ^= 0x04;
    std::fs::write(&to, bytes).unwrap();
    to
}

#[test]
fn damaged_recordings_are_reported_by_every_tool() {
    let s = Scratch::new("damaged");
    let name = "seed002-sine";
    assert!(
        run(&s, &scenario(name), &["--mode", "in-process"])
            .status
            .success()
    );
    let clean = s.join(&format!("out/{name}.rrd"));
    let r = read(&clean).unwrap();
    assert_eq!(r.integrity, recording::Integrity::Verified);
    // summary.json holds the same digest as the recording: one per signal and the scenario.
    let sum = summary(&s, name);
    let digest = sum["recording_digest"]
        .as_object()
        .expect("recording_digest in summary.json");
    assert_eq!(digest.len(), r.series.len() + 1, "{digest:?}");
    assert!(r.series.keys().all(|k| digest.contains_key(k)) && digest.contains_key("scenario"));

    // A clean recording passes every tool.
    for (cmd, code, err) in tools(&s, &clean, &clean, "clean") {
        assert_eq!(code, Some(0), "{cmd}: {err}");
        assert!(!err.contains("damaged"), "{cmd}: {err}");
    }

    // One bit of a value of the true state, and one of a sim_time stamp.
    let x = r
        .series
        .keys()
        .find(|k| k.starts_with("/plant/x/"))
        .unwrap()
        .clone();
    let value = r.series[&x].values[10_000].to_bits().to_le_bytes();
    let time = 12_345_000_000i64.to_le_bytes();
    for (what, pattern, entity) in [
        ("value", &value, Some("/plant/")),
        ("sim_time", &time, None),
    ] {
        let bad = flipped(&clean, pattern, s.join(&format!("bad-{what}.rrd")));
        let r = read(&bad).unwrap();
        assert!(
            matches!(r.integrity, recording::Integrity::Damaged(_)),
            "{what}: {:?}",
            r.integrity
        );
        for (cmd, code, err) in tools(&s, &bad, &clean, what) {
            assert_eq!(code, Some(6), "{what} {cmd}: {err}");
            assert!(
                err.contains("damaged") && err.contains(&format!("bad-{what}.rrd")),
                "{what} {cmd}: {err}"
            );
            if let Some(e) = entity {
                assert!(err.contains(e), "{what} {cmd}: {err}");
            }
            assert_eq!(err.trim_end().lines().count(), 1, "{what} {cmd}: {err}");
        }
        for dir in ["csv", "png"] {
            assert!(
                !s.join(&format!("{dir}-{what}")).exists(),
                "{what}: {dir} written from a damaged recording"
            );
        }
    }
}

#[test]
fn a_truncated_recording_is_incomplete_not_damaged() {
    let s = Scratch::new("truncated");
    let name = "seed003-charlie-open-loop";
    assert!(
        run(&s, &scenario(name), &["--mode", "in-process"])
            .status
            .success()
    );
    let clean = s.join(&format!("out/{name}.rrd"));
    let bytes = std::fs::read(&clean).unwrap();
    // Cut like a killed writer: no footer, the last message half written.
    let cut = s.join("cut.rrd.partial");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let r = read(&cut).unwrap();
    assert_eq!(r.integrity, recording::Integrity::Absent);
    assert!(!r.complete);
    let out = launcher(&s).arg("inspect").arg(&cut).output().unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("incomplete") && !err.contains("damaged"),
        "{err}"
    );
}
