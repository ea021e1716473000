//! The recording layout. Layout 2 stores a component's signals as the elements of
//! one entity's rows and reads back signal by signal, bit for bit (LZ4-compressed too); a layout-1 recording (a signal per
//! entity, no `layout` property) still reads; a layout this reader does not know is refused by
//! its number; a recording costs at most twice the bytes of the values it holds.

use std::collections::BTreeMap;
use std::path::PathBuf;

use recording::Integrity;
use recording::read::{Recording, Series, read, write as write_layout_1};
use recording::write::{LAYOUT, RrdSink, UncompressedFileSink};

/// A recording's layout for tests that do not look at it: no view.
fn empty_blueprint(_: &recording::write::Layout) -> rerun::blueprint::Blueprint {
    rerun::blueprint::Blueprint::new(rerun::blueprint::Vertical::new(Vec::<
        rerun::blueprint::ContainerLike,
    >::new()))
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("uio-layout-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// 30 signals of a closed loop's shape in five entities (a plant, two observers, a controller,
/// an input estimate one step late), `steps` rows of values no two alike.
fn write_layout_2(
    path: &std::path::Path,
    steps: u64,
    every: u64,
    compress: bool,
) -> (BTreeMap<String, Series>, usize) {
    let select = recording::write::Selection::new(every, &[])
        .unwrap()
        .compressed(compress);
    // The sink makes its file new (crate outputs): the previous case's file goes first.
    let _ = std::fs::remove_file(path);
    let mut sink =
        RrdSink::create(path, "layout", empty_blueprint, "name = \"layout\"", select).unwrap();
    let (now, late) = (sink.group("signals"), sink.group("what"));
    let mut paths: Vec<String> = (1..=3)
        .map(|i| format!("/plant/x/{i}"))
        .chain((1..=2).map(|j| format!("/plant/y/{j}")))
        .chain([
            "/disturbance/1".into(),
            "/input/1".into(),
            "/input/2".into(),
        ])
        .collect();
    for o in ["uio", "luenberger"] {
        paths.extend((1..=3).map(|i| format!("/observer/{o}/xhat/{i}")));
        paths.extend((1..=3).map(|i| format!("/observer/{o}/error/{i}")));
        paths.extend((1..=2).map(|j| format!("/observer/{o}/residual/{j}")));
        paths.push(format!("/observer/{o}/log10_max_abs_error"));
    }
    paths.extend(["/controller/u/1".to_string(), "/controller/u/2".to_string()]);
    let ids: Vec<_> = paths
        .iter()
        .map(|p| sink.series(now, p, p, [1, 2, 3], 1.0))
        .collect();
    let what = sink.series(late, "/observer/uio/what/1", "w estimate", [4, 5, 6], 2.0);
    let mut expected: BTreeMap<String, Series> = BTreeMap::new();
    for k in 0..steps {
        sink.row(now, k, k as f64 * 1e-3);
        for (j, (id, p)) in ids.iter().zip(&paths).enumerate() {
            let v = (k as f64 * 0.37 + j as f64).sin() * 10f64.powi(j as i32 % 7 - 3);
            sink.push(*id, v);
            if k % every == 0 {
                let s = expected.entry(p.clone()).or_default();
                s.steps.push(k as i64);
                s.values.push(v);
            }
        }
        if k > 0 {
            sink.row(late, k - 1, (k - 1) as f64 * 1e-3);
            let v = -(k as f64);
            sink.push(what, v);
            if (k - 1) % every == 0 {
                let s = expected.entry("/observer/uio/what/1".into()).or_default();
                s.steps.push(k as i64 - 1);
                s.values.push(v);
            }
        }
        sink.flush_full().unwrap();
    }
    let digests = sink.finish(steps).unwrap();
    assert_eq!(
        digests.len(),
        paths.len() + 2,
        "a digest per signal and the scenario's"
    );
    (expected, paths.len() + 1)
}

#[test]
fn layout_2_reads_back_signal_by_signal_bit_for_bit() {
    let dir = scratch("roundtrip");
    let path = dir.join("r.rrd");
    for (every, compress) in [(1, false), (7, false), (1, true)] {
        let (expected, signals) = write_layout_2(&path, 10_000, every, compress);
        let r = read(&path).unwrap();
        assert_eq!(r.integrity, Integrity::Verified);
        assert!(r.complete);
        assert_eq!(r.series.len(), signals);
        assert_eq!(r.series, expected, "every {every}, compressed {compress}");
        assert_eq!(r.names["/plant/x/2"], "/plant/x/2");
        assert_eq!(r.names["/observer/uio/what/1"], "w estimate");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_recording_costs_at_most_twice_its_values() {
    let dir = scratch("size");
    let path = dir.join("r.rrd");
    let steps = 50_000;
    let (_, signals) = write_layout_2(&path, steps, 1, false);
    let bytes = std::fs::metadata(&path).unwrap().len() as f64;
    let raw = (steps as usize * signals * 8) as f64;
    let _ = std::fs::remove_dir_all(&dir);
    // Layout 1 took ≈ 5.5 × (44 bytes for every 8-byte value).
    assert!(
        bytes <= 2.0 * raw,
        "{bytes} bytes for {raw} bytes of values: {:.2}×",
        bytes / raw
    );
}

#[test]
fn a_layout_1_recording_still_reads() {
    let dir = scratch("old");
    let path = dir.join("old.rrd");
    let mut old = Recording::default();
    for (i, p) in ["/plant/x/1", "/observer/uio/xhat/1", "/latency/step"]
        .iter()
        .enumerate()
    {
        old.series.insert(
            p.to_string(),
            Series {
                steps: (0..5000).collect(),
                values: (0..5000).map(|k| (k * (i + 1)) as f64 / 3.0).collect(),
            },
        );
    }
    write_layout_1(&path, &old).unwrap();
    let r = read(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(r.integrity, Integrity::Verified);
    assert_eq!(r.series, old.series);
}

#[test]
fn a_newer_layout_is_refused_by_its_number() {
    let dir = scratch("newer");
    let path = dir.join("newer.rrd");
    let stream = rerun::RecordingStreamBuilder::new("uio-observers")
        .buffered()
        .unwrap();
    stream.set_sink(Box::new(UncompressedFileSink::create(&path).unwrap()));
    stream
        .send_property(
            "layout",
            &rerun::TextDocument::new((LAYOUT + 1).to_string()),
        )
        .unwrap();
    stream.flush_blocking().unwrap();
    drop(stream);
    let e = read(&path).unwrap_err().to_string();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        e.contains(&format!(
            "recording layout {} is newer than this reader reads (1 to {LAYOUT})",
            LAYOUT + 1
        )),
        "{e}"
    );
    assert!(
        e.starts_with(&path.display().to_string()) && !e.contains('\n'),
        "{e}"
    );
}

#[test]
fn a_wide_entity_goes_in_smaller_batches_and_reads_back() {
    use recording::write::{FLUSH_STEPS, FLUSH_VALUES};
    let dir = scratch("wide");
    let path = dir.join("w.rrd");
    // 3000 signals a row: a batch holds FLUSH_VALUES / 3000 rows, so 2000 rows make several.
    let width = 3000;
    assert!(FLUSH_VALUES / width < FLUSH_STEPS);
    let mut sink = RrdSink::create(&path, "wide", empty_blueprint, "", Default::default()).unwrap();
    let g = sink.group("signals");
    let ids: Vec<_> = (1..=width)
        .map(|i| sink.series(g, &format!("/plant/x/{i}"), "x", [0, 0, 0], 1.0))
        .collect();
    for k in 0..2000u64 {
        sink.row(g, k, k as f64 * 0.01);
        for (i, id) in ids.iter().enumerate() {
            sink.push(*id, (k * 7919 + i as u64) as f64 / 3.0);
        }
        sink.flush_full().unwrap();
    }
    sink.finish(2000).unwrap();
    let r = read(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(r.integrity, Integrity::Verified);
    assert_eq!(r.series.len(), width);
    for (i, id) in [1usize, 1500, 3000].iter().enumerate() {
        let s = &r.series[&format!("/plant/x/{id}")];
        assert_eq!(s.steps, (0..2000).collect::<Vec<i64>>(), "{i}");
        assert!(
            s.values
                .iter()
                .enumerate()
                .all(|(k, &v)| v == (k as u64 * 7919 + *id as u64 - 1) as f64 / 3.0)
        );
    }
}
