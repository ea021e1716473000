//! Every TOML example in the README and in docs/ parses — uncommented, as a user would copy
//! it — and a complete scenario among them validates as one.

use std::path::Path;

use tests::repo;

/// The ```toml blocks of the README, with their first line number.
fn toml_blocks(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        match (&mut current, line.trim_start()) {
            (None, l) if l.starts_with("```toml") => current = Some((i + 2, String::new())),
            (Some(_), l) if l.starts_with("```") => out.push(current.take().unwrap()),
            (Some((_, body)), _) => {
                body.push_str(line);
                body.push('\n');
            }
            _ => {}
        }
    }
    out
}

/// A line's commented-out setting, uncommented: "# key = value   # note" → "key = value".
fn uncomment(line: &str) -> Option<String> {
    let rest = line.trim_start().strip_prefix('#')?.trim_start();
    let looks_like_toml = rest.starts_with('[')
        || rest
            .split_once('=')
            .is_some_and(|(k, _)| !k.trim().is_empty() && !k.contains(' '));
    looks_like_toml.then(|| rest.to_string())
}

#[test]
fn every_toml_example_parses_and_scenarios_validate() {
    let mut pages = vec![repo().join("README.md")];
    let mut docs: Vec<_> = std::fs::read_dir(repo().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    let mut count = 0;
    for page in &pages {
        let name = page.strip_prefix(repo()).unwrap().display().to_string();
        let text = std::fs::read_to_string(page).unwrap();
        let blocks = toml_blocks(&text);
        count += blocks.len();
        check(&name, &blocks);
    }
    assert!(count > 0, "the README and docs/ have no TOML example");
}

/// Each block parses as TOML, a block with `[plant]` validates as a scenario, and each of its
/// commented settings, uncommented on its own, is TOML too.
fn check(page: &str, blocks: &[(usize, String)]) {
    for (line, body) in blocks {
        toml::from_str::<toml::Table>(body).unwrap_or_else(|e| panic!("{page}:{line}: {e}"));
        if body.contains("[plant]") {
            scenario::Scenario::parse(Path::new(page), body)
                .unwrap_or_else(|e| panic!("{page}:{line}: {e}"));
        }
        // Each commented setting, uncommented on its own, is valid TOML too.
        for (j, l) in body.lines().enumerate() {
            if let Some(setting) = uncomment(l) {
                if setting.starts_with('[') {
                    continue;
                }
                toml::from_str::<toml::Table>(&setting).unwrap_or_else(|e| {
                    panic!(
                        "{page}:{}: commented example `{setting}` is not TOML: {e}",
                        line + j
                    )
                });
            }
        }
    }
}
