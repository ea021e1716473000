//! A digest of every recorded signal, written at the end of a run (in the `.rrd` as the
//! recording property `digest`, and in `summary.json`) and checked by the reader, so that a
//! recording damaged after it was written is reported as damaged instead of read as data.
//!
//! Algorithm: per entity, XXH64 with seed 0 over the entity's rows in the order they were
//! written (step order), each row as three little-endian 8-byte words: the `step` (i64), the
//! `sim_time` in nanoseconds (i64; 0 where the recording has no such timeline) and the value's
//! `f64` bit pattern. The scenario text stored in the recording is digested as the key
//! `scenario` (its UTF-8 bytes). Digests are written as 16 lowercase hex digits. An entity with
//! rows that the digest does not list, or one it lists that has none, is damage too. Left out
//! is everything else: Rerun's row and chunk ids, each series' static `SeriesLines` (legend,
//! colour, width), the blueprint and the recording's other properties. Damage there changes no
//! signal's steps, times or values, but it can change a legend, a colour, the layout the viewer
//! shows or what a property says. XXH64 is no defence against a deliberate forgery, only
//! against damage.

use std::collections::BTreeMap;
use std::hash::Hasher as _;

use twox_hash::XxHash64;

/// What the digest says about a recording.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Integrity {
    /// Every signal matches the digest written with it.
    Verified,
    /// This entity (or part of the file) does not match.
    Damaged(String),
    /// No digest: the writer did not finish (or the file predates digests).
    #[default]
    Absent,
}

/// The key under which the scenario text is digested.
pub const SCENARIO_KEY: &str = "scenario";

/// A running digest of one entity.
#[derive(Clone)]
pub struct Running(XxHash64);

impl Default for Running {
    fn default() -> Self {
        Running(XxHash64::with_seed(0))
    }
}

impl Running {
    /// Adds rows, in the order written: steps, sim_time in ns (None: no such timeline), values.
    pub fn update(&mut self, steps: &[i64], times_ns: Option<&[i64]>, values: &[f64]) {
        self.update_rows(&mut Rows::new(steps, times_ns), values.iter().copied());
    }

    /// Adds one signal's values at the rows of `rows`, in order (as many values as rows).
    /// (Fewer values than rows: the rows they reach, as [`Self::update`].)
    pub fn update_rows(&mut self, rows: &mut Rows, values: impl Iterator<Item = f64>) {
        let mut n = 0;
        for (row, v) in rows.0.chunks_exact_mut(24).zip(values) {
            row[16..].copy_from_slice(&v.to_bits().to_le_bytes());
            n += 1;
        }
        self.0.write(&rows.0[..24 * n]);
    }

    /// 16 hex digits.
    pub fn hex(&self) -> String {
        format!("{:016x}", self.0.finish())
    }
}

/// The rows of a batch that several signals share (an entity's signals, or the entities of a
/// group): each row's `step` and `sim_time` words laid out once, so that each signal only
/// fills in its values before its digest takes the whole batch in one write
/// ([`Running::update_rows`]). XXH64's streaming state gives the same hash however the bytes
/// are cut, and a batch's one write runs at the hash's own speed.
pub struct Rows(Vec<u8>);

impl Rows {
    /// The rows at `steps`, with `times_ns` (None: no such timeline; 0 is digested).
    pub fn new(steps: &[i64], times_ns: Option<&[i64]>) -> Self {
        let mut buf = vec![0u8; 24 * steps.len()];
        for (i, (row, k)) in buf.chunks_exact_mut(24).zip(steps).enumerate() {
            let t = times_ns.and_then(|t| t.get(i)).copied().unwrap_or(0);
            row[..8].copy_from_slice(&k.to_le_bytes());
            row[8..16].copy_from_slice(&t.to_le_bytes());
        }
        Rows(buf)
    }
}

/// The digest of a text.
pub fn of_text(text: &str) -> String {
    format!("{:016x}", XxHash64::oneshot(0, text.as_bytes()))
}

/// The digest as stored: `{"algorithm": …, "entities": {entity: hex}}`.
pub fn to_json(entities: &BTreeMap<String, String>) -> String {
    serde_json::json!({ "algorithm": "xxh64 seed 0 over (i64 step, i64 sim_time ns, f64 bits) little-endian triples in step order", "entities": entities }).to_string()
}

/// Checks what was read — each entity's running digest over its rows in file order, and the
/// scenario text — against the stored digest text.
pub fn verify(read: &BTreeMap<String, Running>, scenario: Option<&str>, stored: &str) -> Integrity {
    let Some(expected) = serde_json::from_str::<serde_json::Value>(stored)
        .ok()
        .and_then(|v| {
            v.get("entities")?.as_object().map(|m| {
                m.iter()
                    .map(|(k, v)| (k.clone(), v.as_str().unwrap_or("").to_string()))
                    .collect::<BTreeMap<_, _>>()
            })
        })
    else {
        return Integrity::Damaged("its digest cannot be read".into());
    };
    for (entity, hex) in &expected {
        let actual = if entity == SCENARIO_KEY {
            scenario.map(of_text)
        } else {
            read.get(entity).map(Running::hex)
        };
        if actual.as_deref() != Some(hex.as_str()) {
            return Integrity::Damaged(named(entity));
        }
    }
    // Data the digest does not know of was not written by this run.
    match read.keys().find(|k| !expected.contains_key(*k)) {
        Some(extra) => Integrity::Damaged(named(extra)),
        None => Integrity::Verified,
    }
}

/// What [`Integrity::Damaged`] names: an entity path (from `/`) or [`SCENARIO_KEY`], which the
/// caller quotes; any other key, itself damaged, as a sentence with the key quoted, since it
/// comes from the file and may hold control characters.
fn named(key: &str) -> String {
    if key.starts_with('/') || key == SCENARIO_KEY {
        key.to_string()
    } else {
        format!(
            "its digest lists {}, which is no signal of a recording",
            scenario::untrusted::quoted(key)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_digest_does_not_depend_on_how_the_data_was_batched() {
        let steps: Vec<i64> = (0..1000).collect();
        let values: Vec<f64> = steps.iter().map(|&k| (k as f64).sin()).collect();
        let mut whole = Running::default();
        whole.update(&steps, Some(&steps), &values);
        let mut parts = Running::default();
        for (s, v) in steps.chunks(333).zip(values.chunks(333)) {
            parts.update(s, Some(s), v);
        }
        assert_eq!(whole.hex(), parts.hex());
        // The definition: XXH64 (seed 0) of the rows' little-endian words, in one piece.
        let bytes: Vec<u8> = steps
            .iter()
            .zip(&values)
            .flat_map(|(k, v)| {
                [k.to_le_bytes(), k.to_le_bytes(), v.to_bits().to_le_bytes()].concat()
            })
            .collect();
        assert_eq!(
            whole.hex(),
            format!("{:016x}", XxHash64::oneshot(0, &bytes))
        );
        // One bit of one value.
        let mut flipped = values.clone();
        flipped[500] = f64::from_bits(flipped[500].to_bits() ^ 1);
        let mut other = Running::default();
        other.update(&steps, Some(&steps), &flipped);
        assert_ne!(whole.hex(), other.hex());
        // One bit of one time stamp.
        let mut times = steps.clone();
        times[7] ^= 1 << 40;
        let mut other = Running::default();
        other.update(&steps, Some(&times), &values);
        assert_ne!(whole.hex(), other.hex());
        // XXH64 of the empty input with seed 0, the reference value.
        assert_eq!(Running::default().hex(), "ef46db3751d8e999");
        // Shared rows, refilled by a second signal, and a column shorter than its rows.
        let mut rows = Rows::new(&steps, Some(&steps));
        let (mut a, mut b, mut short) =
            (Running::default(), Running::default(), Running::default());
        a.update_rows(&mut rows, flipped.iter().copied());
        b.update_rows(&mut rows, values.iter().copied());
        short.update_rows(&mut rows, values[..10].iter().copied());
        let mut short_by_update = Running::default();
        short_by_update.update(&steps, Some(&steps), &values[..10]);
        assert_eq!(
            (a.hex(), b.hex(), short.hex()),
            (
                other_hex(&steps, &flipped),
                whole.hex(),
                short_by_update.hex()
            )
        );
    }

    fn other_hex(steps: &[i64], values: &[f64]) -> String {
        let mut d = Running::default();
        d.update(steps, Some(steps), values);
        d.hex()
    }
}
