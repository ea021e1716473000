//! "did you mean …": the closest known word to a misspelt key, kind or name, by edit distance
//! (Damerau–Levenshtein with adjacent transpositions, case-insensitive), when it is close enough
//! to be the intended one: at most a third of the longer word's letters (and at least one) apart.

/// `" (did you mean \"poles\"?)"`, or "" when no known word is close.
pub fn did_you_mean<'a>(word: &str, known: impl IntoIterator<Item = &'a str>) -> String {
    closest(word, known).map_or(String::new(), |k| {
        format!(" (did you mean {}?)", crate::untrusted::quoted(k))
    })
}

/// Words longer than this get no suggestion, and candidates longer than this are skipped: the
/// distance table is (|a| + 1)(|b| + 1) cells, and a hostile file's 20 MiB field name must not
/// cost gigabytes.
pub const MAX_WORD: usize = 64;

/// At most this many candidates are compared.
pub const MAX_CANDIDATES: usize = 1000;

/// The closest known word within the limit, ties to the first; none for a word longer than
/// [`MAX_WORD`] characters.
pub fn closest<'a>(word: &str, known: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    if word.chars().nth(MAX_WORD).is_some() {
        return None;
    }
    let w = word.to_lowercase();
    let mut best: Option<(usize, &str)> = None;
    for k in known.into_iter().take(MAX_CANDIDATES) {
        if k == word || k.chars().nth(MAX_WORD).is_some() {
            continue;
        }
        let d = distance(&w, &k.to_lowercase());
        let limit = (w.chars().count().max(k.chars().count()) / 3).max(1);
        if d <= limit && best.is_none_or(|(b, _)| d < b) {
            best = Some((d, k));
        }
    }
    best.map(|(_, k)| k)
}

/// Optimal string alignment distance between a and b (in chars).
fn distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, v) in d[0].iter_mut().enumerate() {
        *v = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            d[i][j] = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d[i][j] = d[i][j].min(d[i - 2][j - 2] + 1);
            }
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_words_are_suggested_and_far_ones_not() {
        assert_eq!(closest("pole", ["poles", "gain"]), Some("poles"));
        assert_eq!(
            closest("plaecment", ["placement", "poles"]),
            Some("placement")
        );
        assert_eq!(
            closest("luenburger", ["luenberger", "kalman"]),
            Some("luenberger")
        );
        assert_eq!(closest("Phi", ["A", "B", "Phi2"]), Some("Phi2"));
        assert_eq!(closest("zzz", ["poles", "gain"]), None);
        assert_eq!(did_you_mean("xyz", ["poles"]), "");
        // A word or candidate over MAX_WORD characters is not compared (no n² table).
        let long = "p".repeat(MAX_WORD + 1);
        assert_eq!(closest(&long, [long.as_str(), "poles"]), None);
        assert_eq!(closest("poles1", [long.as_str()]), None);
        assert_eq!(did_you_mean("gian", ["gain"]), " (did you mean 'gain'?)");
    }
}
