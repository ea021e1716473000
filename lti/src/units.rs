//! Times and frequencies as an engineer writes them in a scenario: `"48 h"`, `"1 min"`,
//! `"250 ms"`, `"2 days"` for a time (in seconds), `"1/day"`, `"3/h"`, `"0.5 Hz"` for a frequency
//! (in Hz), beside plain numbers (seconds, Hz). A two-day building run reads `duration = "48 h"`,
//! `dt = "1 min"`, not 172800 and 60.
//!
//! The serde helpers in [`de`] accept either form for a field; the value kept is always the
//! number in seconds (Hz), so everything downstream — and the configurations the components
//! receive — is unchanged.

/// Seconds per unit, for the units a time may carry.
fn unit(u: &str) -> Option<f64> {
    Some(match u {
        "ms" => 1e-3,
        "s" => 1.0,
        "min" => 60.0,
        "h" => 3600.0,
        "day" | "days" => 86_400.0,
        _ => return None,
    })
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

/// A time in seconds from `"<number> <unit>"` (a bare number is seconds).
pub fn seconds(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')
        .or_else(|| t.rfind(' '));
    let Some(at) = split else {
        return number(t, text);
    };
    let (n, u) = t.split_at(at);
    let per = unit(u.trim()).ok_or_else(|| {
        format!(
            "'{text}': '{}' is not a time unit (give one of {UNITS}, e.g. \"48 h\")",
            u.trim()
        )
    })?;
    Ok(number(n, text)? * per)
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
        return Ok(number(n, text)? / per);
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

    /// A time: seconds, or `"48 h"`.
    pub fn seconds<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        value(d, super::seconds)
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

    /// A frequency: Hz, or `"1/day"`, `"0.5 Hz"`.
    pub fn hertz<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        value(d, super::hertz)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
