//! `uio-launcher plot` stays inside its axes, draws one colour per observer,
//! an |e| view on a log axis, and what `--signals`, `--from` and `--to` select; every signal is
//! numbered from 1 and named with its unit in plots and CSV headers.

use std::path::Path;

use recording::plot::{Figure, PlotSelection, Scale, figures};
use tests::*;

/// The plot rectangle of a PNG (left, top, right, bottom): the y axis is the longest vertical
/// run of dark pixels, the x axis the longest horizontal one.
fn plot_rect(img: &image::RgbImage) -> (u32, u32, u32, u32) {
    let dark = |x: u32, y: u32| {
        let p = img.get_pixel(x, y).0;
        p.iter().all(|&c| c < 80) && p.iter().max().unwrap() - p.iter().min().unwrap() < 20
    };
    let (w, h) = img.dimensions();
    let longest = |n: u32, at: &dyn Fn(u32) -> bool| {
        let (mut best, mut run, mut end) = (0, 0, 0);
        for i in 0..n {
            run = if at(i) { run + 1 } else { 0 };
            if run > best {
                (best, end) = (run, i);
            }
        }
        (best, end + 1 - best, end)
    };
    let (mut v, mut left) = ((0, 0, 0), 0);
    for x in 0..w {
        let r = longest(h, &|y| dark(x, y));
        if r.0 > v.0 {
            (v, left) = (r, x);
        }
    }
    let (mut hz, mut bottom) = ((0, 0, 0), 0);
    for y in 0..h {
        let r = longest(w, &|x| dark(x, y));
        // The lowest of equally long lines: a frame's top edge is as long as its bottom.
        if r.0 >= hz.0 {
            (hz, bottom) = (r, y);
        }
    }
    (left, v.1, hz.2, bottom)
}

/// Pixels of a series colour (saturated, unlike text, grid and frame) left of, above or below
/// the plot rectangle. (Right of it is the legend column, whose samples carry the colours.)
fn coloured_outside(png: &Path) -> Vec<(u32, u32)> {
    let img = image::open(png).unwrap().to_rgb8();
    let (left, top, _, bottom) = plot_rect(&img);
    let mut out = Vec::new();
    for (x, y, p) in img.enumerate_pixels() {
        let p = p.0;
        let saturated = p.iter().max().unwrap() - p.iter().min().unwrap() > 60;
        if saturated && (x < left || y < top || y > bottom) {
            out.push((x, y));
        }
    }
    out
}

/// A 300 s run at 1 ms with a long quiet stretch, noise, and one spike a million times larger.
fn spiky_recording(path: &Path) {
    let n = 300_000;
    let steps: Vec<i64> = (0..n).collect();
    let noise = |k: i64| ((k * 7919) % 101) as f64 / 101.0;
    let latency: Vec<f64> = steps
        .iter()
        .map(|&k| {
            if k == 150_000 {
                4e9
            } else {
                15_000.0 + 20_000.0 * noise(k)
            }
        })
        .collect();
    let estimate: Vec<f64> = steps
        .iter()
        .map(|&k| {
            if k == 200_000 {
                1e6
            } else {
                (k as f64 * 1e-3).sin() + 0.01 * noise(k)
            }
        })
        .collect();
    let mut r = Recording::default();
    r.series.insert(
        "/latency/step".into(),
        Series {
            steps: steps.clone(),
            values: latency,
        },
    );
    r.series.insert(
        "/observer/a/xhat/1".into(),
        Series {
            steps: steps.clone(),
            values: estimate.clone(),
        },
    );
    r.series.insert(
        "/plant/x/1".into(),
        Series {
            steps,
            values: estimate,
        },
    );
    recording::read::write(path, &r).unwrap();
}

#[test]
fn plots_stay_inside_their_axes() {
    let s = Scratch::new("plot-spike");
    let rrd = s.join("spike.rrd");
    spiky_recording(&rrd);
    let out = launcher(&s)
        .arg("plot")
        .arg(&rrd)
        .arg("--out")
        .arg(s.join("png"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let mut checked = 0;
    for f in std::fs::read_dir(s.join("png")).unwrap().flatten() {
        let outside = coloured_outside(&f.path());
        assert!(
            outside.is_empty(),
            "{}: {} pixels of a series colour outside the axes, e.g. {:?}",
            f.path().display(),
            outside.len(),
            &outside[..outside.len().min(5)]
        );
        checked += 1;
    }
    assert!(checked >= 2, "{checked} files");
}

#[test]
fn one_colour_per_observer_a_log_error_view_and_one_based_names() {
    let s = Scratch::new("plot-views");
    assert!(
        run(&s, &scenario("seed002-sine"), &["--mode", "in-process"])
            .status
            .success()
    );
    let r = read(&s.join("out/seed002-sine.rrd")).unwrap();
    assert!(
        r.series.contains_key("/plant/x/1")
            && r.series.contains_key("/plant/x/3")
            && !r.series.contains_key("/plant/x/0")
    );
    assert!(
        r.series.contains_key("/observer/uio/error/3")
            && r.series.contains_key("/input/2")
            && r.series.contains_key("/disturbance/1")
    );
    let figs = figures(&r, &PlotSelection::default()).unwrap();
    let fig = |file: &str| {
        &figs
            .iter()
            .find(|(f, _)| f == file)
            .unwrap_or_else(|| panic!("no {file}"))
            .1
    };
    let colour_of = |file: &str, label_part: &str| {
        fig(file)
            .curves
            .iter()
            .find(|c| c.label.contains(label_part))
            .unwrap_or_else(|| panic!("{file}: {label_part}"))
            .line
            .color
    };
    // The same colour for an observer in every view; the true state apart and wider.
    let uio = colour_of("state_1_x1.png", "(uio)");
    let luenberger = colour_of("state_1_x1.png", "(luenberger)");
    assert_ne!(uio, luenberger);
    assert_eq!(colour_of("state_3_x3.png", "(uio)"), uio);
    assert_eq!(colour_of("errors_log.png", "uio"), uio);
    assert_eq!(colour_of("error_uio.png", "e1"), uio);
    let truth = &fig("state_2_x2.png").curves[0];
    assert!(
        truth.label.contains("true")
            && truth.line.width > fig("state_2_x2.png").curves[1].line.width
    );
    assert!(![uio, luenberger].contains(&truth.line.color));
    // The log view separates the UIO (converging like e^{−t}) from the Luenberger observer
    // (driven by the disturbance) by orders of magnitude at the end of the run.
    let log = fig("errors_log.png");
    assert_eq!(log.scale, Scale::Log);
    let last = |part: &str| {
        log.curves
            .iter()
            .find(|c| c.label.contains(part))
            .unwrap()
            .points
            .iter()
            .filter(|p| p.0 > 15.0)
            .map(|p| p.1)
            .fold(f64::MIN, f64::max)
    };
    assert!(
        last("luenberger") - last("uio") > 4.0,
        "log10 gap {}",
        last("luenberger") - last("uio")
    );
}

#[test]
fn signals_and_a_time_window_choose_what_is_drawn() {
    let s = Scratch::new("plot-select");
    assert!(
        run(&s, &scenario("seed002-sine"), &["--mode", "in-process"])
            .status
            .success()
    );
    let rrd = s.join("out/seed002-sine.rrd");
    let out = launcher(&s)
        .arg("plot")
        .arg(&rrd)
        .args([
            "--out",
            "png",
            "--signals",
            "/observer/uio/**",
            "--from",
            "5",
            "--to",
            "7.5",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let mut files: Vec<String> = std::fs::read_dir(s.join("png"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert_eq!(
        files,
        [
            "error_uio.png",
            "errors_log.png",
            "input_estimate_uio.png",
            "residual_uio.png",
            "state_1_x1.png",
            "state_2_x2.png",
            "state_3_x3.png"
        ]
    );
    let r = read(&rrd).unwrap();
    let sel = PlotSelection {
        signals: vec!["/observer/uio/**".into()],
        from: Some(5.0),
        to: Some(7.5),
    };
    for (file, fig) in figures(&r, &sel).unwrap() {
        for c in &fig.curves {
            assert!(
                c.label.contains("uio") || file.contains("uio"),
                "{file}: {}",
                c.label
            );
            let (lo, hi) = c
                .points
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
            assert!(
                lo >= 5.0 && hi <= 7.5 && hi - lo > 2.4,
                "{file}: {lo}..{hi}"
            );
        }
    }
    // A bad window or glob: exit 2, one line naming the option, nothing drawn.
    for (args, what) in [
        (vec!["--from", "3", "--to", "1"], "--from"),
        (vec!["--to", "nan"], "--to"),
        (vec!["--signals", "/plant/[x"], "--signals"),
    ] {
        let out = launcher(&s)
            .arg("plot")
            .arg(&rrd)
            .args(["--out", "bad"])
            .args(&args)
            .output()
            .unwrap();
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(what), "{err}");
        assert!(!s.join("bad").exists());
    }
    // A window with no data.
    let out = launcher(&s)
        .arg("plot")
        .arg(&rrd)
        .args(["--out", "late", "--from", "100", "--to", "200"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{:?}", text(&out));
}

#[test]
fn names_and_units_label_plots_and_csv_headers() {
    let s = Scratch::new("plot-names");
    let text_ = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let named = text_.replacen(
        "[plant]",
        "[plant]\nstate_names = [\"pos\", \"vel\", \"volt\"]\nstate_units = [\"m\", \"m/s\", \"V\"]\noutput_names = [\"pos_meas\", \"volt_meas\"]\noutput_units = [\"m\", \"V\"]\ninput_names = [\"force\", \"supply\"]\ninput_units = [\"N\", \"V\"]\ndisturbance_names = [\"gust\"]\ndisturbance_units = [\"N\"]",
        1,
    );
    let path = s.join("named.toml");
    std::fs::write(&path, named).unwrap();
    assert!(run(&s, &path, &["--mode", "in-process"]).status.success());
    let rrd = s.join("out/seed002-sine.rrd");
    let out = launcher(&s)
        .arg("export")
        .arg(&rrd)
        .arg("--csv")
        .arg(s.join("csv"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let header = |file: &str| {
        std::fs::read_to_string(s.join("csv").join(file))
            .unwrap()
            .lines()
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(
        header("plant_x.csv"),
        "step,sim_time,pos [m],vel [m/s],volt [V]"
    );
    assert_eq!(
        header("plant_y.csv"),
        "step,sim_time,pos_meas [m],volt_meas [V]"
    );
    assert_eq!(
        header("observer_uio_xhat.csv"),
        "step,sim_time,pos [m],vel [m/s],volt [V]"
    );
    assert_eq!(
        header("observer_uio_error.csv"),
        "step,sim_time,e1 [m],e2 [m/s],e3 [V]"
    );
    assert_eq!(
        header("observer_luenberger_residual.csv"),
        "step,sim_time,r1 [m],r2 [V]"
    );
    // Closed loop without `track`: u = r − G x̂, r a reference in the input's own unit.
    assert_eq!(
        header("input.csv"),
        "step,sim_time,force ref [N],supply ref [V]"
    );
    assert_eq!(header("observer_uio_what.csv"), "step,sim_time,gust [N]");
    assert_eq!(
        header("controller_u.csv"),
        "step,sim_time,force (u) [N],supply (u) [V]"
    );
    assert_eq!(header("disturbance.csv"), "step,sim_time,gust [N]");
    let latency = header("latency.csv");
    let cols: Vec<&str> = latency.split(',').collect();
    assert_eq!(
        cols.iter().filter(|c| **c == "step").count(),
        1,
        "{latency}"
    );
    assert!(cols.contains(&"step_latency [µs]"), "{latency}");
    // Plots: titles, axis labels and legends carry the names and units.
    let r = read(&rrd).unwrap();
    let figs = figures(&r, &PlotSelection::default()).unwrap();
    let (file, fig) = figs.iter().find(|(f, _)| f.starts_with("state_2")).unwrap();
    assert_eq!(file, "state_2_vel.png");
    assert_eq!(fig.y_label, "vel [m/s]");
    assert!(fig.title.contains("vel") && fig.curves.iter().any(|c| c.label == "vel (uio)"));
    let outputs = &figs.iter().find(|(f, _)| f == "outputs.png").unwrap().1;
    let labels: Vec<&str> = outputs.curves.iter().map(|c| c.label.as_str()).collect();
    assert_eq!(labels, ["pos_meas [m]", "volt_meas [V]"]);
    let inputs = &figs.iter().find(|(f, _)| f == "inputs.png").unwrap().1;
    let labels: Vec<&str> = inputs.curves.iter().map(|c| c.label.as_str()).collect();
    assert_eq!(
        labels,
        [
            "force ref [N]",
            "supply ref [V]",
            "force (u) [N]",
            "supply (u) [V]"
        ]
    );
    // With `track`, each reference is the setpoint of what its row picks: a state by a unit
    // row, an output by a row of C, else z_j without a unit.
    for (track, want) in [
        (
            "[[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]",
            "step,sim_time,pos ref [m],volt ref [V]",
        ),
        (
            "[[0.0, 1.0, 0.0], [1.0, 0.0, 1.0]]",
            "step,sim_time,vel ref [m/s],z2 ref",
        ),
    ] {
        let tracked = std::fs::read_to_string(&path).unwrap().replacen(
            "[controller]",
            &format!("[controller]\ntrack = {track}"),
            1,
        );
        let t = s.join("tracked.toml");
        std::fs::write(&t, tracked).unwrap();
        let out = launcher(&s)
            .arg("run")
            .arg(&t)
            .args(["--mode", "in-process", "--force", "--out"])
            .arg(s.join("tracked"))
            .output()
            .unwrap();
        assert!(out.status.success(), "{track}: {:?}", text(&out));
        let out = launcher(&s)
            .arg("export")
            .arg(s.join("tracked/seed002-sine.rrd"))
            .arg("--csv")
            .arg(s.join("tracked-csv"))
            .arg("--force")
            .output()
            .unwrap();
        assert!(out.status.success(), "{:?}", text(&out));
        let got = std::fs::read_to_string(s.join("tracked-csv/input.csv")).unwrap();
        assert_eq!(got.lines().next().unwrap(), want, "{track}");
    }
    // A names list of the wrong length is bad input, named by file and field.
    let bad = std::fs::read_to_string(&path).unwrap().replace(
        "output_names = [\"pos_meas\", \"volt_meas\"]",
        "output_names = [\"pos_meas\"]",
    );
    std::fs::write(&path, bad).unwrap();
    let out = run(&s, &path, &["--mode", "in-process", "--force"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("named.toml")
            && err.contains("plant.output_names")
            && err.contains("has 1 entry, C has 2 rows"),
        "{err}"
    );
}

/// The diagnosis view draws J on a log axis (its values log10, 0 at the floor), and
/// each threshold dashed in the colour of the evaluation it bounds.
#[test]
fn the_diagnosis_view_has_j_on_a_log_axis_and_dashed_thresholds_in_their_colours() {
    let s = Scratch::new("plot-diagnosis");
    let out = run(
        &s,
        &scenario("seed002-actuator-faults"),
        &["--mode", "in-process"],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    let r = recording::read::read(&s.join("out/seed002-actuator-faults.rrd")).unwrap();
    let figs = figures(&r, &PlotSelection::default()).unwrap();
    let (_, fig) = figs
        .iter()
        .find(|(f, _)| f == "diagnosis_gos.png")
        .expect("a diagnosis view");
    assert_eq!(fig.scale, Scale::Log);
    for i in 1..=2 {
        let j = fig
            .curves
            .iter()
            .find(|c| c.label.starts_with(&format!("J{i}")))
            .unwrap();
        let t = fig
            .curves
            .iter()
            .find(|c| c.label.starts_with(&format!("threshold {i}")))
            .unwrap();
        assert!(t.dashed && !j.dashed);
        assert_eq!(t.line.color, j.line.color, "threshold {i}");
        let raw = r.series[&format!("/diagnosis/gos/threshold/{i}")].values[0];
        assert_eq!(t.points[0].1, raw.log10(), "threshold {i} on the log axis");
    }
}

/// A state name of 250 characters (scenario files allow it): before, `plot` stopped at its
/// file, "File name too long", and wrote nothing. The file carries the name's first 64
/// characters; the plot's title and axis the whole name.
#[test]
fn a_state_name_of_250_characters_is_plotted_under_a_file_name_that_fits() {
    let s = Scratch::new("plot-long-name");
    let long = "x".repeat(250);
    let text_ = std::fs::read_to_string(scenario("seed002-sine")).unwrap();
    let path = s.join("long.toml");
    std::fs::write(
        &path,
        text_.replacen(
            "[plant]",
            &format!("[plant]\nstate_names = [\"{long}\", \"vel\", \"volt\"]"),
            1,
        ),
    )
    .unwrap();
    assert!(run(&s, &path, &["--mode", "in-process"]).status.success());
    let out = launcher(&s)
        .arg("plot")
        .arg(s.join("out/seed002-sine.rrd"))
        .arg("--out")
        .arg(s.join("png"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{:?}", text(&out));
    let file = format!("state_1_{}.png", "x".repeat(64));
    assert!(s.join("png").join(&file).is_file(), "{file} missing");
    let figs = figures(
        &read(&s.join("out/seed002-sine.rrd")).unwrap(),
        &PlotSelection::default(),
    )
    .unwrap();
    let fig = &figs.iter().find(|(f, _)| *f == file).unwrap().1;
    assert!(
        fig.title.contains(&long) && fig.y_label.contains(&long),
        "{}",
        fig.title
    );
}

/// The sorted legends of the latency views (`latency.png`, `latency_followers.png`) of shipped
/// scenario `name` run across processes.
fn latency_legends(s: &Scratch, name: &str) -> [Vec<String>; 2] {
    let out = run(s, &scenario(name), &["--mode", "processes"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let r = recording::read::read(&s.join(&format!("out/{name}.rrd"))).unwrap();
    let figs = figures(&r, &PlotSelection::default()).unwrap();
    ["latency.png", "latency_followers.png"].map(|file| {
        let (_, fig) = figs.iter().find(|(f, _)| f == file).expect(file);
        let mut l: Vec<String> = fig.curves.iter().map(|c| c.label.clone()).collect();
        l.sort();
        l
    })
}

/// Across processes the follower Luenberger observer trails the plant in batches: its
/// "latency" is a batch delay of milliseconds. It gets a view of its own, so that the lockstep's
/// hops (µs) keep a readable axis. In open loop every observer but the first is such a follower.
#[test]
fn the_followers_batch_delay_is_plotted_apart_from_the_lockstep_hops() {
    let s = Scratch::new("plot-latency");
    let [ring, followers] = latency_legends(&s, "seed002-sine");
    assert_eq!(
        ring,
        [
            "controller->plant",
            "observer/uio->controller",
            "plant->observer/uio",
            "step"
        ]
    );
    assert_eq!(followers, ["plant->observer/luenberger"]);
    // In open loop the plant reads no estimate: the first observer keeps it in step, and every
    // other trails it.
    let [ring, followers] = latency_legends(&s, "dc-motor-load-torque");
    assert_eq!(ring, ["plant->observer/uio", "step"]);
    assert_eq!(
        followers,
        ["plant->observer/hui-zak", "plant->observer/luenberger"]
    );
}

/// A one-state plant run in one process for the timing lines `head` (dt, duration, a
/// `time_unit`): its recording and its figures.
fn slow_run(s: &Scratch, head: &str) -> (recording::read::Recording, Vec<(String, Figure)>) {
    let path = s.join("slow.toml");
    std::fs::write(
        &path,
        format!("name = \"slow\"\n{head}\n[plant]\nA = [[-0.0002]]\nB = [[0.0001]]\nC = [[1.0]]\nx0 = [1.0]\n\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n\n[[observer]]\nname = \"luenberger\"\nkind = \"luenberger\"\npoles = [-0.001]\n"),
    )
    .unwrap();
    let out = run(s, &path, &["--mode", "in-process"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let r = recording::read::read(&s.join("out/slow.rrd")).unwrap();
    let figs = figures(&r, &PlotSelection::default()).unwrap();
    (r, figs)
}

/// A scenario written with `time_unit = "min"` is plotted in minutes, whatever its length.
#[test]
fn a_run_in_its_own_time_unit_is_plotted_in_it() {
    let s = Scratch::new("plot-minutes");
    let (_, figs) = slow_run(&s, "time_unit = \"min\"\ndt = 1\nduration = 2880\n");
    let (_, state) = figs.iter().find(|(f, _)| f.starts_with("state_1")).unwrap();
    assert_eq!(state.x_label, "t [min]");
    // Step 2879 of a minute each.
    let last = state.curves[0].points.last().unwrap().0;
    assert!((last - 2879.0).abs() < 1e-9, "{last}");
}

/// A two-day run at dt = 60 s reads in hours, not in 10⁵ seconds; `--from`/`--to` take seconds
/// (or a time with its unit, `python/tests/test_time_units.py`).
#[test]
fn a_two_day_run_is_plotted_in_hours() {
    let s = Scratch::new("plot-hours");
    let (r, figs) = slow_run(&s, "dt = 60.0\nduration = 172800.0\n");
    let (_, state) = figs.iter().find(|(f, _)| f.starts_with("state_1")).unwrap();
    assert_eq!(state.x_label, "t [h]");
    let last = state.curves[0].points.last().unwrap().0;
    assert!((last - 2879.0 * 60.0 / 3600.0).abs() < 1e-9, "{last}");
    // A window of the second day, in seconds as the options take it.
    let sel = PlotSelection {
        signals: vec!["/plant/**".into()],
        from: Some(86_400.0),
        to: None,
    };
    let figs = figures(&r, &sel).unwrap();
    let (_, state) = figs.iter().find(|(f, _)| f.starts_with("state_1")).unwrap();
    assert!((state.curves[0].points[0].0 - 24.0).abs() < 1e-9);
    for (duration, unit) in [
        (20.0, "s"),
        (600.0, "min"),
        (172_800.0, "h"),
        (864_000.0, "days"),
    ] {
        assert_eq!(lti::units::scale(duration).0, unit, "{duration}");
    }
}
