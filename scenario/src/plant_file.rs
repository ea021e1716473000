//! What a plant read from a file (`[plant.fmu]`, `[plant.replay]`) shares: the design model's
//! sizes its map must match, and where its file is.

use std::path::{Path, PathBuf};

use super::quoted;
use crate::check::{Bad, bad};

/// Sizes of the design model a plant's map must match.
pub(crate) struct Sizes {
    pub n: usize,
    pub p: usize,
    pub l: usize,
    pub q: usize,
}

/// The file `written` at `field`: absolute, from the scenario's folder `dir`, and there; as
/// written when there is no folder (a recorded scenario names its files, they are not read).
pub(crate) fn path(field: &str, dir: Option<&Path>, written: &str) -> Result<PathBuf, Bad> {
    let Some(dir) = dir else {
        return Ok(PathBuf::from(written));
    };
    let path = dir.join(written);
    if !path.is_file() {
        // There, but not a regular file (a FIFO would block the reader): say what it is.
        let why = match std::fs::metadata(&path) {
            Ok(_) => crate::untrusted::open_regular(&path)
                .err()
                .unwrap_or_else(|| "not a regular file".into()),
            Err(_) => "no such file".into(),
        };
        return Err(bad(
            field,
            format!("{}: {why}", quoted(&path.display().to_string())),
        ));
    }
    std::fs::canonicalize(&path).map_err(|e| bad(field, format!("{}: {e}", path.display())))
}
