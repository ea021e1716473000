//! Times and frequencies as an engineer writes them in a scenario: `"48 h"`, `"1 min"`,
//! `"250 ms"`, `"2 days"` for a time (in seconds), `"1/day"`, `"3/h"`, `"0.5 Hz"` for a frequency
//! (in Hz), beside plain numbers (seconds, Hz). A two-day building run reads `duration = "48 h"`,
//! `dt = "1 min"`, not 172800 and 60.
//!
//! The serde helpers in [`de`] accept either form for a field; the value kept is always the
//! number in seconds (Hz), so everything downstream — and the configurations the components
//! receive — is unchanged.
//!
//! A scenario-wide `time_unit = "h"` makes a bare number of a simulated time mean hours
//! ([`with_bare_unit`]): `dt = 1` is an hour's step. Frequencies named in Hz (`frequency_hz`)
//! and wall-clock limits ([`de::wall_seconds_opt`]) keep their own unit.

use std::cell::Cell;

/// A unit of time as an exact decimal number of seconds, factor · 10^exp10 (1 ms = 1·10⁻³ s,
/// 1 h = 3600 s), so that "18 ms" is the double nearest 0.018 — the sample time 18 · 0.001 s the
/// sample checks compare in decimal — not 18 × 0.001 in binary (0.018000000000000002).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Per {
    factor: u32,
    exp10: i32,
}

impl Per {
    const SECOND: Per = Per {
        factor: 1,
        exp10: 0,
    };

    /// Seconds per unit, as a double.
    fn seconds(self) -> f64 {
        self.factor as f64 * 10f64.powi(self.exp10)
    }

    /// `v` units in seconds: the decimal product of `v`'s shortest digits and the unit, rounded
    /// once to the nearest double.
    fn of(self, v: f64) -> f64 {
        if self == Per::SECOND || !v.is_finite() || v == 0.0 {
            return v;
        }
        // `{:e}` writes the shortest digits that read back as v: "1.8e1", "-2.5e-3".
        let text = format!("{v:e}");
        let (mantissa, exp) = text.split_once('e').expect("{:e} has an exponent");
        let exp: i32 = exp.parse().expect("{:e}'s exponent is an integer");
        let (sign, mantissa) = match mantissa.strip_prefix('-') {
            Some(m) => ("-", m),
            None => ("", mantissa),
        };
        let fraction = mantissa.split_once('.').map_or(0, |(_, f)| f.len()) as i32;
        let digits: u128 = mantissa.replace('.', "").parse().expect("digits");
        let product = digits * self.factor as u128;
        format!("{sign}{product}e{}", exp - fraction + self.exp10)
            .parse()
            .expect("a decimal reads as a double")
    }
}

thread_local! {
    /// The unit of a bare number of a simulated time while a scenario is read (s by default).
    static BARE: Cell<Per> = const { Cell::new(Per::SECOND) };
}

/// Runs `f` with a bare number of a simulated time meaning `unit` ("h", "min", …; [`seconds`]'s
/// units), on this thread; `None` keeps seconds. An unknown unit is the error, naming the units.
pub fn with_bare_unit<T>(unit_name: Option<&str>, f: impl FnOnce() -> T) -> Result<T, String> {
    let per = match unit_name {
        None => Per::SECOND,
        Some(u) => unit(u.trim())
            .ok_or_else(|| format!("'{u}' is not a time unit (give one of {UNITS}, e.g. \"h\")"))?,
    };
    struct Reset(Per);
    impl Drop for Reset {
        fn drop(&mut self) {
            BARE.with(|b| b.set(self.0));
        }
    }
    let _reset = Reset(BARE.with(|b| b.replace(per)));
    Ok(f())
}

/// A bare number of a simulated time in seconds, in the unit [`with_bare_unit`] set.
fn bare(v: f64) -> f64 {
    BARE.with(Cell::get).of(v)
}

/// The units a time may carry.
fn unit(u: &str) -> Option<Per> {
    let (factor, exp10) = match u {
        "ms" => (1, -3),
        "s" => (1, 0),
        "min" => (60, 0),
        "h" => (3600, 0),
        "day" | "days" => (86_400, 0),
        _ => return None,
    };
    Some(Per { factor, exp10 })
}

const UNITS: &str = "ms, s, min, h, day(s)";

/// The finite number `s` (trimmed), a part of `whole`: the error quotes both.
pub fn number(s: &str, whole: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{whole}': '{}' is not a number", s.trim()))?;
    if !v.is_finite() {
        return Err(format!("'{whole}': '{}' is not finite", s.trim()));
    }
    Ok(v)
}

/// A time in seconds from `"<number> <unit>"` (a bare number is seconds, or the unit
/// [`with_bare_unit`] set).
pub fn seconds(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')
        .or_else(|| t.rfind(' '));
    let Some(at) = split else {
        return Ok(bare(number(t, text)?));
    };
    let (n, u) = t.split_at(at);
    let per = unit(u.trim()).ok_or_else(|| {
        format!(
            "'{text}': '{}' is not a time unit (give one of {UNITS}, e.g. \"48 h\")",
            u.trim()
        )
    })?;
    Ok(per.of(number(n, text)?))
}

/// The unit a reader takes for a time of `seconds`, and its length in seconds: s up to 3 min,
/// min up to 3 h, h up to 3 days, then days (a plot's axis, a run's length, a time constant).
pub fn scale(seconds: f64) -> (&'static str, f64) {
    match seconds.abs() {
        t if t >= 3.0 * 86_400.0 => ("days", 86_400.0),
        t if t >= 3.0 * 3_600.0 => ("h", 3_600.0),
        t if t >= 180.0 => ("min", 60.0),
        _ => ("s", 1.0),
    }
}

/// Seconds in one `unit` ("h", "min", …, [`seconds`]'s units), or `None` for another word.
pub fn unit_seconds(unit_name: &str) -> Option<f64> {
    unit(unit_name.trim()).map(Per::seconds)
}

/// A time as a reader says it, in the unit [`scale`] picks (`"12 h"`, `"90 s"`, `"3.5 days"`),
/// to 4 significant digits.
pub fn readable(seconds: f64) -> String {
    let (unit, per) = scale(seconds);
    let v = seconds / per;
    if v == 0.0 || !v.is_finite() {
        return format!("{v} {unit}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.digits$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    };
    format!("{text} {unit}")
}

/// A frequency in Hz from `"<number> Hz"`, `"<number>/<unit>"` or `"1/<unit>"` (a bare number is Hz).
pub fn hertz(text: &str) -> Result<f64, String> {
    let t = text.trim();
    if let Some((n, u)) = t.split_once('/') {
        let per = unit(u.trim()).ok_or_else(|| {
            format!(
                "'{text}': '{}' is not a time unit (give one of {UNITS}, e.g. \"1/day\")",
                u.trim()
            )
        })?;
        return Ok(number(n, text)? / per.seconds());
    }
    match t.strip_suffix("Hz") {
        Some(n) => number(n, text),
        None => number(t, text).map_err(|_| {
            format!("'{text}' is not a frequency (a number of Hz, \"0.5 Hz\" or \"1/day\")")
        }),
    }
}

/// serde helpers: a number, or a string with a unit.
pub mod de {
    use serde::{Deserialize, Deserializer, de::Error};

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Written {
        Number(f64),
        Text(String),
    }

    fn value<'de, D: Deserializer<'de>>(
        d: D,
        parse: fn(&str) -> Result<f64, String>,
    ) -> Result<f64, D::Error> {
        match Written::deserialize(d)? {
            Written::Number(v) => Ok(v),
            Written::Text(t) => parse(&t).map_err(D::Error::custom),
        }
    }

    /// A simulated time: seconds (or the scenario's `time_unit`), or `"48 h"`.
    pub fn seconds<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match Written::deserialize(d)? {
            Written::Number(v) => Ok(super::bare(v)),
            Written::Text(t) => super::seconds(&t).map_err(D::Error::custom),
        }
    }

    /// An optional wall-clock time: seconds whatever the scenario's `time_unit`, or `"2 min"`.
    pub fn wall_seconds_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        #[derive(Deserialize)]
        struct Wrap(#[serde(deserialize_with = "wall")] f64);
        fn wall<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
            let seconds = |t: &str| super::with_bare_unit(None, || super::seconds(t))?;
            value(d, seconds)
        }
        Ok(Option::<Wrap>::deserialize(d)?.map(|w| w.0))
    }

    /// An optional time.
    pub fn seconds_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        #[derive(Deserialize)]
        struct Wrap(#[serde(deserialize_with = "seconds")] f64);
        Ok(Option::<Wrap>::deserialize(d)?.map(|w| w.0))
    }

    /// A list of times.
    pub fn seconds_vec<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        #[derive(Deserialize)]
        struct Wrap(#[serde(deserialize_with = "seconds")] f64);
        Ok(Vec::<Wrap>::deserialize(d)?
            .into_iter()
            .map(|w| w.0)
            .collect())
    }

    /// Optional lists of times (`[[on, off], …]`).
    pub fn seconds_pairs_opt<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Option<Vec<Vec<f64>>>, D::Error> {
        #[derive(Deserialize)]
        struct Wrap(#[serde(deserialize_with = "seconds_vec")] Vec<f64>);
        Ok(Option::<Vec<Wrap>>::deserialize(d)?.map(|v| v.into_iter().map(|w| w.0).collect()))
    }

    /// A frequency: Hz, or `"1/day"`, `"0.5 Hz"`.
    pub fn hertz<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        value(d, super::hertz)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A readable time reads back as the time it says, in the unit the run's length picks.
    #[test]
    fn a_readable_time_reads_back_as_itself() {
        for (t, want) in [
            (43_200.0, "12 h"),
            (90.0, "90 s"),
            (216_000.0, "60 h"),
            (302_400.0, "3.5 days"),
            (0.25, "0.25 s"),
            (600.0, "10 min"),
            (172_800.0, "48 h"),
            (0.0, "0 s"),
        ] {
            let text = readable(t);
            assert_eq!(text, want);
            assert!(
                (seconds(&text).unwrap() - t).abs() <= 1e-9 * t.abs(),
                "{text}"
            );
        }
    }

    /// Under a time unit a bare time is in it, a written unit stays itself, a frequency in Hz
    /// stays Hz, and the unit ends with the reading (also when it fails).
    #[test]
    fn a_bare_time_is_in_the_time_unit_while_it_is_set() {
        let read = with_bare_unit(Some("h"), || {
            (
                seconds("2").unwrap(),
                seconds("30 min").unwrap(),
                hertz("1").unwrap(),
            )
        })
        .unwrap();
        assert_eq!(read, (7200.0, 1800.0, 1.0));
        assert_eq!(seconds("2").unwrap(), 2.0);
        assert!(
            with_bare_unit(Some("fortnight"), || ())
                .unwrap_err()
                .contains("fortnight")
        );
        let _ = std::panic::catch_unwind(|| with_bare_unit(Some("min"), || panic!("inside")));
        assert_eq!(seconds("2").unwrap(), 2.0);
    }

    /// A time with a unit is the double nearest its exact decimal value in seconds (what the
    /// sample checks compare), not the binary product: "18 ms" is 0.018, not 0.018000000000000002.
    #[test]
    fn a_time_with_a_unit_is_its_exact_decimal_value() {
        for (text, want) in [
            ("18 ms", "0.018"),
            ("0.1 h", "360"),
            ("1.7 min", "102"),
            ("3e-2 ms", "3e-5"),
            ("-2.5 days", "-216000"),
            ("0.3 ms", "0.0003"),
        ] {
            assert_eq!(
                seconds(text).unwrap(),
                want.parse::<f64>().unwrap(),
                "{text}"
            );
        }
        assert_eq!(0.018_f64, "0.018".parse::<f64>().unwrap());
        assert_ne!(18.0 * 1e-3, 0.018, "the binary product this avoids");
    }

    #[test]
    fn times_and_frequencies_read_as_written() {
        for (text, want) in [
            ("48 h", 172_800.0),
            ("1 min", 60.0),
            ("250 ms", 0.25),
            ("2 days", 172_800.0),
            ("1 day", 86_400.0),
            ("1.5h", 5400.0),
            ("10", 10.0),
            ("1e3 s", 1000.0),
        ] {
            assert_eq!(seconds(text), Ok(want), "{text}");
        }
        assert_eq!(hertz("1/day"), Ok(1.0 / 86_400.0));
        assert_eq!(hertz("3/h"), Ok(3.0 / 3600.0));
        assert_eq!(hertz("0.5 Hz"), Ok(0.5));
        assert_eq!(hertz("2"), Ok(2.0));
        for bad in ["48 x", "h", "nan s", "1/week"] {
            let e = seconds(bad).and(hertz(bad)).unwrap_err();
            assert!(e.contains(bad), "{bad}: {e}");
        }
    }
}
