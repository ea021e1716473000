//! What a recording opens with in the Rerun viewer: its blueprint puts the time panel on the
//! `sim_time` timeline, paused, and each series carries the palette's colour, so the viewer
//! and the PNG plots agree.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use re_log_encoding::DecoderApp;
use recording::palette;
use recording::signals;
use recording::write::{RrdSink, blueprint};
use rerun::external::re_log_types::LogMsg;
use rerun::log::Chunk;
use scenario::Scenario;

/// Every static chunk of `path` by (store is blueprint, entity path).
fn chunks(path: &Path) -> BTreeMap<(bool, String), Vec<Chunk>> {
    let mut out: BTreeMap<(bool, String), Vec<Chunk>> = BTreeMap::new();
    for msg in DecoderApp::decode_lazy(BufReader::new(File::open(path).unwrap())) {
        let LogMsg::ArrowMsg(store, arrow) = msg.unwrap() else {
            continue;
        };
        let chunk = Chunk::from_arrow_msg(&arrow).unwrap();
        out.entry((!store.is_recording(), chunk.entity_path().to_string()))
            .or_default()
            .push(chunk);
    }
    out
}

#[test]
fn the_viewer_opens_on_sim_time_paused_with_the_palettes_colours() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/seed002-sine.toml"),
    )
    .unwrap();
    let s = Scenario::parse(Path::new("seed002-sine.toml"), &text).unwrap();
    let dir = std::env::temp_dir().join(format!("uio-blueprint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bp.rrd");
    let scenario = s.clone();
    let mut sink = RrdSink::create(
        &path,
        &s.name,
        move |layout| blueprint(&scenario, layout),
        &s.source,
        Default::default(),
    )
    .unwrap();
    let g = sink.group("signals");
    let observers: Vec<String> = s.observers.iter().map(|o| o.name.clone()).collect();
    let mut ids = Vec::new();
    for p in [signals::state(0), signals::estimate("luenberger", 0)] {
        let line = palette::line(&p, &observers);
        let id = sink.series(
            g,
            &p,
            "legend",
            line.color,
            palette::viewer_width(&p, &observers),
        );
        ids.push(id);
    }
    sink.row(g, 0, 0.0);
    for id in &ids {
        sink.push(*id, 1.0);
    }
    sink.finish(1).unwrap();
    let all = chunks(&path);
    let _ = std::fs::remove_dir_all(&dir);
    let panel = &all[&(true, "/time_panel".to_string())];
    let timeline: Vec<String> = panel
        .iter()
        .flat_map(|c| {
            c.iter_slices::<String>("TimePanelBlueprint:timeline".into())
                .flatten()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(timeline, ["sim_time"]);
    let play: Vec<u8> = panel
        .iter()
        .flat_map(|c| {
            c.iter_slices::<u8>("TimePanelBlueprint:play_state".into())
                .flat_map(|s| s.to_vec())
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(
        play,
        [rerun::blueprint::components::PlayState::Paused as u8]
    );
    // Colours as 0xRRGGBBAA.
    let colour = |entity: &str| -> Vec<u32> {
        all[&(false, entity.to_string())]
            .iter()
            .flat_map(|c| {
                c.iter_slices::<u32>("SeriesLines:colors".into())
                    .flat_map(|s| s.to_vec())
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let rgba = |c: palette::Rgb| u32::from_be_bytes([c[0], c[1], c[2], 255]);
    // Layout 2: each signal is an instance of its component's entity, colour for colour.
    assert_eq!(colour("/plant"), [rgba(palette::TRUE_STATE)]);
    assert_eq!(colour("/observer/luenberger"), [rgba(palette::color(1))]);
}
