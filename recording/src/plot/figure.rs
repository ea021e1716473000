//! One PNG: plotters draws the frame, grid, ticks, title and legend text into a buffer; the
//! curves are drawn by [`super::raster`] (anti-aliased, clipped to the plot area); the legend
//! sits in its own column right of the plot so it never covers data.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::raster::{Canvas, Rect, polyline};
use crate::palette::Line;

/// Image size, pixels.
pub const SIZE: (u32, u32) = (1400, 700);
/// Width of the legend column.
const LEGEND_W: u32 = 290;
/// At most this many tick labels per axis.
const X_LABELS: usize = 10;
const Y_LABELS: usize = 8;

/// How the y values are read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scale {
    /// As they are.
    Linear,
    /// The points hold log10 of the value; ticks are labelled with the value.
    Log,
}

/// One series, in plot coordinates (y already log10 for [`Scale::Log`]).
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// Colour and width.
    pub line: Line,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
    /// Drawn dashed (a threshold beside the series it bounds, in that series' colour).
    pub dashed: bool,
}

/// Dash and gap lengths of a dashed curve, pixels.
const DASH: (f64, f64) = (12.0, 7.0);

/// The pieces of a polyline (in pixels) that a dash pattern draws.
fn dashes(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut on = true;
    let mut left = DASH.0;
    let mut piece: Vec<(f64, f64)> = points.first().map_or_else(Vec::new, |&p| vec![p]);
    for pair in points.windows(2) {
        let (mut a, b) = (pair[0], pair[1]);
        let mut len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        if !len.is_finite() {
            continue;
        }
        while len > left {
            let t = left / len;
            let cut = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
            if on {
                piece.push(cut);
                out.push(std::mem::take(&mut piece));
            } else {
                piece = vec![cut];
            }
            on = !on;
            len -= left;
            left = if on { DASH.0 } else { DASH.1 };
            a = cut;
        }
        left -= len;
        if on {
            piece.push(b);
        }
    }
    if on && piece.len() > 1 {
        out.push(piece);
    }
    out
}

/// What one PNG shows.
pub struct Figure {
    /// Caption.
    pub title: String,
    /// y axis description.
    pub y_label: String,
    /// x axis description.
    pub x_label: String,
    /// y scale.
    pub scale: Scale,
    /// x scale (the points' x already log10 for [`Scale::Log`]).
    pub x_scale: Scale,
    /// Curves, drawn in order (the first underneath).
    pub curves: Vec<Curve>,
}

/// The step between the ticks plotters puts on `lo..hi` when asked for at most `n` labels.
fn tick_step(lo: f64, hi: f64, n: usize) -> f64 {
    let points = RangedCoordf64::from(lo..hi).key_points(n);
    match points.as_slice() {
        [a, b, ..] => b - a,
        _ => (hi - lo).abs().max(f64::MIN_POSITIVE),
    }
}

/// A linear tick label with the digits its step needs: "0.25", "-3", "2.5e-15".
fn linear_label(v: f64, step: f64, max_abs: f64) -> String {
    if v.abs() < step * 1e-6 {
        return "0".into();
    }
    let step_exp = step.log10().floor() as i32;
    let exp = max_abs.log10().floor() as i32;
    if !(-3..6).contains(&exp) {
        // Scientific with the mantissa digits the step resolves at this value's magnitude.
        let own = v.abs().log10().floor() as i32;
        format!("{:.*e}", (own - step_exp).clamp(0, 6) as usize, v)
    } else {
        format!("{:.*}", (-step_exp).max(0) as usize, v)
    }
}

/// A log-axis tick label: the value 10^v, plain near 1, else as a power of ten.
fn log_label(v: f64, step: f64) -> String {
    let value = 10f64.powf(v);
    if step >= 1.0 && (v - v.round()).abs() < 1e-9 {
        let e = v.round() as i32;
        if (-3..=4).contains(&e) {
            format!("{}", 10f64.powi(e))
        } else {
            format!("1e{e}")
        }
    } else {
        format!("{value:.2e}").replace("e0", "")
    }
}

fn range(curves: &[Curve], axis: impl Fn(&(f64, f64)) -> f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in curves
        .iter()
        .flat_map(|c| c.points.iter().map(&axis))
        .filter(|v| v.is_finite())
    {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    lo.is_finite().then_some((lo, hi))
}

/// Draws `fig` into the PNG `path`; false when it has no finite point (nothing written).
pub fn draw(path: &Path, fig: &Figure) -> Result<bool, String> {
    let Some((x0, mut x1)) = range(&fig.curves, |p| p.0) else {
        return Ok(false);
    };
    let Some((lo, hi)) = range(&fig.curves, |p| p.1) else {
        return Ok(false);
    };
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    // The y range holds every point with a 5 % margin; a flat series gets a band around it.
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else if fig.scale == Scale::Log {
        0.5
    } else {
        lo.abs().max(f64::MIN_POSITIVE) * 0.5
    };
    let (y0, y1) = if hi > lo || lo != 0.0 || fig.scale == Scale::Log {
        (lo - pad, hi + pad)
    } else {
        (-1.0, 1.0)
    };
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let mut buf = vec![255u8; 3 * w * h];
    let (plot, legend) = frame(&mut buf, fig, (x0, x1, y0, y1))?;
    let mut canvas = Canvas {
        buf: &mut buf,
        width: w,
    };
    let map = |(x, y): (f64, f64)| {
        let px = plot.x0 as f64 + (x - x0) / (x1 - x0) * (plot.x1 - plot.x0) as f64;
        let py = plot.y1 as f64 - (y - y0) / (y1 - y0) * (plot.y1 - plot.y0) as f64;
        (px, py)
    };
    // Inside the frame line, so a curve at the edge does not paint over it.
    let inner = Rect {
        x0: plot.x0 + 1,
        y0: plot.y0 + 1,
        x1: plot.x1 - 1,
        y1: plot.y1 - 1,
    };
    for c in &fig.curves {
        let pts: Vec<(f64, f64)> = c.points.iter().map(|&p| map(p)).collect();
        if c.dashed {
            for piece in dashes(&pts) {
                polyline(
                    &mut canvas,
                    inner,
                    &piece,
                    c.line.color,
                    c.line.width as f64,
                );
            }
        } else {
            polyline(&mut canvas, inner, &pts, c.line.color, c.line.width as f64);
        }
    }
    let legend_clip = Rect {
        x0: SIZE.0 as i32 - LEGEND_W as i32,
        y0: 0,
        x1: SIZE.0 as i32 - 1,
        y1: SIZE.1 as i32 - 1,
    };
    for (c, (x, y)) in fig.curves.iter().zip(legend) {
        let (x, y) = (x as f64, y as f64);
        let sample = if c.dashed {
            vec![
                vec![(x, y), (x + 11.0, y)],
                vec![(x + 19.0, y), (x + 30.0, y)],
            ]
        } else {
            vec![vec![(x, y), (x + 30.0, y)]]
        };
        for piece in sample {
            polyline(
                &mut canvas,
                legend_clip,
                &piece,
                c.line.color,
                c.line.width as f64 + 0.5,
            );
        }
    }
    write_png(path, &buf)?;
    Ok(true)
}

/// An RGB buffer of [`SIZE`] as the PNG `path`: encoded here and written staged (`outputs`), as
/// plotters' file backend would create the path itself, through any link planted there.
pub(super) fn write_png(path: &Path, buf: &[u8]) -> Result<(), String> {
    outputs::write(path, |w| {
        use image::ImageEncoder;
        image::codecs::png::PngEncoder::new(w)
            .write_image(buf, SIZE.0, SIZE.1, image::ColorType::Rgb8)
            .map_err(|e| e.to_string())
    })
}

/// Title, grid, ticks, frame and legend text; returns the plot rectangle and where each
/// legend sample line starts.
fn frame(
    buf: &mut [u8],
    fig: &Figure,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> Result<(Rect, Vec<(i32, i32)>), String> {
    let root = BitMapBackend::with_buffer(buf, SIZE).into_drawing_area();
    let (left, right) = root.split_horizontally(SIZE.0 - LEGEND_W);
    let (xstep, ystep) = (tick_step(x0, x1, X_LABELS), tick_step(y0, y1, Y_LABELS));
    let max_abs = y0.abs().max(y1.abs());
    let x_max = x0.abs().max(x1.abs());
    let mut chart = ChartBuilder::on(&left)
        .caption(&fig.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(52)
        .y_label_area_size(96)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    let ylab = |v: &f64| match fig.scale {
        Scale::Linear => linear_label(*v, ystep, max_abs),
        Scale::Log => log_label(*v, ystep),
    };
    chart
        .configure_mesh()
        .x_desc(&fig.x_label)
        .y_desc(&fig.y_label)
        .x_labels(X_LABELS)
        .y_labels(Y_LABELS)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 16))
        .bold_line_style(RGBColor(222, 222, 222))
        .light_line_style(RGBColor(245, 245, 245))
        .axis_style(BLACK)
        .x_label_formatter(&|v| match fig.x_scale {
            Scale::Linear => linear_label(*v, xstep, x_max),
            Scale::Log => log_label(*v, xstep),
        })
        .y_label_formatter(&ylab)
        .draw()
        .map_err(|e| e.to_string())?;
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let plot = Rect {
        x0: xr.start,
        y0: yr.start,
        x1: xr.end - 1,
        y1: yr.end - 1,
    };
    root.draw(&Rectangle::new(
        [(plot.x0, plot.y0), (plot.x1, plot.y1)],
        BLACK.stroke_width(1),
    ))
    .map_err(|e| e.to_string())?;
    let mut samples = Vec::new();
    let (lx, _) = right.get_pixel_range();
    let mut y = plot.y0 + 12;
    for c in &fig.curves {
        // `right` has its own origin at its top-left corner; the samples are in image pixels.
        right
            .draw(&Text::new(
                c.label.clone(),
                (46, y - 9),
                ("sans-serif", 15).into_font().color(&BLACK),
            ))
            .map_err(|e| e.to_string())?;
        samples.push((lx.start + 8, y));
        y += 24;
    }
    root.present().map_err(|e| e.to_string())?;
    Ok((plot, samples))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dash pattern along a straight line: pieces of 12 px every 19 px, the last one cut.
    #[test]
    fn a_dashed_line_is_cut_into_dashes() {
        let pieces = dashes(&[(0.0, 0.0), (20.0, 0.0), (50.0, 0.0)]);
        let spans: Vec<(f64, f64)> = pieces.iter().map(|p| (p[0].0, p[p.len() - 1].0)).collect();
        assert_eq!(spans, [(0.0, 12.0), (19.0, 31.0), (38.0, 50.0)]);
    }

    /// Rounding-level errors get readable ticks, not 0.000000000000002 or a row of zeros.
    #[test]
    fn tick_labels_carry_the_digits_their_step_needs() {
        assert_eq!(linear_label(2.5e-15, 5e-16, 1.2e-14), "2.5e-15");
        assert_eq!(linear_label(-1e-11, 5e-12, 1.2e-11), "-1.0e-11");
        assert_eq!(linear_label(1e-22, 5e-16, 1.2e-14), "0");
        assert_eq!(linear_label(0.25, 0.05, 2.0), "0.25");
        assert_eq!(linear_label(150000.0, 50000.0, 3e5), "150000");
        assert_eq!(log_label(-15.0, 5.0), "1e-15");
        assert_eq!(log_label(2.0, 1.0), "100");
        assert_eq!(log_label(0.5, 0.1), "3.16");
    }
}
