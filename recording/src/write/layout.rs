//! Where each signal lives in a recording of layout 2: its entity and its instance there.
//!
//! A signal keeps its path (`/plant/x/1`) as its name in every reader; in the file it is
//! element `i` of the values of its entity (`/plant`, see [`crate::signals::entity_of`]),
//! one row of which holds all of that entity's signals at one step. The blueprint needs the
//! element to plot one signal of an entity on its own.

use std::collections::BTreeMap;

use crate::palette::Rgb;

/// The recording layout this writer writes, stored as the recording's property `layout`.
/// Layout 1 (no property) stored every signal as an entity of its own.
pub const LAYOUT: u32 = 2;

/// The component holding a row's values: one instance per row, a list of one double per signal.
pub const VALUES_COMPONENT: &str = "uio:values";

/// The static component naming the signal behind each element of an entity's values.
pub const SERIES_COMPONENT: &str = "uio:series";

/// How a signal's line is drawn: legend, colour, width in points.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// The legend.
    pub legend: String,
    /// Its colour.
    pub color: Rgb,
    /// Its width.
    pub width: f32,
}

/// Signal path → (entity path, instance, line).
#[derive(Debug, Clone, Default)]
pub struct Layout {
    at: BTreeMap<String, (String, usize, Line)>,
    sizes: BTreeMap<String, usize>,
}

impl Layout {
    /// Adds an entity holding `signals` as its instances 0, 1, ….
    pub fn entity(&mut self, entity: &str, signals: impl IntoIterator<Item = (String, Line)>) {
        let mut n = 0;
        for (i, (s, line)) in signals.into_iter().enumerate() {
            self.at.insert(s, (entity.to_string(), i, line));
            n = i + 1;
        }
        self.sizes.insert(entity.to_string(), n);
    }

    /// The entity and instance of signal `path`, if it is recorded.
    pub fn at(&self, path: &str) -> Option<(&str, usize, &Line)> {
        self.at.get(path).map(|(e, i, l)| (e.as_str(), *i, l))
    }

    /// How many instances `entity` has.
    pub fn size(&self, entity: &str) -> usize {
        self.sizes.get(entity).copied().unwrap_or(0)
    }

    /// Every recorded signal's path, in order.
    pub fn signals(&self) -> impl Iterator<Item = &str> {
        self.at.keys().map(String::as_str)
    }
}
