//! An MCAP log as plant samples. `[plant.replay] channel` names a JSON channel (or a list of
//! them, joined message by message: a `uio-launcher export --mcap` file holds x, y, u and w on
//! channels of their own); each message is a row, its fields mapped by name to u, y and
//! optionally w and x exactly as a CSV's header names are (`"/topic.field"` names a field of
//! one channel of the list; a bare name is looked up in the channels in order). The time is the
//! messages' log_time (ns, counted from the first message so that an epoch stamp keeps its
//! nanoseconds in an f64) or the field `time` names. samples.rs puts the rows on the grid with
//! the CSV's rules, so the same data replays to the same bits from either file.
//!
//! Messages are read in file order, so log times that go back are refused, not sorted. A
//! message that is not a JSON object, or lacks a mapped field, or holds a non-number there, is
//! refused naming the file, the row (the message's index in its channel, from 1) and the field;
//! JSON has no NaN or infinity, so `null` (what our export writes for them) and Python's bare
//! `NaN`, `Infinity` are read as non-finite values and refused (or held, `missing = "hold"`).

use std::collections::BTreeMap;

use ::mcap::MessageStream;
use serde_json::{Map, Value};

use scenario::suggest::did_you_mean;
use scenario::untrusted::{quoted, quoted_list};

use crate::Params;
use crate::samples::{self, Mapped, Naming};
use crate::table::Table;

/// One listed channel: its messages' log times and payloads, in file order.
struct Channel {
    topic: String,
    times: Vec<u64>,
    data: Vec<Vec<u8>>,
}

/// Reads the MCAP log the parameters name.
// one job: one MCAP log read end to end, its bounds checked where its bytes come.
pub fn load(p: &Params) -> Result<Table, String> {
    let file = p.file();
    let bytes = std::fs::read(&p.path).map_err(|e| format!("{file}: {e}"))?;
    let chans = messages(&file, &bytes, &p.channels)?;
    let rows = chans[0].times.len();
    for c in &chans[1..] {
        if c.times.len() != rows {
            return Err(format!(
                "{file}: channel {:?} has {} messages, {:?} has {rows}: the channels are joined message by message",
                c.topic,
                c.times.len(),
                chans[0].topic
            ));
        }
        if let Some(i) = (0..rows).find(|&i| c.times[i] != chans[0].times[i]) {
            return Err(format!(
                "{file}: row {}: log_time {} ns on {:?}, {} ns on {:?}: the channels' messages must pair up in time",
                i + 1,
                c.times[i],
                c.topic,
                chans[0].times[i],
                chans[0].topic
            ));
        }
    }

    // The mapped fields, in sample order: time (when a field), x, y, w, u; each (channel, key).
    let first: Vec<Map<String, Value>> = chans
        .iter()
        .map(|c| object(&c.data[0]).map_err(|why| format!("{file}: row 1 of {:?}: {why}", c.topic)))
        .collect::<Result<_, _>>()?;
    let multi = chans.len() > 1;
    let find = |key: &str, name: &str| -> Result<(usize, String), String> {
        for (ci, c) in chans.iter().enumerate() {
            if let Some(field) = name
                .strip_prefix(c.topic.as_str())
                .and_then(|f| f.strip_prefix('.'))
                && first[ci].contains_key(field)
            {
                return Ok((ci, field.to_string()));
            }
        }
        if let Some(ci) = first.iter().position(|m| m.contains_key(name)) {
            return Ok((ci, name.to_string()));
        }
        let known: Vec<String> = chans
            .iter()
            .flat_map(|c| {
                keys_in_order(&c.data[0])
                    .into_iter()
                    .map(move |k| if multi { format!("{}.{k}", c.topic) } else { k })
            })
            .collect();
        let topics: Vec<&str> = chans.iter().map(|c| c.topic.as_str()).collect();
        Err(format!(
            "{file}: no field {} ({key}) in the first message of {}{}; it has {}",
            quoted(name),
            quoted_list(topics.iter().copied()),
            did_you_mean(name, known.iter().map(String::as_str)),
            quoted_list(known.iter().map(String::as_str))
        ))
    };
    let group = |key: &str, list: &[String]| -> Result<Vec<(usize, String)>, String> {
        list.iter()
            .enumerate()
            .map(|(i, n)| find(&format!("plant.replay.{key}[{}]", i + 1), n))
            .collect()
    };
    let time = p
        .time
        .as_deref()
        .map(|t| find("plant.replay.time", t))
        .transpose()?;
    let states = p.states.is_some();
    let mut cols = Vec::new();
    cols.extend(time.clone());
    cols.extend(group("states", p.states.as_deref().unwrap_or_default())?);
    cols.extend(group("outputs", &p.outputs)?);
    cols.extend(group(
        "disturbances",
        p.disturbances.as_deref().unwrap_or_default(),
    )?);
    cols.extend(group("inputs", &p.inputs)?);
    // What messages call each column: the name as the scenario gives it.
    let shown: Vec<&str> = p
        .time
        .iter()
        .chain(p.states.iter().flatten())
        .chain(&p.outputs)
        .chain(p.disturbances.iter().flatten())
        .chain(&p.inputs)
        .map(String::as_str)
        .collect();

    // Without a time field, the log_time: seconds since the first message (a row's own time in
    // the time column's place, as a CSV's).
    let by_log_time = time.is_none();
    let mut m = Mapped::new(p, true, cols.len() + usize::from(by_log_time));
    let t0 = chans[0].times[0];
    let mut parsed: Vec<Map<String, Value>> = first;
    for i in 0..rows {
        if i > 0 {
            for (ci, c) in chans.iter().enumerate() {
                parsed[ci] = object(&c.data[i])
                    .map_err(|why| format!("{file}: row {} of {:?}: {why}", i + 1, c.topic))?;
            }
        }
        if by_log_time {
            let t = (i128::from(chans[0].times[i]) - i128::from(t0)) as f64 / 1e9;
            m.push(0, Ok(t), String::new)?;
        }
        for (j, (ci, key)) in cols.iter().enumerate() {
            let at = || format!("{file}: row {}, field {:?}", i + 1, shown[j]);
            m.push(
                j + usize::from(by_log_time),
                number(parsed[*ci].get(key)),
                at,
            )?;
        }
    }
    let row = |i: usize| format!("row {}", i + 1);
    let time_name = match &p.time {
        Some(t) => format!("field {t:?}"),
        None => "log_time (s after the first message)".to_string(),
    };
    samples::table(
        p,
        file,
        m,
        states,
        &Naming {
            row: &row,
            time: &time_name,
            rows: "messages",
        },
    )
}

/// Largest chunk a log may declare, uncompressed (64 MiB; our exporter's are under 1 MiB): a
/// chunk is decompressed whole, so a 1.7 KB file declaring 2^62 bytes must be refused before.
pub const MAX_CHUNK: u64 = 64 << 20;

/// Largest sum of the chunks' uncompressed sizes (1 GiB): the messages are held in memory.
pub const MAX_UNCOMPRESSED: u64 = 1 << 30;

/// Refuses a log whose chunks declare more than [`MAX_CHUNK`] each or [`MAX_UNCOMPRESSED`] in
/// all, from their headers alone (nothing is decompressed here; the reader then stops at each
/// declared size). A record the scan cannot read is left for the reader to report.
fn bounded(file: &str, bytes: &[u8]) -> Result<(), String> {
    let Ok(records) = ::mcap::read::LinearReader::new(bytes) else {
        return Ok(());
    };
    let mut total = 0u64;
    for (i, record) in records.enumerate() {
        let Ok(record) = record else { return Ok(()) };
        if let ::mcap::records::Record::Chunk { header, .. } = record {
            let size = header.uncompressed_size;
            if size > MAX_CHUNK {
                return Err(format!(
                    "{file}: chunk {} declares {size} bytes uncompressed, more than the {} MiB a chunk may hold here",
                    i + 1,
                    MAX_CHUNK >> 20
                ));
            }
            total = total.saturating_add(size);
            if total > MAX_UNCOMPRESSED {
                return Err(format!(
                    "{file}: its chunks declare more than {} GiB uncompressed in all, more than a replay holds in memory",
                    MAX_UNCOMPRESSED >> 30
                ));
            }
        }
    }
    Ok(())
}

/// The messages of the listed channels, in file order; refuses a file without one of them
/// (naming the channels it has), a channel not JSON-encoded, or one without messages.
fn messages(file: &str, bytes: &[u8], topics: &[String]) -> Result<Vec<Channel>, String> {
    let unreadable = |e: ::mcap::McapError| format!("{file}: not a readable MCAP file: {e}");
    let mut chans: Vec<Channel> = topics
        .iter()
        .map(|t| Channel {
            topic: t.clone(),
            times: Vec::new(),
            data: Vec::new(),
        })
        .collect();
    // Every channel the file declares (topic → encoding), for the messages below.
    let mut all: BTreeMap<String, String> = BTreeMap::new();
    bounded(file, bytes)?;
    if let Ok(Some(summary)) = ::mcap::Summary::read(bytes) {
        all.extend(
            summary
                .channels
                .values()
                .map(|c| (c.topic.clone(), c.message_encoding.clone())),
        );
    }
    let json = |topic: &str, encoding: &str| -> Result<(), String> {
        if encoding == "json" {
            Ok(())
        } else {
            Err(format!(
                "{file}: channel {topic:?} is encoded as {encoding:?}: only JSON channels (message encoding \"json\") replay"
            ))
        }
    };
    for t in topics {
        if let Some(enc) = all.get(t) {
            json(t, enc)?;
        }
    }
    for msg in MessageStream::new(bytes).map_err(unreadable)? {
        let msg = msg.map_err(unreadable)?;
        let topic = &msg.channel.topic;
        if !all.contains_key(topic) {
            all.insert(topic.clone(), msg.channel.message_encoding.clone());
        }
        if let Some(c) = chans.iter_mut().find(|c| &c.topic == topic) {
            json(topic, &msg.channel.message_encoding)?;
            c.times.push(msg.log_time);
            c.data.push(msg.data.into_owned());
        }
    }
    for c in &chans {
        if !all.contains_key(&c.topic) {
            let have = quoted_list(all.keys().map(String::as_str));
            return Err(format!(
                "{file}: no channel {} (plant.replay.channel){}; the file has {have}",
                quoted(&c.topic),
                did_you_mean(&c.topic, all.keys().map(String::as_str))
            ));
        }
        if c.times.is_empty() {
            return Err(format!("{file}: channel {:?} has no messages", c.topic));
        }
    }
    Ok(chans)
}

/// A message as a JSON object. Bare `NaN`, `Infinity` and `-Infinity` (Python's json writes
/// them) are not JSON: they are read as the strings [`NON_FINITE`] marks so that the field
/// they stand in is refused as a non-finite value rather than the whole message as not JSON.
fn object(data: &[u8]) -> Result<Map<String, Value>, String> {
    let value = match serde_json::from_slice::<Value>(data) {
        Ok(v) => v,
        Err(e) => match lenient(data) {
            Some(fixed) => {
                serde_json::from_slice::<Value>(&fixed).map_err(|_| format!("not JSON ({e})"))?
            }
            None => return Err(format!("not JSON ({e})")),
        },
    };
    match value {
        Value::Object(m) => Ok(m),
        other => Err(format!("a JSON {}, not an object", kind(&other))),
    }
}

/// The keys of a JSON object in the order the message writes them (a serde_json map sorts
/// them), for messages that list a message's fields as a CSV's header would.
fn keys_in_order(data: &[u8]) -> Vec<String> {
    struct Keys(Vec<String>);
    impl<'de> serde::Deserialize<'de> for Keys {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct Visit;
            impl<'de> serde::de::Visitor<'de> for Visit {
                type Value = Keys;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("a JSON object")
                }
                fn visit_map<A: serde::de::MapAccess<'de>>(
                    self,
                    mut m: A,
                ) -> Result<Keys, A::Error> {
                    let mut keys = Vec::new();
                    while let Some((k, _)) = m.next_entry::<String, serde::de::IgnoredAny>()? {
                        keys.push(k);
                    }
                    Ok(Keys(keys))
                }
            }
            d.deserialize_map(Visit)
        }
    }
    let fixed = lenient(data);
    serde_json::from_slice::<Keys>(fixed.as_deref().unwrap_or(data))
        .map_or_else(|_| Vec::new(), |k| k.0)
}

/// Marks a string that stood for a bare non-finite token.
const NON_FINITE: char = '\u{0}';

/// `data` with bare NaN / Infinity / -Infinity outside strings quoted behind [`NON_FINITE`],
/// or None when it has none.
fn lenient(data: &[u8]) -> Option<Vec<u8>> {
    let (mut out, mut in_string, mut escaped, mut changed, mut i) =
        (Vec::with_capacity(data.len() + 16), false, false, false, 0);
    while i < data.len() {
        let b = data[i];
        if in_string {
            (escaped, in_string) = (!escaped && b == b'\\', escaped || b != b'"');
        } else if b == b'"' {
            in_string = true;
        } else if let Some(token) = [&b"-Infinity"[..], b"Infinity", b"NaN"]
            .into_iter()
            .find(|t| data[i..].starts_with(t))
        {
            out.extend(b"\"\\u0000");
            out.extend(token);
            out.push(b'"');
            (i, changed) = (i + token.len(), true);
            continue;
        }
        out.push(b);
        i += 1;
    }
    changed.then_some(out)
}

/// A mapped field's value, or why it has none.
fn number(v: Option<&Value>) -> Result<f64, String> {
    match v {
        None => Err("not in the message".to_string()),
        Some(Value::Number(n)) => n
            .as_f64()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{n} is not finite")),
        Some(Value::Null) => {
            Err("null is not finite (JSON writes NaN and infinities as null)".to_string())
        }
        Some(Value::String(s)) if s.starts_with(NON_FINITE) => {
            Err(format!("{} is not finite", &s[1..]))
        }
        Some(other) => Err(format!("{other} is not a number")),
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(_) => "number",
        Value::String(_) => "string",
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bare_non_finite_tokens_are_fields_refused_and_strings_stay_strings() {
        let m = object(br#"{"a": NaN, "b": -Infinity, "c": "NaN \" Infinity", "d": 1.5}"#).unwrap();
        assert_eq!(number(m.get("a")), Err("NaN is not finite".to_string()));
        assert_eq!(
            number(m.get("b")),
            Err("-Infinity is not finite".to_string())
        );
        assert_eq!(m["c"], Value::String("NaN \" Infinity".into()));
        assert_eq!(number(m.get("d")), Ok(1.5));
        assert_eq!(number(m.get("e")), Err("not in the message".to_string()));
        assert_eq!(keys_in_order(br#"{"z": 1, "a": NaN}"#), ["z", "a"]);
        assert!(
            object(b"[1, 2]")
                .unwrap_err()
                .contains("a JSON array, not an object")
        );
    }
}
