//! `uio-launcher plot`: one PNG per view of the recording's blueprint — each state with every
//! observer's estimate, every observer's max |e| on a log axis, each observer's errors and
//! residuals, the unknown inputs, the inputs, the outputs, and the latency (log axis) — with
//! the names, units and colours of the Rerun views, drawn with plotters' pure-Rust bitmap
//! backend and an embedded font (DejaVu Sans), so nothing but this binary is needed.

mod figure;
mod map;
mod raster;
mod select;

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::style::FontStyle;
use scenario::{Named, Scenario};

pub use figure::{Curve, Figure, SIZE, Scale};
pub use map::{Map, draw_map};
pub use select::{Matcher, PlotSelection};

use crate::palette;
use crate::read::{Recording, Series};
use crate::signals;
use crate::tools::recorded_scenario;

const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Latencies below this (a hop measured as 0 ns) are drawn at it on the log axis, µs.
const LATENCY_FLOOR_US: f64 = 1e-3;

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is valid TrueType; a failure would only leave plots without text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// A view before its data is read: file, texts, scale, and (legend, entity path) per curve.
struct View {
    file: String,
    title: String,
    y_label: String,
    scale: Scale,
    series: Vec<(String, String)>,
}

/// Min and max per pixel column: the shape of a long series survives, at a few thousand points.
fn decimate(points: &[(f64, f64)], width: usize) -> Vec<(f64, f64)> {
    if points.len() <= 2 * width {
        return points.to_vec();
    }
    let per = points.len().div_ceil(width);
    let mut out = Vec::with_capacity(2 * width + 2);
    for chunk in points.chunks(per) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = i;
            }
            if p.1 > chunk[hi].1 {
                hi = i;
            }
        }
        out.push(chunk[lo.min(hi)]);
        if lo != hi {
            out.push(chunk[lo.max(hi)]);
        }
    }
    out
}

/// Numbered members of a group, ascending: "/plant/x" → [(1, "/plant/x/1"), …]. Components
/// number from 1; a member numbered 0 (a recording from before that rule) is left out, so
/// that every k here has a component k − 1.
fn members(r: &Recording, group: &str) -> Vec<(usize, String)> {
    let prefix = format!("{group}/");
    let mut v: Vec<(usize, String)> = r
        .series
        .keys()
        .filter_map(|p| {
            p.strip_prefix(&prefix)
                .and_then(|m| m.parse().ok())
                .filter(|&k: &usize| k >= 1)
                .map(|k| (k, p.clone()))
        })
        .collect();
    v.sort();
    v
}

/// "y [m]" when every member shares the unit, else "y".
fn common_unit(what: &str, units: &[String]) -> String {
    match units.first() {
        Some(u) if !u.is_empty() && units.iter().all(|x| x == u) => format!("{what} [{u}]"),
        _ => what.to_string(),
    }
}

/// A name as part of a file name: ASCII letters, digits, `-` and `_`, at most [`NAME_IN_FILE`]
/// characters (a file name holds at most 255 bytes: a 250-character state name made `plot`
/// write nothing, "File name too long"). The files stay distinct by their index or by names
/// that are distinct within their 64 first characters (observers' and diagnosers' are at most 64).
pub fn sanitize(s: &str) -> String {
    s.chars()
        .take(NAME_IN_FILE)
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The longest name a plot's file name carries.
const NAME_IN_FILE: usize = 64;

// one job: the plot views of a recording, one arm per view in the order `plot` writes them.
fn views(r: &Recording, s: Option<&Scenario>, observers: &[String]) -> Vec<View> {
    let named = |path: &str| {
        signals::named(s, path).unwrap_or_else(|| Named {
            name: r
                .names
                .get(path)
                .cloned()
                .unwrap_or_else(|| path.to_string()),
            unit: String::new(),
        })
    };
    let legend = |path: &str| named(path).with_unit();
    // "e3: eta [rad]" for a named state, "e3 [rad]" for one with the default name.
    let tagged =
        |tag: String, of: Named, default: String| match (of.name == default, of.unit.is_empty()) {
            (true, true) => tag,
            (true, false) => format!("{tag} [{}]", of.unit),
            (false, _) => format!("{tag}: {}", of.with_unit()),
        };
    let mut out = Vec::new();
    for (k, path) in members(r, "/plant/x") {
        let x = named(&path);
        let mut series = vec![(format!("{} (true)", x.name), path.clone())];
        series.extend(
            observers
                .iter()
                .map(|o| (format!("{} ({o})", x.name), signals::estimate(o, k - 1))),
        );
        let title = if x.name == format!("x{k}") {
            format!("x{k} — true and estimated")
        } else {
            format!("x{k}: {} — true and estimated", x.name)
        };
        out.push(View {
            file: format!("state_{k}_{}.png", sanitize(&x.name)),
            title,
            y_label: x.with_unit(),
            scale: Scale::Linear,
            series,
        });
    }
    let state_units: Vec<String> = members(r, "/plant/x")
        .iter()
        .map(|(_, p)| named(p).unit)
        .collect();
    if !observers.is_empty() {
        let series = observers
            .iter()
            .map(|o| (format!("max |e| ({o})"), signals::log_error(o)))
            .collect();
        let title = format!(
            "max_i |e_i| of every observer, log scale (0 drawn at {:e})",
            signals::LOG_FLOOR
        );
        out.push(View {
            file: "errors_log.png".into(),
            title,
            y_label: common_unit("max |e|", &state_units),
            scale: Scale::Log,
            series,
        });
    }
    for o in observers {
        let errors = members(r, &format!("/observer/{o}/error"));
        let units: Vec<String> = errors.iter().map(|(_, p)| named(p).unit).collect();
        let series = errors
            .iter()
            .map(|(k, p)| {
                (
                    tagged(
                        format!("e{k}"),
                        named(&signals::state(k - 1)),
                        format!("x{k}"),
                    ),
                    p.clone(),
                )
            })
            .collect();
        out.push(View {
            file: format!("error_{}.png", sanitize(o)),
            title: format!("estimation error e = x − xhat ({o})"),
            y_label: common_unit("e", &units),
            scale: Scale::Linear,
            series,
        });
        let residuals = members(r, &format!("/observer/{o}/residual"));
        let units: Vec<String> = residuals.iter().map(|(_, p)| named(p).unit).collect();
        let series = residuals
            .iter()
            .map(|(k, p)| {
                (
                    tagged(
                        format!("r{k}"),
                        named(&signals::output(k - 1)),
                        format!("y{k}"),
                    ),
                    p.clone(),
                )
            })
            .collect();
        out.push(View {
            file: format!("residual_{}.png", sanitize(o)),
            title: format!("residual r = y − C·xhat ({o})"),
            y_label: common_unit("r", &units),
            scale: Scale::Linear,
            series,
        });
        // A UIO's ŵ beside the true w it estimates.
        let estimates = members(r, &format!("/observer/{o}/what"));
        if !estimates.is_empty() {
            let mut series = Vec::new();
            let mut units = Vec::new();
            for (k, p) in &estimates {
                let w = named(&signals::disturbance(k - 1));
                series.push((format!("{} (true)", w.name), signals::disturbance(k - 1)));
                series.push((format!("{} estimate ({o})", w.name), p.clone()));
                units.push(w.unit);
            }
            out.push(View {
                file: format!("input_estimate_{}.png", sanitize(o)),
                title: format!(
                    "unknown inputs w and their estimate ŵ ({o}; ŵ_k is known at t_(k+1))"
                ),
                y_label: common_unit("w", &units),
                scale: Scale::Linear,
                series,
            });
        }
    }
    let group = |groups: &[&str]| -> (Vec<(String, String)>, Vec<String>) {
        let paths: Vec<String> = groups
            .iter()
            .flat_map(|g| members(r, g))
            .map(|(_, p)| p)
            .collect();
        (
            paths.iter().map(|p| (legend(p), p.clone())).collect(),
            paths.iter().map(|p| named(p).unit).collect(),
        )
    };
    let (series, units) = group(&["/disturbance", "/measurement_disturbance"]);
    out.push(View {
        file: "unknown_inputs.png".into(),
        title: "unknown inputs w (state) and v (measurement)".into(),
        y_label: common_unit("w, v", &units),
        scale: Scale::Linear,
        series,
    });
    let (series, units) = group(&["/input", "/controller/u"]);
    out.push(View {
        file: "inputs.png".into(),
        title: "known inputs r and controller output u".into(),
        y_label: common_unit("r, u", &units),
        scale: Scale::Linear,
        series,
    });
    let (series, units) = group(&["/plant/y"]);
    out.push(View {
        file: "outputs.png".into(),
        title: "measured outputs y".into(),
        y_label: common_unit("y", &units),
        scale: Scale::Linear,
        series,
    });
    // Diagnosis: per bank its evaluations against their thresholds and its decisions, then the
    // injected faults (legends as recorded).
    let recorded = |prefix: &str| -> Vec<(String, String)> {
        r.series
            .keys()
            .filter(|p| p.starts_with(prefix))
            .map(|p| {
                (
                    r.names.get(p).cloned().unwrap_or_else(|| p.clone()),
                    p.clone(),
                )
            })
            .collect()
    };
    let mut banks: Vec<&str> = r
        .series
        .keys()
        .filter_map(|p| {
            p.strip_prefix("/diagnosis/")
                .and_then(|x| x.split_once('/'))
                .map(|(d, _)| d)
        })
        .collect();
    banks.dedup();
    for d in banks {
        let series = [
            recorded(&format!("/diagnosis/{d}/evaluation/")),
            recorded(&format!("/diagnosis/{d}/threshold/")),
        ]
        .concat();
        out.push(View {
            file: format!("diagnosis_{}.png", sanitize(d)),
            title: format!("residual evaluations J (solid) and their thresholds (dashed, same colour), log scale ({d})"),
            y_label: "J".into(),
            scale: Scale::Log,
            series,
        });
        let series = [
            recorded(&format!("/diagnosis/{d}/alarm/")),
            recorded(&format!("/diagnosis/{d}/isolated")),
        ]
        .concat();
        out.push(View {
            file: format!("alarms_{}.png", sanitize(d)),
            title: format!("alarms and isolated channel ({d}; 0 none, −1 unknown)"),
            y_label: "alarm, channel".into(),
            scale: Scale::Linear,
            series,
        });
    }
    let faults: Vec<(String, String)> = recorded("/fault/")
        .into_iter()
        .filter(|(_, p)| p.ends_with("/value"))
        .collect();
    if !faults.is_empty() {
        out.push(View {
            file: "faults.png".into(),
            title: "injected faults (magnitude while active)".into(),
            y_label: "fault".into(),
            scale: Scale::Linear,
            series: faults,
        });
    }
    // The lockstep's own hops, and apart from them the followers' batch delays (milliseconds
    // that would squash the hops' microseconds on one axis).
    let latency = |followers: bool| -> Vec<(String, String)> {
        r.series
            .keys()
            .filter(|p| p.starts_with("/latency/"))
            .filter(|p| s.is_some_and(|s| signals::follower_hop(s, p)) == followers)
            .map(|p| {
                (
                    r.names
                        .get(p)
                        .cloned()
                        .unwrap_or_else(|| p.trim_start_matches("/latency/").to_string()),
                    p.clone(),
                )
            })
            .collect()
    };
    out.push(View {
        file: "latency.png".into(),
        title: "lockstep latency, log scale".into(),
        y_label: "latency [µs]".into(),
        scale: Scale::Log,
        series: latency(false),
    });
    let followers = latency(true);
    if !followers.is_empty() {
        out.push(View {
            file: "latency_followers.png".into(),
            title: "followers' batch delay (observers off the lockstep ring), log scale".into(),
            y_label: "delay [µs]".into(),
            scale: Scale::Log,
            series: followers,
        });
    }
    out
}

/// max_i |e_i| of `o` per step, as log10 (zeros at the floor); from the recorded errors, so
/// it works for any recording.
fn log_max_error(r: &Recording, o: &str) -> Option<Series> {
    let errors: Vec<&Series> = members(r, &format!("/observer/{o}/error"))
        .iter()
        .filter_map(|(_, p)| r.series.get(p))
        .collect();
    let first = errors.first()?;
    let mut out = Series {
        steps: first.steps.clone(),
        values: vec![0.0; first.steps.len()],
    };
    for e in &errors {
        // Series of one group share their steps; a shorter one (a killed writer) cuts the rest.
        let n = out.values.len().min(e.values.len());
        out.values.truncate(n);
        out.steps.truncate(n);
        for (m, v) in out.values.iter_mut().zip(&e.values) {
            *m = crate::write::nan_max(*m, v.abs());
        }
    }
    out.values
        .iter_mut()
        .for_each(|v| *v = signals::log10_floored(*v));
    Some(out)
}

/// The time axis's unit for the run of `s`, and its length in seconds: the scenario's own
/// `time_unit` (validated when it was read), else the one its length reads in
/// ([`lti::units::scale`]: a two-day run in hours).
fn axis_unit(s: &scenario::Scenario) -> (&str, f64) {
    match s.time_unit.as_deref() {
        Some(u) => (u, lti::units::unit_seconds(u).unwrap_or(1.0)),
        None => lti::units::scale(s.duration),
    }
}

/// The figures of every selected view of `r`, with their file names; an error names what is
/// wrong (a bad selection, nothing selected).
pub fn figures(r: &Recording, selection: &PlotSelection) -> Result<Vec<(String, Figure)>, String> {
    let sel = selection.matcher()?;
    let scenario = recorded_scenario(r);
    let s = scenario.as_ref();
    // Time in the run's own scale: a two-day run reads in hours, not in 10⁵ s.
    let (x_label, axis) = match s {
        Some(s) => {
            let (unit, per) = axis_unit(s);
            (format!("t [{unit}]"), Some((s.dt, per)))
        }
        None => ("step".to_string(), None),
    };
    let seconds = |k: i64| axis.map_or(k as f64, |(dt, _)| k as f64 * dt);
    let x_of = |k: i64| axis.map_or(k as f64, |(dt, per)| k as f64 * dt / per);
    let observers = crate::signals::observers_of(r.series.keys(), s);
    // The scenario's order gives each observer its colour.
    let order: Vec<String> = s
        .map(|s| s.observers.iter().map(|o| o.name.clone()).collect())
        .unwrap_or_default();
    let colours: Vec<String> = if order.is_empty() {
        observers.clone()
    } else {
        order
    };
    let width = (SIZE.0 as usize).saturating_sub(400);
    let mut out = Vec::new();
    for view in views(r, s, &observers) {
        let mut curves = Vec::new();
        for (label, path) in &view.series {
            let derived = path.ends_with("/log10_max_abs_error");
            let observer = path
                .strip_prefix("/observer/")
                .and_then(|p| p.split_once('/'))
                .map(|(o, _)| o);
            let chosen = sel.entity(path)
                || (derived
                    && observer.is_some_and(|o| {
                        members(r, &format!("/observer/{o}/error"))
                            .iter()
                            .any(|(_, p)| sel.entity(p))
                    }));
            if !chosen {
                continue;
            }
            let owned;
            let series = match (derived, observer) {
                (true, Some(o)) => match log_max_error(r, o) {
                    Some(s) => {
                        owned = s;
                        &owned
                    }
                    None => continue,
                },
                _ => match r.series.get(path) {
                    Some(s) => s,
                    None => continue,
                },
            };
            let latency = path.starts_with("/latency/");
            let us_per_value = r.latency_ns_per_value() * 1e-3;
            // J spans decades (rounding before a fault, its size after): on a log axis, 0 at the floor.
            let threshold = path.starts_with("/diagnosis/") && path.contains("/threshold/");
            let evaluation =
                threshold || (path.starts_with("/diagnosis/") && path.contains("/evaluation/"));
            let y = |v: f64| {
                if latency {
                    (v * us_per_value).max(LATENCY_FLOOR_US).log10()
                } else if evaluation {
                    signals::log10_floored(v)
                } else {
                    v
                }
            };
            let points: Vec<(f64, f64)> = series
                .steps
                .iter()
                .zip(&series.values)
                .filter(|(k, _)| sel.time(seconds(**k)))
                .map(|(&k, &v)| (x_of(k), y(v)))
                .filter(|p| p.1.is_finite())
                .collect();
            if points.is_empty() {
                continue;
            }
            curves.push(Curve {
                label: label.clone(),
                line: palette::line(path, &colours),
                points: decimate(&points, width),
                dashed: threshold,
            });
        }
        if !curves.is_empty() {
            out.push((
                view.file,
                Figure {
                    title: view.title,
                    y_label: view.y_label,
                    x_label: x_label.clone(),
                    scale: view.scale,
                    x_scale: Scale::Linear,
                    curves,
                },
            ));
        }
    }
    if out.is_empty() {
        return Err(format!(
            "nothing to plot: no selected signal has data{}",
            if selection.from.is_some() || selection.to.is_some() {
                " in the time window"
            } else {
                ""
            }
        ));
    }
    Ok(out)
}

/// Draws one figure into the PNG `path` (in the style of `plot`'s views); false when it has
/// no finite point (nothing written).
pub fn draw(path: &Path, fig: &Figure) -> Result<bool, String> {
    register_font();
    figure::draw(path, fig)
}

/// Draws every selected view of `r` into `dir`; returns the files written.
pub fn plot(r: &Recording, dir: &Path, sel: &PlotSelection) -> Result<Vec<PathBuf>, String> {
    let figures = figures(r, sel)?;
    register_font();
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let mut written = Vec::new();
    for (file, fig) in figures {
        let path = dir.join(file);
        if figure::draw(&path, &fig).map_err(|e| format!("{}: {e}", path.display()))? {
            written.push(path);
        }
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_member_numbered_0_is_left_out_so_no_index_wraps() {
        let mut r = Recording::default();
        for p in [
            "/plant/x/0",
            "/plant/x/1",
            "/plant/x/2",
            "/observer/uio/error/0",
            "/observer/uio/xhat/0",
        ] {
            r.series.insert(
                p.into(),
                Series {
                    steps: vec![0],
                    values: vec![1.0],
                },
            );
        }
        assert_eq!(
            members(&r, "/plant/x"),
            [(1, "/plant/x/1".to_string()), (2, "/plant/x/2".to_string())]
        );
        assert!(members(&r, "/observer/uio/error").is_empty());
        // Every view of such a recording is built without an index k − 1 wrapping.
        let views = views(&r, None, &["uio".to_string()]);
        let states: Vec<&str> = views
            .iter()
            .filter(|v| v.file.starts_with("state_"))
            .map(|v| v.file.as_str())
            .collect();
        assert_eq!(states.len(), 2, "{states:?}");
        assert!(
            views
                .iter()
                .find(|v| v.file == "error_uio.png")
                .is_some_and(|v| v.series.is_empty())
        );
    }
}
