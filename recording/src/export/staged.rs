//! Writing a file under a temporary name beside its target and renaming it into place once
//! complete: an export that fails half-way (disk full, a bad path, a panic) leaves no partial
//! file under the target's name, and a reader never sees one.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file being written at a temporary path; removed unless [`Staged::commit`] renames it.
pub struct Staged {
    tmp: PathBuf,
    target: PathBuf,
    done: bool,
}

impl Staged {
    /// Creates `.<name>.partial-<pid>` beside `target`.
    pub fn create(target: &Path) -> Result<(Self, BufWriter<File>), String> {
        let name = target.file_name().ok_or_else(|| format!("{}: cannot write: not a file name", target.display()))?;
        let tmp = target.with_file_name(format!(".{}.partial-{}", name.to_string_lossy(), std::process::id()));
        let file = OpenOptions::new().write(true).create_new(true).open(&tmp).map_err(|e| cannot_write(target, &e))?;
        Ok((Self { tmp, target: target.to_path_buf(), done: false }, BufWriter::new(file)))
    }

    /// Flushes `w` to disk and renames the file to its target.
    pub fn commit(mut self, w: BufWriter<File>) -> Result<(), String> {
        let file = w.into_inner().map_err(|e| cannot_write(&self.target, e.error()))?;
        file.sync_all().map_err(|e| cannot_write(&self.target, &e))?;
        std::fs::rename(&self.tmp, &self.target).map_err(|e| cannot_write(&self.target, &e))?;
        self.done = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// The one-line error of a file that cannot be written.
pub fn cannot_write(path: &Path, e: &dyn std::fmt::Display) -> String {
    format!("{}: cannot write: {e}", path.display())
}

/// Writes `target` through `body`, staged.
pub fn write(target: &Path, body: impl FnOnce(&mut BufWriter<File>) -> Result<(), String>) -> Result<(), String> {
    let (staged, mut w) = Staged::create(target)?;
    body(&mut w)?;
    w.flush().map_err(|e| cannot_write(target, &e))?;
    staged.commit(w)
}
