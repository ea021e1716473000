//! The shipped scenarios: where they are, finding one by the name `uio-launcher list` prints, and
//! the list itself.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use scenario::{Scenario, quoted};

use crate::error::LaunchError;

/// The shipped scenarios: ./scenarios, else the repository's.
pub fn dir() -> PathBuf {
    let local = PathBuf::from("scenarios");
    if local.is_dir() {
        local
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios")
    }
}

/// The scenario `arg` names (a file or a shipped scenario's name, [`resolve`]), validated.
pub fn load(arg: &Path) -> Result<Scenario, LaunchError> {
    Ok(Scenario::load(&resolve(arg)?)?)
}

/// The scenario file `arg` names: `arg` itself when it exists or looks like a path (holds a
/// '/' or ends in `.toml`); otherwise the shipped scenario of that file stem or that name.
pub fn resolve(arg: &Path) -> Result<PathBuf, LaunchError> {
    let text = arg.to_string_lossy();
    if arg.symlink_metadata().is_ok()
        || text.contains('/')
        || text.ends_with(".toml")
        || text.is_empty()
    {
        return Ok(arg.to_path_buf());
    }
    let dir = dir();
    let by_stem = dir.join(format!("{text}.toml"));
    if by_stem.is_file() {
        return Ok(by_stem);
    }
    let entries = list(&dir).unwrap_or_default();
    if let Some(e) = entries.iter().find(|e| e.name.as_deref() == Some(&*text)) {
        return Ok(e.file.clone());
    }
    let hint =
        scenario::suggest::did_you_mean(&text, entries.iter().filter_map(|e| e.name.as_deref()));
    Err(LaunchError::BadInput(format!(
        "{}: no such file, nor a shipped scenario of that name in {} (see `uio-launcher list`){hint}",
        quoted(&text),
        dir.display()
    )))
}

/// One scenario file of a directory.
#[derive(Debug, Clone)]
pub struct Entry {
    /// The file.
    pub file: PathBuf,
    /// Its name, if it is valid.
    pub name: Option<String>,
    /// Its description, or why it is invalid.
    pub text: String,
    /// The other files of the directory with the same name.
    pub same_name: Vec<PathBuf>,
}

impl Entry {
    /// One line of `uio-launcher list`.
    pub fn line(&self) -> String {
        let Some(name) = &self.name else {
            return scenario::untrusted::one_line(&format!(
                "{:<34} (invalid: {})",
                self.file.display(),
                self.text
            ));
        };
        let mut line = format!("{name:<34} {}", self.text);
        if !self.same_name.is_empty() {
            let mut files: Vec<String> = std::iter::once(&self.file)
                .chain(&self.same_name)
                .map(|f| file_name(f))
                .collect();
            files.sort();
            line += &format!("  (duplicate name, in {})", files.join(" and "));
        }
        // A description may hold anything; a line of the list stays one line.
        scenario::untrusted::one_line(&line)
    }
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// Every `*.toml` of `dir`, sorted, each loaded and checked; names used twice are flagged
/// (a name picks the recording's file name, so two such scenarios overwrite each other).
pub fn list(dir: &Path) -> Result<Vec<Entry>, LaunchError> {
    let read = std::fs::read_dir(dir).map_err(|e| {
        LaunchError::BadInput(format!("{}: cannot list scenarios: {e}", dir.display()))
    })?;
    let mut files: Vec<PathBuf> = read
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut entries: Vec<Entry> = files
        .into_iter()
        .map(|file| match Scenario::load(&file) {
            Ok(s) => Entry {
                file,
                name: Some(s.name),
                text: s.description,
                same_name: Vec::new(),
            },
            Err(e) => Entry {
                file,
                name: None,
                text: e.to_string(),
                same_name: Vec::new(),
            },
        })
        .collect();
    let mut by_name: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for e in &entries {
        if let Some(n) = &e.name {
            by_name.entry(n.clone()).or_default().push(e.file.clone());
        }
    }
    for e in &mut entries {
        if let Some(n) = &e.name {
            e.same_name = by_name[n]
                .iter()
                .filter(|f| **f != e.file)
                .cloned()
                .collect();
        }
    }
    Ok(entries)
}
