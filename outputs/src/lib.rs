//! Every file the tool writes goes through here, so that no output can be turned into a write
//! somewhere else:
//!
//! * a file is created only as a **new** regular file, `O_CREAT | O_EXCL | O_NOFOLLOW`: a
//!   symlink, FIFO, device or any file planted at its name makes the open fail, so nothing is
//!   truncated, followed or blocked on;
//! * a finished output is written under an **unpredictable** temporary name beside its target
//!   (`.<name>.<64 random bits>.partial`) and renamed into place, which replaces a link planted
//!   at the target rather than writing through it, and leaves no half-written file under the
//!   target's name when writing fails half-way (a full disk, a panic).
//!
//! Invariant: no writer in the workspace opens an output with `File::create`, `fs::write` or an
//! `OpenOptions` without [`create_new`]'s flags.

use std::collections::hash_map::RandomState;
use std::fs::{File, OpenOptions};
use std::hash::{BuildHasher, Hasher};
use std::io::{BufWriter, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

/// Opens `path` as a new regular file for writing: fails if anything exists there, a symlink
/// included (dangling or not), and never follows one. Mode 0666 less the umask.
pub fn create_new(path: &Path) -> std::io::Result<File> {
    OpenOptions::new()
        .write(true)
        .create_new(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_CLOEXEC)
        .open(path)
}

/// 64 bits no other user can predict (std's per-process random hash keys, mixed with the time
/// and a counter so that two names of one process differ).
fn random() -> u64 {
    static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let mut h = RandomState::new().build_hasher();
    h.write_u64(COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed));
    h.write_u128(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos()),
    );
    h.write_u32(std::process::id());
    h.finish()
}

/// A temporary path beside `target`: `.<name>.<random>.partial`.
fn temporary(target: &Path) -> Result<PathBuf, String> {
    let name = target
        .file_name()
        .ok_or_else(|| format!("{}: cannot write: not a file name", target.display()))?;
    Ok(target.with_file_name(format!(
        ".{}.{:016x}.partial",
        name.to_string_lossy(),
        random()
    )))
}

/// A file being written at a temporary path; removed unless [`Staged::commit`] renames it.
pub struct Staged {
    tmp: PathBuf,
    target: PathBuf,
    done: bool,
}

impl Staged {
    /// Creates the temporary file beside `target` ([`create_new`]).
    pub fn create(target: &Path) -> Result<(Self, BufWriter<File>), String> {
        let tmp = temporary(target)?;
        let file = create_new(&tmp).map_err(|e| cannot_write(target, &e))?;
        Ok((
            Self {
                tmp,
                target: target.to_path_buf(),
                done: false,
            },
            BufWriter::new(file),
        ))
    }

    /// Flushes `w` to disk and renames the file to its target (replacing whatever is there, a
    /// planted link itself rather than what it points to).
    pub fn commit(mut self, w: BufWriter<File>) -> Result<(), String> {
        let file = w
            .into_inner()
            .map_err(|e| cannot_write(&self.target, e.error()))?;
        file.sync_all()
            .map_err(|e| cannot_write(&self.target, &e))?;
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
pub fn write(
    target: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> Result<(), String>,
) -> Result<(), String> {
    let (staged, mut w) = Staged::create(target)?;
    body(&mut w)?;
    w.flush().map_err(|e| cannot_write(target, &e))?;
    staged.commit(w)
}

/// Writes `bytes` to `target`, staged.
pub fn write_bytes(target: &Path, bytes: &[u8]) -> Result<(), String> {
    write(target, |w| {
        w.write_all(bytes).map_err(|e| cannot_write(target, &e))
    })
}

/// Whether a new file can be made in `dir`: one is created at an unpredictable name and
/// removed.
pub fn probe(dir: &Path) -> std::io::Result<()> {
    let path = dir.join(format!(".write-test.{:016x}", random()));
    create_new(&path)?;
    std::fs::remove_file(&path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::symlink;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("outputs-test-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_link_planted_at_the_target_is_replaced_not_written_through() {
        let d = dir("link");
        let victim = d.join("victim");
        std::fs::write(&victim, "keep").unwrap();
        let target = d.join("out.json");
        symlink(&victim, &target).unwrap();
        write_bytes(&target, b"ours").unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
        assert!(
            !std::fs::symlink_metadata(&target)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "ours");
        // Nothing else is left beside it.
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 2);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn create_new_refuses_links_and_existing_files_and_fifos() {
        let d = dir("new");
        let victim = d.join("victim");
        std::fs::write(&victim, "keep").unwrap();
        symlink(&victim, d.join("link")).unwrap();
        symlink(d.join("nowhere"), d.join("dangling")).unwrap();
        let fifo = std::ffi::CString::new(d.join("fifo").to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
        for name in ["link", "dangling", "victim", "fifo"] {
            assert!(create_new(&d.join(name)).is_err(), "{name}");
        }
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
        assert!(!d.join("nowhere").exists());
        probe(&d).unwrap();
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 4);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn temporary_names_differ_every_time() {
        let t = Path::new("/x/out.rrd");
        let (a, b) = (temporary(t).unwrap(), temporary(t).unwrap());
        assert_ne!(a, b);
        assert!(
            a.file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .starts_with(".out.rrd.")
        );
    }
}
