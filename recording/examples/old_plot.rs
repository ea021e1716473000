//! `launcher plot`: one PNG per view of the recording's blueprint — each state with every
//! observer's estimate, each observer's errors and residuals, the unknown inputs, the inputs,
//! the outputs, and the latency — drawn with plotters' pure-Rust bitmap backend and an embedded
//! font (DejaVu Sans), so nothing but this binary is needed on the machine.

use std::path::{Path, PathBuf};
use std::sync::Once;

use lti::eig::sig;
use plotters::prelude::*;
use plotters::style::FontStyle;

use recording::{Recording, Series};
use recording::tools::recorded_scenario;

const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
const SIZE: (u32, u32) = (1200, 600);

/// One figure: a title, a y label, and its series (legend, entity).
struct View {
    file: String,
    title: String,
    y_label: String,
    series: Vec<(String, String)>,
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is valid TrueType; a failure would only leave plots without text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Min and max per pixel column: the shape of a long series survives, at a few thousand points.
fn decimate(s: &Series, x_of: impl Fn(i64) -> f64, width: usize) -> Vec<(f64, f64)> {
    let n = s.values.len();
    if n <= 2 * width {
        return s.steps.iter().zip(&s.values).map(|(&k, &v)| (x_of(k), v)).filter(|p| p.1.is_finite()).collect();
    }
    let per = n.div_ceil(width);
    let mut out = Vec::with_capacity(2 * width);
    for chunk in s.steps.chunks(per).zip(s.values.chunks(per)) {
        let (ks, vs) = chunk;
        let (mut lo, mut hi) = (0, 0);
        for i in 0..vs.len() {
            if vs[i] < vs[lo] {
                lo = i;
            }
            if vs[i] > vs[hi] {
                hi = i;
            }
        }
        for i in if lo <= hi { [lo, hi] } else { [hi, lo] } {
            if vs[i].is_finite() {
                out.push((x_of(ks[i]), vs[i]));
            }
        }
    }
    out
}

fn views(r: &Recording) -> Vec<View> {
    let scenario = recorded_scenario(r);
    let mut out = Vec::new();
    let legend = |path: &str| r.names.get(path).cloned().unwrap_or_else(|| path.to_string());
    let matching = |prefix: &str| -> Vec<(String, String)> { r.series.keys().filter(|p| p.starts_with(prefix)).map(|p| (legend(p), p.clone())).collect() };
    let observers: Vec<String> = {
        let mut v: Vec<String> = r.series.keys().filter_map(|p| p.strip_prefix("/observer/").and_then(|x| x.split_once('/')).map(|(n, _)| n.to_string())).collect();
        v.dedup();
        // In the scenario's order where it is known.
        let order: Vec<String> = scenario.as_ref().map(|s| s.observers.iter().map(|o| o.name.clone()).collect()).unwrap_or_default();
        v.sort_by_key(|n| order.iter().position(|o| o == n).unwrap_or(usize::MAX));
        v
    };
    let n = r.series.keys().filter(|p| p.starts_with("/plant/x/")).count();
    for i in 0..n {
        let (name, unit) = match &scenario {
            Some(s) if i < s.names.state.len() => (s.names.state[i].name.clone(), s.names.state[i].unit.clone()),
            _ => (format!("x{}", i + 1), String::new()),
        };
        let mut series = vec![(legend(&format!("/plant/x/{}", i + 1)), format!("/plant/x/{}", i + 1))];
        series.extend(observers.iter().map(|o| (legend(&format!("/observer/{o}/xhat/{}", i + 1)), format!("/observer/{o}/xhat/{}", i + 1))));
        let y_label = if unit.is_empty() { name.clone() } else { format!("{name} [{unit}]") };
        out.push(View { file: format!("state_{}_{}.png", i + 1, sanitize(&name)), title: format!("state x{}: {name}, true and estimated", i + 1), y_label, series });
    }
    for o in &observers {
        out.push(View { file: format!("error_{}.png", sanitize(o)), title: format!("estimation error e = x − xhat ({o})"), y_label: "e".into(), series: matching(&format!("/observer/{o}/error/")) });
        out.push(View { file: format!("residual_{}.png", sanitize(o)), title: format!("residual r = y − C·xhat ({o})"), y_label: "r".into(), series: matching(&format!("/observer/{o}/residual/")) });
    }
    let mut unknown = matching("/disturbance/");
    unknown.extend(matching("/measurement_disturbance/"));
    if !unknown.is_empty() {
        out.push(View { file: "unknown_inputs.png".into(), title: "unknown inputs w (state) and v (measurement)".into(), y_label: "w, v".into(), series: unknown });
    }
    let mut inputs = matching("/input/");
    inputs.extend(matching("/controller/u/"));
    out.push(View { file: "inputs.png".into(), title: "known inputs r and controller output u".into(), y_label: "r, u".into(), series: inputs });
    out.push(View { file: "outputs.png".into(), title: "measured outputs y".into(), y_label: "y".into(), series: matching("/plant/y/") });
    let latency = matching("/latency/");
    if !latency.is_empty() {
        out.push(View { file: "latency.png".into(), title: "lockstep latency".into(), y_label: "latency [µs]".into(), series: latency });
    }
    out.retain(|v| !v.series.is_empty());
    out
}

fn sanitize(s: &str) -> String {
    s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect()
}

/// Draws every view of `r` into `dir`; returns the files written.
fn plot(r: &Recording, dir: &Path) -> Result<Vec<PathBuf>, String> {
    register_font();
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let dt = recorded_scenario(r).map(|s| s.dt);
    let x_of = |k: i64| dt.map_or(k as f64, |dt| k as f64 * dt);
    let x_label = if dt.is_some() { "t [s]" } else { "step" };
    let mut written = Vec::new();
    for view in views(r) {
        let scale = if view.file == "latency.png" { 1e-3 } else { 1.0 };
        let curves: Vec<(String, Vec<(f64, f64)>)> = view
            .series
            .iter()
            .filter_map(|(name, path)| r.series.get(path).map(|s| (name.clone(), decimate(s, x_of, SIZE.0 as usize).into_iter().map(|(x, y)| (x, y * scale)).collect())))
            .collect();
        let points = curves.iter().flat_map(|(_, c)| c.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for &(x, y) in points {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if !x0.is_finite() {
            continue;
        }
        if x1 <= x0 {
            x1 = x0 + 1.0;
        }
        let pad = if y1 > y0 { 0.05 * (y1 - y0) } else { y0.abs().max(1.0) * 0.5 };
        let (y0, y1) = (y0 - pad, y1 + pad);
        let path = dir.join(&view.file);
        draw(&path, &view, &curves, (x0, x1, y0, y1), x_label).map_err(|e| format!("{}: {e}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

fn draw(path: &Path, view: &View, curves: &[(String, Vec<(f64, f64)>)], (x0, x1, y0, y1): (f64, f64, f64, f64), x_label: &str) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&view.title, ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(85)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    // Six significant digits; values within rounding of zero print as 0, not −0.0.
    let snap = 1e-9 * y0.abs().max(y1.abs());
    let tick = |v: &f64| if v.abs() < snap { "0".to_string() } else { sig(*v) };
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(&view.y_label)
        .label_style(("sans-serif", 15))
        .y_label_formatter(&tick)
        .x_label_formatter(&|v| sig(*v))
        .draw()?;
    for (i, (name, points)) in curves.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let style = ShapeStyle { color, filled: false, stroke_width: if i == 0 { 3 } else { 2 } };
        chart
            .draw_series(LineSeries::new(points.iter().copied(), style))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], style));
    }
    chart.configure_series_labels().position(SeriesLabelPosition::UpperRight).background_style(WHITE.mix(0.85)).border_style(BLACK).label_font(("sans-serif", 15)).draw()?;
    root.present()?;
    Ok(())
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let r = recording::read(Path::new(&a[1])).unwrap();
    for f in plot(&r, Path::new(&a[2])).unwrap() { println!("{}", f.display()); }
}
