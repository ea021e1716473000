//! Where a field sits in the scenario file, as line:column, found through toml's spanned parse.

use toml::de::{DeTable, DeValue};

/// One step of a field path: a key or an array index.
#[derive(Debug, Clone, PartialEq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// Parses "plant.A[1]" or "observer[0].poles" into segments.
pub fn parse_path(path: &str) -> Vec<Seg> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let mut rest = part;
        if let Some(i) = rest.find('[') {
            if i > 0 {
                out.push(Seg::Key(rest[..i].to_string()));
            }
            rest = &rest[i..];
            while let Some(end) = rest.find(']') {
                if let Ok(k) = rest[1..end].parse() {
                    out.push(Seg::Index(k));
                }
                rest = &rest[end + 1..];
            }
        } else if !rest.is_empty() && rest != "?" {
            out.push(Seg::Key(rest.to_string()));
        }
    }
    out
}

/// The byte offset where the value at `path` starts, or the deepest ancestor found.
pub fn offset(text: &str, path: &[Seg]) -> Option<usize> {
    let root = DeTable::parse(text).ok()?;
    let mut best = None;
    let mut table = Some(root.get_ref());
    let mut value: Option<&DeValue> = None;
    for seg in path {
        let next = match seg {
            Seg::Key(k) => table.and_then(|t| t.iter().find(|(key, _)| key.get_ref() == k)).map(|(key, v)| {
                best = Some(key.span().start);
                v
            }),
            Seg::Index(i) => value.and_then(|v| v.as_array()).and_then(|a| a.get(*i)),
        };
        let Some(v) = next else { break };
        best = Some(v.span().start);
        value = Some(v.get_ref());
        table = v.get_ref().as_table();
    }
    best
}

/// 1-based line and column of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map_or(before.len(), |p| before.len() - p - 1) + 1;
    (line, col)
}
