//! What a variation gives: a table (per figure its nominal value, its range and its worst
//! point, named), `<name>.vary.csv` (a row per point), `<name>.vary.json`, and one PNG per
//! figure and varied parameter: the figure against the parameter, one curve per combination of
//! the other parameters' grid values (up to eight), the nominal value marked by a dashed line.

use std::path::{Path, PathBuf};

use recording::palette::{Line, THIN, color};
use recording::plot::{Curve, Figure, Scale};

use super::figures::larger_is_worse;
use super::spec::Vary;
use super::{Outcome, Point};
use crate::error::LaunchError;
use scenario::Scenario;

/// Most curves in one plot: more combinations of the other parameters are not drawn.
const MAX_CURVES: usize = 8;

/// The figure columns, in the order the points first give them.
pub fn columns(outcomes: &[Outcome]) -> Vec<String> {
    let mut cols: Vec<String> = Vec::new();
    for o in outcomes {
        for (c, _) in &o.figures.0 {
            if !cols.contains(c) {
                cols.push(c.clone());
            }
        }
    }
    cols
}

/// A point as its `--vary`s read: "A[2,3] *= 1.2, E *= 0.5".
pub fn describe(varies: &[Vary], p: &Point) -> String {
    varies
        .iter()
        .zip(&p.values)
        .map(|(v, x)| v.at(*x))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The worst completed point of `column`: (index, value).
pub fn worst(outcomes: &[Outcome], column: &str) -> Option<(usize, f64)> {
    let larger = larger_is_worse(column);
    outcomes
        .iter()
        .enumerate()
        .filter(|(_, o)| o.status == "completed")
        .filter_map(|(i, o)| o.figures.get(column).map(|v| (i, v)))
        .filter(|(_, v)| v.is_finite())
        .fold(None, |best: Option<(usize, f64)>, (i, v)| match best {
            Some((_, b)) if (larger && v <= b) || (!larger && v >= b) => best,
            _ => Some((i, v)),
        })
}

/// The table printed after a variation.
pub fn table(name: &str, varies: &[Vary], seed: u64, jobs: usize, outcomes: &[Outcome]) -> String {
    let mut t = format!(
        "{name} --vary: {} points (the nominal model and {} varied), seed {seed}, {jobs} job(s)\n",
        outcomes.len(),
        outcomes.len().saturating_sub(1)
    );
    for v in varies {
        t += &format!("  varied: {}\n", v.text);
    }
    let cols = columns(outcomes);
    let width = cols
        .iter()
        .map(|c| c.chars().count())
        .max()
        .unwrap_or(6)
        .max(6);
    t += &format!(
        "  {:<width$}  {:>12}  {:>12}  {:>12}  worst at\n",
        "figure", "nominal", "min", "max"
    );
    let fmt = |v: Option<f64>| v.map_or_else(|| "—".to_string(), lti::eig::sig);
    for c in &cols {
        let vals: Vec<f64> = outcomes
            .iter()
            .filter(|o| o.status == "completed")
            .filter_map(|o| o.figures.get(c))
            .filter(|v| v.is_finite())
            .collect();
        let min = vals.iter().copied().reduce(f64::min);
        let max = vals.iter().copied().reduce(f64::max);
        let nominal = outcomes
            .iter()
            .find(|o| o.point.nominal)
            .and_then(|o| o.figures.get(c));
        let at = worst(outcomes, c).map_or_else(
            || "—".to_string(),
            |(i, _)| {
                if outcomes[i].point.nominal {
                    "the nominal model".to_string()
                } else {
                    describe(varies, &outcomes[i].point)
                }
            },
        );
        t += &format!(
            "  {:<width$}  {:>12}  {:>12}  {:>12}  {at}\n",
            c,
            fmt(nominal),
            fmt(min),
            fmt(max)
        );
    }
    for status in ["diverged", "failed"] {
        let bad: Vec<&Outcome> = outcomes.iter().filter(|o| o.status == status).collect();
        if let Some(first) = bad.first() {
            t += &format!(
                "  {status}: {} point(s); the first at {}: {}\n",
                bad.len(),
                describe(varies, &first.point),
                first.reason.as_deref().unwrap_or("")
            );
        }
    }
    t
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// `<name>.vary.csv`: point, nominal, status, each `--vary`'s value, each figure (empty where a
/// point has none). Numbers as Rust prints an f64: the shortest text that reads back to it.
pub fn csv(varies: &[Vary], outcomes: &[Outcome]) -> String {
    let cols = columns(outcomes);
    let mut head = vec!["point".to_string(), "nominal".into(), "status".into()];
    head.extend(varies.iter().map(|v| v.text.clone()));
    head.extend(cols.iter().cloned());
    let mut t = head
        .iter()
        .map(|h| csv_field(h))
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    for (i, o) in outcomes.iter().enumerate() {
        let mut row = vec![
            i.to_string(),
            o.point.nominal.to_string(),
            o.status.to_string(),
        ];
        row.extend(o.point.values.iter().map(|v| format!("{v}")));
        row.extend(cols.iter().map(|c| {
            o.figures
                .get(c)
                .map_or_else(String::new, |v| format!("{v}"))
        }));
        t += &(row.join(",") + "\n");
    }
    t
}

/// `<name>.vary.json`.
pub fn json(name: &str, varies: &[Vary], seed: u64, outcomes: &[Outcome]) -> serde_json::Value {
    let cols = columns(outcomes);
    let points: Vec<serde_json::Value> = outcomes
        .iter()
        .map(|o| {
            let figs: serde_json::Map<String, serde_json::Value> = cols
                .iter()
                .map(|c| (c.clone(), o.figures.get(c).into()))
                .collect();
            serde_json::json!({
                "values": o.point.values,
                "nominal": o.point.nominal,
                "status": o.status,
                "reason": o.reason,
                "figures": figs,
            })
        })
        .collect();
    let worst: serde_json::Map<String, serde_json::Value> = cols
        .iter()
        .filter_map(|c| {
            worst(outcomes, c).map(|(i, v)| {
                (
                    c.clone(),
                    serde_json::json!({ "point": i, "value": v, "at": describe(varies, &outcomes[i].point) }),
                )
            })
        })
        .collect();
    serde_json::json!({
        "scenario": name,
        "seed": seed,
        "vary": varies.iter().map(|v| v.text.clone()).collect::<Vec<_>>(),
        "columns": cols,
        "points": points,
        "worst": worst,
    })
}

fn sanitize(s: &str) -> String {
    s.chars()
        .take(64)
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The values of every parameter but the `k`-th.
fn others(p: &Point, k: usize) -> Vec<f64> {
    p.values
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != k)
        .map(|(_, x)| *x)
        .collect()
}

/// The same values, bit for bit.
fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The combinations of the other parameters' values among the varied points, in point order.
fn combinations(varied: &[&Outcome], k: usize) -> Vec<Vec<f64>> {
    let mut combos: Vec<Vec<f64>> = Vec::new();
    for o in varied {
        let other = others(&o.point, k);
        if !combos.iter().any(|c| same(c, &other)) {
            combos.push(other);
        }
    }
    combos
}

/// Column `c` against parameter `k`: a curve per combination of the others (their values in
/// its legend), the nominal value as a dashed vertical line.
fn curves(
    c: &str,
    k: usize,
    varies: &[Vary],
    combos: &[Vec<f64>],
    varied: &[&Outcome],
    nominal: Option<&Outcome>,
) -> Vec<Curve> {
    let mut curves = Vec::new();
    for (n, combo) in combos.iter().enumerate() {
        // The nominal point on the curve of its other parameters' values, so that a curve
        // through it passes through it (the dashed line below marks where it is).
        let mut pts: Vec<(f64, f64)> = varied
            .iter()
            .copied()
            .chain(nominal)
            .filter(|o| o.status == "completed" && same(&others(&o.point, k), combo))
            .filter_map(|o| o.figures.get(c).map(|y| (o.point.values[k], y)))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let label = if combos.len() == 1 {
            c.to_string()
        } else {
            let rest: Vec<&Vary> = varies
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != k)
                .map(|(_, w)| w)
                .collect();
            let parts: Vec<String> = rest.iter().zip(combo).map(|(w, x)| w.at(*x)).collect();
            parts.join(", ")
        };
        curves.push(Curve {
            label,
            line: Line {
                color: color(n),
                width: THIN + 0.5,
            },
            points: pts,
            dashed: false,
        });
    }
    if let Some(nom) = nominal.and_then(|o| o.figures.get(c).map(|y| (o.point.values[k], y))) {
        let (lo, hi) = curves
            .iter()
            .flat_map(|cv| cv.points.iter().map(|p| p.1))
            .chain([nom.1])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
                (a.min(y), b.max(y))
            });
        curves.push(Curve {
            label: format!("nominal: {} {}", c, lti::eig::sig(nom.1)),
            line: Line {
                color: recording::palette::TRUE_STATE,
                width: THIN,
            },
            points: vec![(nom.0, lo), (nom.0, hi)],
            dashed: true,
        });
    }
    curves
}

/// The PNGs, into `dir`: one per figure and varied parameter; the files written, and the plots
/// left out (too many combinations of the other parameters), said as lines.
pub fn plots(
    dir: &Path,
    name: &str,
    varies: &[Vary],
    outcomes: &[Outcome],
) -> Result<(Vec<PathBuf>, Vec<String>), String> {
    let cols = columns(outcomes);
    let (mut written, mut skipped) = (Vec::new(), Vec::new());
    let varied: Vec<&Outcome> = outcomes.iter().filter(|o| !o.point.nominal).collect();
    let nominal = outcomes.iter().find(|o| o.point.nominal);
    for (k, v) in varies.iter().enumerate() {
        let combos = combinations(&varied, k);
        if combos.len() > MAX_CURVES {
            skipped.push(format!(
                "no plot against {}: {} combinations of the other parameters (at most {MAX_CURVES} curves)",
                v.text,
                combos.len()
            ));
            continue;
        }
        for c in &cols {
            let fig = Figure {
                title: format!("{name}: {c} against {}", v.text),
                y_label: c.clone(),
                x_label: v.text.clone(),
                scale: Scale::Linear,
                x_scale: Scale::Linear,
                curves: curves(c, k, varies, &combos, &varied, nominal),
            };
            let path = dir.join(format!(
                "{name}.vary_{}__{}.png",
                sanitize(c),
                sanitize(&v.text)
            ));
            if recording::plot::draw(&path, &fig)? {
                written.push(path);
            }
        }
    }
    maps(dir, name, varies, outcomes, &mut written, &mut skipped)?;
    Ok((written, skipped))
}

/// A 2-D map per figure and pair of varied parameters whose other parameters take one value
/// among the points (two varied: every pair; more: the pairs the others do not vary within):
/// `<name>.vary_<figure>__<p>__<q>.png`, the nominal point ringed and the worst crossed.
fn maps(
    dir: &Path,
    name: &str,
    varies: &[Vary],
    outcomes: &[Outcome],
    written: &mut Vec<PathBuf>,
    skipped: &mut Vec<String>,
) -> Result<(), String> {
    let varied: Vec<&Outcome> = outcomes.iter().filter(|o| !o.point.nominal).collect();
    let nominal = outcomes.iter().find(|o| o.point.nominal);
    for a in 0..varies.len() {
        for b in a + 1..varies.len() {
            let rest = |p: &Point| -> Vec<f64> {
                p.values
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != a && *j != b)
                    .map(|(_, x)| *x)
                    .collect()
            };
            let mut combos: Vec<Vec<f64>> = Vec::new();
            for o in &varied {
                let r = rest(&o.point);
                if !combos.iter().any(|c| same(c, &r)) {
                    combos.push(r);
                }
            }
            if combos.len() > 1 {
                skipped.push(format!(
                    "no map of {} against {}: the other parameters take {} values among the points",
                    varies[a].text,
                    varies[b].text,
                    combos.len()
                ));
                continue;
            }
            for c in columns(outcomes) {
                let at = |o: &Outcome| (o.point.values[a], o.point.values[b]);
                let map = recording::plot::Map {
                    title: format!("{name}: {c} over {} and {}", varies[a].text, varies[b].text),
                    x_label: varies[a].text.clone(),
                    y_label: varies[b].text.clone(),
                    value_label: c.clone(),
                    points: varied
                        .iter()
                        .filter(|o| o.status == "completed")
                        .filter_map(|o| o.figures.get(&c).map(|v| (at(o).0, at(o).1, v)))
                        .collect(),
                    nominal: nominal.map(at),
                    worst: worst(outcomes, &c).map(|(i, _)| at(&outcomes[i])),
                };
                let path = dir.join(format!(
                    "{name}.vary_{}__{}__{}.png",
                    sanitize(&c),
                    sanitize(&varies[a].text),
                    sanitize(&varies[b].text)
                ));
                if recording::plot::draw_map(&path, &map)? {
                    written.push(path);
                }
            }
        }
    }
    Ok(())
}

/// What [`write`] wrote.
pub struct Written {
    /// `<name>.vary.csv`.
    pub csv: PathBuf,
    /// `<name>.vary.json`.
    pub json: PathBuf,
    /// Its text.
    pub json_text: String,
    /// How many PNGs.
    pub pngs: usize,
    /// Plots not drawn, and why.
    pub skipped: Vec<String>,
}

/// Writes a variation's CSV, JSON and plots into `out` (the launcher's `sweep --vary` and the
/// Python package's `sweep(vary=…)`).
pub fn write(
    out: &Path,
    s: &Scenario,
    varies: &[Vary],
    outcomes: &[Outcome],
) -> Result<Written, LaunchError> {
    let csv_path = out.join(format!("{}.vary.csv", s.name));
    outputs::write_bytes(&csv_path, csv(varies, outcomes).as_bytes())
        .map_err(LaunchError::Component)?;
    let json_path = out.join(format!("{}.vary.json", s.name));
    let json_text =
        serde_json::to_string_pretty(&json(&s.name, varies, s.seed, outcomes)).expect("serialises");
    outputs::write_bytes(&json_path, (json_text.clone() + "\n").as_bytes())
        .map_err(LaunchError::Component)?;
    let (pngs, skipped) = plots(out, &s.name, varies, outcomes).map_err(LaunchError::Component)?;
    Ok(Written {
        csv: csv_path,
        json: json_path,
        json_text,
        pngs: pngs.len(),
        skipped,
    })
}
