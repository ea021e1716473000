//! Where a field sits in the scenario file, as line:column, found through toml's spanned parse.

use toml::de::{DeTable, DeValue};

/// One step of a field path: a key or an array index.
#[derive(Debug, Clone, PartialEq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// Parses "plant.A[2]" or "observer[1].poles" into segments. Field paths in messages number
/// array entries from 1, like every other numbering the user sees (`observer[1]` is the first
/// `[[observer]]`); segments index from 0.
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
                if let Ok(k) = rest[1..end].parse::<usize>()
                    && k >= 1
                {
                    out.push(Seg::Index(k - 1));
                }
                rest = &rest[end + 1..];
            }
        } else if !rest.is_empty() && rest != "?" {
            out.push(Seg::Key(rest.to_string()));
        }
    }
    out
}

/// A serde field path ("observer[0].colour", indices from 0) as messages write it, from 1.
pub fn one_based(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    let mut rest = path;
    while let Some(open) = rest.find('[') {
        out.push_str(&rest[..=open]);
        rest = &rest[open + 1..];
        let close = rest.find(']').unwrap_or(rest.len());
        match rest[..close].parse::<usize>() {
            Ok(k) => out.push_str(&(k + 1).to_string()),
            Err(_) => out.push_str(&rest[..close]),
        }
        rest = &rest[close..];
    }
    out.push_str(rest);
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
            Seg::Key(k) => table
                .and_then(|t| t.iter().find(|(key, _)| key.get_ref() == k))
                .map(|(key, v)| {
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
    let col = before
        .rfind('\n')
        .map_or(before.len(), |p| before.len() - p - 1)
        + 1;
    (line, col)
}
