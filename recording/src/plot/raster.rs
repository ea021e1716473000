//! Anti-aliased lines of any width on an RGB buffer, clipped to a rectangle. plotters draws
//! wide lines as aliased polygons whose miter joins spike far past a sharp turn (a decimated
//! noisy series turns sharply at every column) and does not clip to the plot area; here each
//! pixel takes the coverage of its distance to the polyline, and nothing outside the rectangle
//! is touched.

use crate::palette::Rgb;

/// An RGB8 image, row-major.
pub struct Canvas<'a> {
    /// The pixels.
    pub buf: &'a mut [u8],
    /// Width in pixels.
    pub width: usize,
}

/// A pixel rectangle, inclusive bounds.
#[derive(Debug, Clone, Copy)]
pub struct Rect {
    /// Left column.
    pub x0: i32,
    /// Top row.
    pub y0: i32,
    /// Right column.
    pub x1: i32,
    /// Bottom row.
    pub y1: i32,
}

/// Draws the polyline through `points` (pixel coordinates; a non-finite point breaks the line)
/// with `width` pixels in `color`, touching only pixels inside `clip`. Overlapping segments of
/// one line do not darken each other: each pixel takes the line's largest coverage once.
pub fn polyline(canvas: &mut Canvas, clip: Rect, points: &[(f64, f64)], color: Rgb, width: f64) {
    let (w, h) = (
        (clip.x1 - clip.x0 + 1).max(0) as usize,
        (clip.y1 - clip.y0 + 1).max(0) as usize,
    );
    if w == 0 || h == 0 {
        return;
    }
    let r = width / 2.0;
    let mut coverage = vec![0f32; w * h];
    // Segments are first cut to the clip rectangle grown by the line's half width, so a far
    // outlier (1e300 pixels away) leaves finite, short segments.
    let grow = r + 2.0;
    let bounds = (
        clip.x0 as f64 - grow,
        clip.y0 as f64 - grow,
        clip.x1 as f64 + grow,
        clip.y1 as f64 + grow,
    );
    for pair in points.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if !(a.0.is_finite() && a.1.is_finite() && b.0.is_finite() && b.1.is_finite()) {
            continue;
        }
        let Some((a, b)) = cut(a, b, bounds) else {
            continue;
        };
        let (lx, hx) = (a.0.min(b.0) - r - 1.0, a.0.max(b.0) + r + 1.0);
        let (ly, hy) = (a.1.min(b.1) - r - 1.0, a.1.max(b.1) + r + 1.0);
        let (px0, px1) = (
            (lx.floor() as i32).max(clip.x0),
            (hx.ceil() as i32).min(clip.x1),
        );
        let (py0, py1) = (
            (ly.floor() as i32).max(clip.y0),
            (hy.ceil() as i32).min(clip.y1),
        );
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = dx * dx + dy * dy;
        for py in py0..=py1 {
            for px in px0..=px1 {
                let (qx, qy) = (px as f64 - a.0, py as f64 - a.1);
                let t = if len2 > 0.0 {
                    ((qx * dx + qy * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (qx - t * dx, qy - t * dy);
                let d = (ex * ex + ey * ey).sqrt();
                let c = (r + 0.5 - d).clamp(0.0, 1.0) as f32;
                if c > 0.0 {
                    let i = (py - clip.y0) as usize * w + (px - clip.x0) as usize;
                    coverage[i] = coverage[i].max(c);
                }
            }
        }
    }
    for (i, &c) in coverage.iter().enumerate() {
        if c > 0.0 {
            let (px, py) = (clip.x0 as usize + i % w, clip.y0 as usize + i / w);
            let o = 3 * (py * canvas.width + px);
            if o + 3 > canvas.buf.len() {
                continue;
            }
            for (px, &want) in canvas.buf[o..o + 3].iter_mut().zip(&color[..3]) {
                let under = *px as f32;
                *px = (under + (want as f32 - under) * c).round() as u8;
            }
        }
    }
}

/// The part of segment a–b inside `(x0, y0, x1, y1)` (Liang–Barsky), if any.
fn cut(
    a: (f64, f64),
    b: (f64, f64),
    (x0, y0, x1, y1): (f64, f64, f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1).then_some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_is_drawn_outside_the_clip_rectangle() {
        let mut buf = vec![255u8; 3 * 100 * 100];
        let clip = Rect {
            x0: 20,
            y0: 20,
            x1: 79,
            y1: 79,
        };
        // A spike far above the rectangle and a zigzag across it.
        let points = [
            (0.0, 50.0),
            (50.0, -1e300),
            (60.0, 50.0),
            (61.0, 99.0),
            (62.0, 10.0),
            (99.0, 50.0),
        ];
        polyline(
            &mut Canvas {
                buf: &mut buf,
                width: 100,
            },
            clip,
            &points,
            [200, 0, 0],
            3.0,
        );
        let mut inside = 0;
        for y in 0..100 {
            for x in 0..100 {
                let px = &buf[3 * (y * 100 + x)..3 * (y * 100 + x) + 3];
                let drawn = px != [255, 255, 255];
                let within = (20..=79).contains(&x) && (20..=79).contains(&y);
                assert!(!drawn || within, "pixel ({x}, {y}) drawn outside");
                inside += drawn as usize;
            }
        }
        assert!(inside > 200, "{inside}");
    }

    #[test]
    fn edges_are_blended() {
        let mut buf = vec![255u8; 3 * 40 * 40];
        polyline(
            &mut Canvas {
                buf: &mut buf,
                width: 40,
            },
            Rect {
                x0: 0,
                y0: 0,
                x1: 39,
                y1: 39,
            },
            &[(2.0, 3.0), (37.0, 30.0)],
            [0, 0, 0],
            2.0,
        );
        let partial = buf.chunks(3).filter(|p| p[0] > 0 && p[0] < 255).count();
        assert!(partial > 20, "{partial} partly covered pixels");
    }
}
