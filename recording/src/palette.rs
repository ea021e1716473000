//! The colours of every picture of a run, shared by the Rerun blueprint and the PNG plots so an
//! observer has one colour everywhere: the true state is grey (visible on white paper and on
//! Rerun's dark background), each observer takes the next colour of a palette of saturated,
//! dark-enough hues (Okabe–Ito and Tableau, without their pale yellows).

/// An sRGB colour.
pub type Rgb = [u8; 3];

/// The true state (and any reference signal an estimate is drawn over).
pub const TRUE_STATE: Rgb = [140, 140, 140];

/// The channel a bank isolated, over time: black, no member's colour.
pub const ISOLATED: Rgb = [0, 0, 0];
/// Which test decided: dark grey, apart from the true state's grey and every member's colour.
pub const DECIDED_BY: Rgb = [85, 85, 85];

/// Observers in scenario order; other signal groups (inputs, outputs, latency hops) take the
/// same sequence by component.
const PALETTE: [Rgb; 8] = [
    [0, 114, 178],   // blue
    [213, 94, 0],    // vermilion
    [0, 158, 115],   // bluish green
    [148, 103, 189], // purple
    [204, 51, 119],  // crimson
    [140, 86, 75],   // brown
    [23, 160, 190],  // cyan, darkened
    [120, 120, 20],  // olive
];

/// The colour of the `i`-th observer of a scenario (or the `i`-th series of a signal group).
pub fn color(i: usize) -> Rgb {
    PALETTE[i % PALETTE.len()]
}

/// Component `i` of one observer's vector signal (its errors, its residuals): shades of the
/// observer's colour, darker and lighter in turn, so the view still reads as that observer.
pub fn shade(base: Rgb, i: usize) -> Rgb {
    // Negative mixes toward black, positive toward white.
    const T: [f64; 6] = [0.0, -0.5, 0.45, -0.25, 0.25, 0.55];
    let t = T[i % T.len()];
    base.map(|c| {
        let c = c as f64;
        (if t < 0.0 {
            c * (1.0 + t)
        } else {
            c + (255.0 - c) * t
        })
        .round() as u8
    })
}

/// How one series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// Its colour.
    pub color: Rgb,
    /// Width in points (Rerun) or pixels (PNG).
    pub width: f32,
}

/// Estimates and every other signal.
pub const THIN: f32 = 1.5;
/// How much wider each estimate is than the one drawn over it, so estimates that coincide
/// still all show (as nested bands).
const NEST: f32 = 0.8;
/// How much wider the true state is than the widest estimate over it in a PNG.
const TRUE_MARGIN: f32 = 1.5;

/// Width of an estimate drawn `over` other estimates, which lie on top of it.
fn nested(over: usize) -> f32 {
    THIN + NEST * over as f32
}

/// The width of the entity at `path` in the Rerun viewer of a run with `observers`. The viewer
/// draws a view's series in entity-path order, so `/plant/x/…` lands on top of `/observer/…`
/// whatever the blueprint says, and observers in name order: there the true state is the
/// thin line over the estimates, and the estimate drawn first the widest, which keeps every
/// line visible where they coincide (a PNG draws the other way round, see [`line`]).
pub fn viewer_width(path: &str, observers: &[String]) -> f32 {
    let parts: Vec<&str> = path.trim_start_matches('/').split('/').collect();
    match parts.as_slice() {
        ["observer", o, "xhat", _] => {
            let later = observers.iter().filter(|x| x.as_str() > *o).count();
            nested(later + 1)
        }
        _ => THIN,
    }
}

/// The line of the entity at `path` (see [`crate::signals`]) in a run whose observers are
/// `observers`, in scenario order: the colours both the recording and the PNG plots use, and
/// the PNG widths (a PNG draws the true state first, widest, then the estimates in scenario
/// order, each thinner than the one before).
pub fn line(path: &str, observers: &[String]) -> Line {
    let thin = |color| Line { color, width: THIN };
    let parts: Vec<&str> = path.trim_start_matches('/').split('/').collect();
    let k = parts
        .last()
        .and_then(|s| s.parse::<usize>().ok())
        .map_or(0, |k| k.saturating_sub(1));
    let observer = |name: &str| {
        color(
            observers
                .iter()
                .position(|o| o == name)
                .unwrap_or(observers.len()),
        )
    };
    match parts.as_slice() {
        ["plant", "x", _] => Line {
            color: TRUE_STATE,
            width: nested(observers.len().saturating_sub(1)) + TRUE_MARGIN,
        },
        ["observer", o, "xhat", _] => {
            let later = observers
                .iter()
                .position(|x| x == o)
                .map_or(0, |i| observers.len() - 1 - i);
            Line {
                color: observer(o),
                width: nested(later),
            }
        }
        ["plant", "y", _] | ["disturbance", _] | ["input", _] => thin(color(k)),
        // Beside w and r in their views, from the other end of the palette.
        ["measurement_disturbance", _] | ["controller", "u", _] => {
            thin(color(PALETTE.len() - 1 - k))
        }
        ["observer", o, "error" | "residual", _] => thin(shade(observer(o), k)),
        // ŵ_k beside w_k (which has the palette's k-th colour): the observer's colour, darkened.
        ["observer", o, "what", _] => thin(shade(observer(o), 1 + k)),
        ["observer", o, ..] => thin(observer(o)),
        // A bank's member i keeps the palette's i-th colour in every trace of it (its residual's
        // components in shades of it); the decisions are black and dark grey, no member's.
        ["diagnoser", _, "residual", i, _] => {
            let i = i.parse::<usize>().map_or(0, |i| i.saturating_sub(1));
            thin(shade(color(i), k))
        }
        [
            "diagnosis",
            _,
            "evaluation" | "threshold" | "alarm" | "glr" | "glr_threshold",
            _,
        ] => thin(color(k)),
        ["diagnosis", _, "isolated"] => thin(ISOLATED),
        ["diagnosis", _, "decided_by"] => thin(DECIDED_BY),
        ["latency", "step"] => thin(TRUE_STATE),
        ["latency", hop] => {
            // plant_to_observer_<o>, observer_<o>_to_controller, controller_to_plant.
            let to_observer = hop.strip_prefix("plant_to_observer_");
            let from_observer = hop
                .strip_prefix("observer_")
                .and_then(|h| h.strip_suffix("_to_controller"));
            match (to_observer, from_observer) {
                (Some(o), _) => thin(observer(o)),
                (_, Some(o)) => thin(shade(observer(o), 1)),
                _ => thin(color(PALETTE.len() - 1)),
            }
        }
        _ => thin(color(k)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Readable on white: no colour is pale (WCAG relative luminance well below white's).
    #[test]
    fn every_colour_contrasts_with_white() {
        let lin = |c: u8| {
            let c = c as f64 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        let lum = |c: Rgb| 0.2126 * lin(c[0]) + 0.7152 * lin(c[1]) + 0.0722 * lin(c[2]);
        for c in PALETTE.iter().copied().chain([TRUE_STATE]) {
            let contrast = 1.05 / (lum(c) + 0.05);
            assert!(contrast >= 2.5, "{c:?}: contrast {contrast:.2} with white");
        }
        // The lightest shade.
        for i in 0..PALETTE.len() {
            let c = shade(color(i), 5);
            assert!(1.05 / (lum(c) + 0.05) >= 1.5, "{c:?}");
        }
    }

    #[test]
    fn an_observer_keeps_its_colour_in_every_signal() {
        let obs = ["uio".to_string(), "luenberger".to_string()];
        let c = line("/observer/luenberger/xhat/2", &obs).color;
        assert_eq!(c, color(1));
        assert_eq!(
            line("/observer/luenberger/log10_max_abs_error", &obs).color,
            c
        );
        assert_eq!(line("/observer/luenberger/error/1", &obs).color, c);
        assert_ne!(
            line("/observer/luenberger/error/2", &obs).color,
            line("/observer/luenberger/error/3", &obs).color
        );
        assert_eq!(line("/latency/plant_to_observer_luenberger", &obs).color, c);
        assert_eq!(line("/plant/x/1", &obs).color, TRUE_STATE);
        assert_ne!(
            line("/input/1", &obs).color,
            line("/controller/u/1", &obs).color
        );
    }

    /// Four bank members are four colours in every trace of theirs, and the decisions are none
    /// of them.
    #[test]
    fn bank_members_and_decisions_have_colours_of_their_own() {
        let obs: [String; 0] = [];
        let members: Vec<Rgb> = (1..=4)
            .map(|i| line(&format!("/diagnosis/gos/evaluation/{i}"), &obs).color)
            .collect();
        for (a, ca) in members.iter().enumerate() {
            for cb in &members[a + 1..] {
                assert_ne!(ca, cb);
            }
            let i = a + 1;
            for what in ["threshold", "alarm", "glr", "glr_threshold"] {
                assert_eq!(line(&format!("/diagnosis/gos/{what}/{i}"), &obs).color, *ca);
            }
            // Its residual's first component in its own colour, not output 1's of member 1.
            assert_eq!(
                line(&format!("/diagnoser/gos/residual/{i}/1"), &obs).color,
                *ca
            );
            assert_ne!(
                line(&format!("/diagnoser/gos/residual/{i}/2"), &obs).color,
                *ca
            );
        }
        for decision in ["/diagnosis/gos/isolated", "/diagnosis/gos/decided_by"] {
            let c = line(decision, &obs).color;
            assert!(
                !PALETTE.contains(&c) && c != TRUE_STATE,
                "{decision}: {c:?}"
            );
        }
        assert_ne!(
            line("/diagnosis/gos/isolated", &obs).color,
            line("/diagnosis/gos/decided_by", &obs).color
        );
    }

    /// What is drawn first is wider than what is drawn over it: in a PNG the truth, then the
    /// observers in scenario order; in the viewer the observers in name order, then the truth.
    #[test]
    fn lines_drawn_first_are_wider() {
        let obs = [
            "uio".to_string(),
            "luenberger".to_string(),
            "dgo".to_string(),
        ];
        let png = |p: &str| line(p, &obs).width;
        assert!(png("/plant/x/1") > png("/observer/uio/xhat/1"));
        assert!(png("/observer/uio/xhat/1") > png("/observer/luenberger/xhat/1"));
        assert!(png("/observer/luenberger/xhat/1") > png("/observer/dgo/xhat/1"));
        let viewer = |p: &str| viewer_width(p, &obs);
        assert!(viewer("/observer/dgo/xhat/1") > viewer("/observer/luenberger/xhat/1"));
        assert!(viewer("/observer/luenberger/xhat/1") > viewer("/observer/uio/xhat/1"));
        assert!(viewer("/observer/uio/xhat/1") > viewer("/plant/x/1"));
    }
}
