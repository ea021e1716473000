//! One PNG of a figure over two parameters: a coloured cell per point (cells of the grid's
//! spacing when the points lie on one, else squares of a fixed size), a colour bar beside it
//! (viridis, the figure's range), the nominal point ringed and the worst one crossed.

use std::path::Path;

use plotters::prelude::*;

use super::figure::{SIZE, write_png};

/// Width of the colour bar's column.
const BAR_W: u32 = 290;
/// The side of a point's square when the points lie on no grid, pixels.
const MARKER: i32 = 16;

/// What one map shows.
pub struct Map {
    /// Caption.
    pub title: String,
    /// x axis description (the first parameter).
    pub x_label: String,
    /// y axis description (the second).
    pub y_label: String,
    /// The figure's name, over the colour bar.
    pub value_label: String,
    /// (x, y, value) per point.
    pub points: Vec<(f64, f64, f64)>,
    /// The nominal point (x, y), ringed.
    pub nominal: Option<(f64, f64)>,
    /// The worst point (x, y), crossed.
    pub worst: Option<(f64, f64)>,
}

/// The smallest gap between distinct sorted values, if the values are evenly spaced (a grid's
/// axis): cells of that width tile it.
fn spacing(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| a.to_bits() == b.to_bits());
    if v.len() < 2 {
        return None;
    }
    let gaps: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let first = gaps[0];
    gaps.iter()
        .all(|g| (g - first).abs() <= 1e-9 * first.abs().max(1.0))
        .then_some(first)
}

fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    lo.is_finite().then_some((lo, hi))
}

/// Draws `map` into the PNG `path`; false when it has no finite point (nothing written).
pub fn draw_map(path: &Path, map: &Map) -> Result<bool, String> {
    let points: Vec<(f64, f64, f64)> = map
        .points
        .iter()
        .copied()
        .filter(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
        .collect();
    let Some((v0, v1)) = bounds(points.iter().map(|p| p.2)) else {
        return Ok(false);
    };
    let xs: Vec<f64> = points.iter().map(|p| p.0).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.1).collect();
    let (sx, sy) = (spacing(&xs), spacing(&ys));
    let grid = sx.is_some() && sy.is_some();
    let (x0, x1) = bounds(xs.iter().copied()).expect("finite");
    let (y0, y1) = bounds(ys.iter().copied()).expect("finite");
    // Half a cell around a grid; 5 % around scattered points (a unit band for a single value).
    let pad = |lo: f64, hi: f64, cell: Option<f64>| match cell {
        Some(c) if grid => (lo - c / 2.0, hi + c / 2.0),
        _ if hi > lo => (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)),
        _ => (lo - 0.5 * lo.abs().max(1.0), hi + 0.5 * hi.abs().max(1.0)),
    };
    let (x0, x1) = pad(x0, x1, sx);
    let (y0, y1) = pad(y0, y1, sy);
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let mut buf = vec![255u8; 3 * w * h];
    let cells = sx.zip(sy).filter(|_| grid);
    paint(&mut buf, map, &points, cells, (x0, x1, y0, y1), (v0, v1))?;
    write_png(path, &buf)?;
    Ok(true)
}

/// The figure's colour at value v of the range [v0, v1].
fn viridis(v: f64, v0: f64, v1: f64) -> RGBColor {
    let t = if v1 > v0 { (v - v0) / (v1 - v0) } else { 0.5 };
    ViridisRGB.get_color(t as f32)
}

/// Axes, cells (of the grid's `cells` size, else squares), the nominal and worst marks and the
/// colour bar, into `buf`.
fn paint(
    buf: &mut [u8],
    map: &Map,
    points: &[(f64, f64, f64)],
    cells: Option<(f64, f64)>,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    (v0, v1): (f64, f64),
) -> Result<(), String> {
    let root = BitMapBackend::with_buffer(buf, SIZE).into_drawing_area();
    let (left, right) = root.split_horizontally(SIZE.0 - BAR_W);
    let mut chart = ChartBuilder::on(&left)
        .caption(&map.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(52)
        .y_label_area_size(96)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(&map.x_label)
        .y_desc(&map.y_label)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 16))
        .disable_mesh()
        .draw()
        .map_err(|e| e.to_string())?;
    let colour = |v: f64| viridis(v, v0, v1);
    let area = chart.plotting_area();
    for &(x, y, v) in points {
        if let Some((cx, cy)) = cells {
            area.draw(&Rectangle::new(
                [(x - cx / 2.0, y - cy / 2.0), (x + cx / 2.0, y + cy / 2.0)],
                colour(v).filled(),
            ))
            .map_err(|e| e.to_string())?;
        } else {
            let (px, py) = chart.backend_coord(&(x, y));
            root.draw(&Rectangle::new(
                [
                    (px - MARKER / 2, py - MARKER / 2),
                    (px + MARKER / 2, py + MARKER / 2),
                ],
                colour(v).filled(),
            ))
            .map_err(|e| e.to_string())?;
        }
    }
    if let Some(n) = map.nominal {
        let (px, py) = chart.backend_coord(&n);
        for r in [11, 12] {
            root.draw(&Circle::new((px, py), r, WHITE.stroke_width(2)))
                .map_err(|e| e.to_string())?;
        }
        root.draw(&Circle::new((px, py), 10, BLACK.stroke_width(2)))
            .map_err(|e| e.to_string())?;
    }
    if let Some(wp) = map.worst {
        let (px, py) = chart.backend_coord(&wp);
        for (colour, width) in [(WHITE, 5), (RED, 2)] {
            for d in [(-9, -9, 9, 9), (-9, 9, 9, -9)] {
                root.draw(&PathElement::new(
                    vec![(px + d.0, py + d.1), (px + d.2, py + d.3)],
                    colour.stroke_width(width),
                ))
                .map_err(|e| e.to_string())?;
            }
        }
    }
    colour_bar(&root, right.get_pixel_range().0.start, map, (v0, v1))?;
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}

/// The colour bar right of the map at pixel column `bx`: the figure's range bottom to top, its
/// ends and middle labelled, and the marks' legend below it.
fn colour_bar(
    root: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    bx: i32,
    map: &Map,
    (v0, v1): (f64, f64),
) -> Result<(), String> {
    let colour = |v: f64| viridis(v, v0, v1);
    let (top, bottom) = (80i32, SIZE.1 as i32 - 90);
    let style = ("sans-serif", 15).into_font();
    root.draw(&Text::new(
        map.value_label.clone(),
        (bx + 14, top - 40),
        style.clone(),
    ))
    .map_err(|e| e.to_string())?;
    for row in top..=bottom {
        let t = (bottom - row) as f64 / (bottom - top) as f64;
        root.draw(&PathElement::new(
            vec![(bx + 14, row), (bx + 44, row)],
            colour(v0 + t * (v1 - v0)).stroke_width(1),
        ))
        .map_err(|e| e.to_string())?;
    }
    for (t, v) in [(0.0, v0), (0.5, 0.5 * (v0 + v1)), (1.0, v1)] {
        let row = bottom - (t * (bottom - top) as f64) as i32;
        root.draw(&Text::new(
            lti::eig::sig(v),
            (bx + 52, row - 8),
            style.clone(),
        ))
        .map_err(|e| e.to_string())?;
    }
    let mut y = bottom + 24;
    if map.nominal.is_some() {
        root.draw(&Text::new("○ nominal", (bx + 14, y), style.clone()))
            .map_err(|e| e.to_string())?;
        y += 22;
    }
    if map.worst.is_some() {
        root.draw(&Text::new("✕ worst", (bx + 14, y), style.color(&RED)))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}
