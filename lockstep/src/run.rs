//! One run's private corner of the machine: an iceoryx2 prefix, a root directory, and the
//! component configurations, all removed when the run ends.
//!
//! Layout: `$UIO_RUNS_DIR/<id>/` (default `$XDG_RUNTIME_DIR/uio-observers/<id>/`, else
//! `/tmp/uio-observers-<uid>/<id>/`, mode 0700) holds `owner.pid` (the launcher's pid), one
//! `<component>.json` per component, and `iox2/`, the iceoryx2 root path; shared memory lives in
//! `/dev/shm/uio<id>_*`. The runs directory is used only when it is private (see
//! [`crate::run_dir`]), and nothing is removed that is not provably a dead run of ours.

use std::ffi::OsStr;
use std::fs;
use std::io::{Read, Write};
use std::os::unix::fs::{DirBuilderExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use iceoryx2::prelude::*;
use iceoryx2_bb_system_types::path::Path as IoxPath;

use crate::error::LockstepError;
use crate::run_dir::{Dir, default_runs_dir, ensure_private, id_pid, open_private};

/// Environment variable naming the directory that holds run directories.
pub const RUNS_DIR_ENV: &str = "UIO_RUNS_DIR";

const SHM_DIR: &str = "/dev/shm";

/// Where a run's iceoryx2 root goes when `<run dir>/iox2/` is too long: iceoryx2 names the
/// unix sockets of its event services (the `block`, `waitset` and `spin-then-block` waits)
/// after the root, and a socket's path holds at most 108 bytes. One per user,
/// `/tmp/uio-iox2-<uid>`: a folder of fixed name belongs to whoever makes it first, and would
/// lock every other user out.
fn short_roots() -> PathBuf {
    PathBuf::from(format!("/tmp/uio-iox2-{}", crate::run_dir::euid()))
}

/// The longest root that leaves room for iceoryx2's socket names (measured: a 62-byte root
/// fails, a 57-byte one works).
const MAX_ROOT: usize = 56;

/// The iceoryx2 root of run `id` in `dir`: `<dir>/iox2/`, or `/tmp/uio-iox2-<uid>/<id>/` when that is
/// too long (a deep `UIO_RUNS_DIR`). A function of the two, so every process finds the same.
pub fn iox2_root(dir: &Path, id: &str) -> PathBuf {
    let inside = dir.join("iox2");
    if inside.as_os_str().len() < MAX_ROOT {
        inside
    } else {
        short_roots().join(id)
    }
}

/// A run's identity and its iceoryx2 configuration.
#[derive(Debug, Clone)]
pub struct RunSpace {
    id: String,
    dir: PathBuf,
    config: Config,
}

/// Where run directories live, made absolute: components run in other working directories (an
/// external one in its scenario's folder) and are handed these paths.
fn runs_dir() -> PathBuf {
    let dir = std::env::var_os(RUNS_DIR_ENV)
        .filter(|d| !d.is_empty())
        .map_or_else(
            || default_runs_dir(std::env::var_os("XDG_RUNTIME_DIR").as_deref()),
            PathBuf::from,
        );
    std::path::absolute(&dir).unwrap_or(dir)
}

/// The folders whose owner the run-directory checks judge: the parents of the runs directory
/// and of the short iceoryx2 roots.
pub(crate) fn checked_parents() -> Vec<PathBuf> {
    [runs_dir(), short_roots()]
        .iter()
        .filter_map(|p| p.parent().map(Path::to_path_buf))
        .collect()
}

const RUNS: &str = "runs directory";
const ROOTS: &str = "iceoryx2 root directory";

/// Makes (or checks) the runs directory and, when this process's runs would need it, the short
/// iceoryx2 roots' directory: each a real directory, ours, mode 0700. Returns the runs
/// directory, or one line naming the path and why it is refused. The launcher calls this before
/// any output exists, so a refused directory is bad input.
pub fn prepare_runs_dir() -> Result<PathBuf, LockstepError> {
    let base = runs_dir();
    ensure_private(RUNS, &base)?;
    // The longest id this process can make: its pid, a counter below 10⁶, a six-digit nonce.
    let longest = format!("{}x999999x999999", std::process::id());
    if !iox2_root(&base.join(&longest), &longest).starts_with(&base) {
        ensure_private(ROOTS, &short_roots())?;
    }
    Ok(base)
}

/// Reads a pid from `name` in `dir`: None when it is absent, unreadable or not a number; an
/// error when it is there but not a regular file of ours (a FIFO, a device, a symlink).
fn read_pid(dir: &Dir, name: &str) -> Result<Option<i32>, std::io::Error> {
    let f = match dir.open_own_file(OsStr::new(name)) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    let mut text = String::new();
    Ok(f.take(32)
        .read_to_string(&mut text)
        .ok()
        .and_then(|_| text.trim().parse().ok()))
}

fn io(what: &str, path: &Path, e: std::io::Error) -> LockstepError {
    LockstepError::Io(format!("{what} {}: {e}", path.display()))
}

impl RunSpace {
    /// A new run owned by this process.
    pub fn create() -> Result<Self, LockstepError> {
        static COUNTER: AtomicU32 = AtomicU32::new(0);
        let base = runs_dir();
        ensure_private(RUNS, &base)?;
        let id = format!(
            "{}x{}x{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed),
            crate::now_ns() % 1_000_000
        );
        // Built under a hidden name and renamed into place, so a concurrent launcher cleaning
        // up dead runs never sees a run directory without its owner.
        let tmp = base.join(format!(".new-{id}"));
        fs::DirBuilder::new()
            .mode(0o700)
            .create(&tmp)
            .map_err(|e| io("cannot create", &tmp, e))?;
        fs::DirBuilder::new()
            .mode(0o700)
            .create(tmp.join("iox2"))
            .map_err(|e| io("cannot create", &tmp, e))?;
        let mut f = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(tmp.join("owner.pid"))
            .map_err(|e| io("cannot write", &tmp, e))?;
        writeln!(f, "{}", std::process::id()).map_err(|e| io("cannot write", &tmp, e))?;
        let dir = base.join(&id);
        let root = iox2_root(&dir, &id);
        if !root.starts_with(&dir) {
            let roots = ensure_private(ROOTS, &short_roots())?;
            roots
                .mkdir(OsStr::new(&id))
                .map_err(|e| io("cannot create", &root, e))?;
        }
        fs::rename(&tmp, &dir).map_err(|e| io("cannot create", &dir, e))?;
        Self::at(id, dir)
    }

    /// An existing run, as a component started by the launcher sees it: the runs directory
    /// private, the run's directory a real one of ours, its `owner.pid` a regular file of ours.
    pub fn open(id: &str) -> Result<Self, LockstepError> {
        if id.is_empty() || !id.chars().all(|c| c.is_ascii_alphanumeric()) {
            return Err(LockstepError::Io(format!("'{id}' is not a run id")));
        }
        let base = runs_dir();
        let dir = base.join(id);
        let missing = || LockstepError::Io(format!("no run '{id}' in {}", base.display()));
        // No runs directory yet (no launcher has run on this machine): no run either.
        if std::fs::symlink_metadata(&base).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound)
        {
            return Err(missing());
        }
        let runs = open_private(RUNS, &base)?;
        let run = match runs.at(OsStr::new(id)) {
            Ok(run) => run,
            Err(e) if e.raw_os_error() == Some(libc::ENOENT) => return Err(missing()),
            Err(e) => {
                return Err(LockstepError::Io(format!(
                    "run directory {}: {e} (a symbolic link or not a directory?); refusing to use it",
                    dir.display()
                )));
            }
        };
        if !run.stat().is_ok_and(|s| s.is_ours()) {
            return Err(LockstepError::Io(format!(
                "run directory {}: not ours; refusing to use it",
                dir.display()
            )));
        }
        match read_pid(&run, "owner.pid") {
            Ok(Some(_)) => Self::at(id.to_string(), dir),
            Ok(None) => Err(missing()),
            Err(e) => Err(LockstepError::Io(format!(
                "{}: {e}; refusing to use it",
                dir.join("owner.pid").display()
            ))),
        }
    }

    fn at(id: String, dir: PathBuf) -> Result<Self, LockstepError> {
        // The built-in defaults, not a config file: runs must not depend on what /etc holds.
        let mut config = Config::default();
        config.global.prefix =
            FileName::new(format!("uio{id}_").as_bytes()).map_err(LockstepError::ipc)?;
        let root = format!("{}/", iox2_root(&dir, &id).display());
        config
            .global
            .set_root_path(&IoxPath::new(root.as_bytes()).map_err(LockstepError::ipc)?);
        Ok(Self { id, dir, config })
    }

    /// The pid of the launcher that owns the run.
    pub fn owner(&self) -> Option<i32> {
        read_pid(&Dir::open(&self.dir).ok()?, "owner.pid")
            .ok()
            .flatten()
    }

    /// The run id (alphanumeric).
    pub fn id(&self) -> &str {
        &self.id
    }

    /// The run directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The iceoryx2 root path (see [`iox2_root`]).
    pub fn iox2_root(&self) -> PathBuf {
        iox2_root(&self.dir, &self.id)
    }

    /// The iceoryx2 configuration with this run's prefix and root.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Where a component's configuration is written.
    pub fn config_path(&self, component: &str) -> PathBuf {
        self.dir.join(format!("{component}.json"))
    }

    /// Writes a component configuration (owner-only permissions).
    pub fn write_config(&self, component: &str, json: &str) -> Result<(), LockstepError> {
        let path = self.config_path(component);
        fs::write(&path, json).map_err(|e| io("cannot write", &path, e))?;
        fs::set_permissions(&path, fs::Permissions::from_mode(0o600))
            .map_err(|e| io("cannot chmod", &path, e))
    }

    /// Reads a component configuration.
    pub fn read_config(&self, component: &str) -> Result<String, LockstepError> {
        let path = self.config_path(component);
        fs::read_to_string(&path).map_err(|e| io("cannot read", &path, e))
    }

    /// The shared-memory files of this run that exist now.
    pub fn shm_files(&self) -> Vec<PathBuf> {
        shm_files_with_prefix(&format!("uio{}_", self.id))
    }

    /// Makes the run's shared-memory files readable and writable by their owner only.
    ///
    /// iceoryx2 creates its data, connection and dynamic segments with mode 0600, but its node
    /// counter (`…node.<version>.global_mgmt`) with global access (0666). The launcher creates
    /// that segment when it joins the bus, before any component starts, and calls this at once.
    pub fn restrict_shm(&self) -> Result<(), LockstepError> {
        let Ok(shm) = Dir::open(Path::new(SHM_DIR)) else {
            return Ok(());
        };
        for f in self.shm_files() {
            // Through an O_NOFOLLOW descriptor of a regular file of ours: a name planted in
            // /dev/shm cannot make this chmod anything else.
            let name = f.file_name().unwrap_or_default();
            let file = shm
                .open_own_file(name)
                .map_err(|e| io("cannot chmod", &f, e))?;
            file.set_permissions(fs::Permissions::from_mode(0o600))
                .map_err(|e| io("cannot chmod", &f, e))?;
        }
        Ok(())
    }

    /// Removes every file of the run: its shared memory and its directory.
    pub fn remove(&self) {
        remove_shm_with_prefix(&format!("uio{}_", self.id));
        if let Some(base) = self.dir.parent()
            && let Ok(runs) = open_private(RUNS, base)
        {
            let _ = runs.remove_tree(OsStr::new(&self.id));
        }
        if let Ok(roots) = open_private(ROOTS, &short_roots()) {
            let _ = roots.remove_tree(OsStr::new(&self.id));
        }
    }
}

/// `/dev/shm` files whose name starts with `prefix` and that are regular files of ours: what
/// another user put there under our name is not ours to chmod or remove.
fn shm_files_with_prefix(prefix: &str) -> Vec<PathBuf> {
    let Ok(shm) = Dir::open(Path::new(SHM_DIR)) else {
        return Vec::new();
    };
    let names = shm.names().unwrap_or_default();
    names
        .into_iter()
        .filter(|n| n.to_string_lossy().starts_with(prefix))
        .filter(|n| shm.stat_at(n).is_ok_and(|s| s.is_file() && s.is_ours()))
        .map(|n| Path::new(SHM_DIR).join(n))
        .collect()
}

fn remove_shm_with_prefix(prefix: &str) {
    let Ok(shm) = Dir::open(Path::new(SHM_DIR)) else {
        return;
    };
    for f in shm_files_with_prefix(prefix) {
        let _ = shm.remove_own_file(f.file_name().unwrap_or_default());
    }
}

fn alive(pid: i32) -> bool {
    // SAFETY: kill with signal 0 only checks for existence and permission.
    unsafe { libc::kill(pid, 0) == 0 || *libc::__errno_location() == libc::EPERM }
}

/// Removes what runs whose launcher has died left behind — their directories and their shared
/// memory, also shared memory whose directory is already gone; returns how many runs were cleaned.
///
/// Only what is provably a dead run of ours goes: in a private runs directory, an entry that is
/// a real directory (not a symlink) owned by us, named like a run id, whose `owner.pid` is a
/// regular file of ours naming a dead process (or is absent and the id's pid is dead). Anything
/// else — a symlink, another user's directory, an `owner.pid` that is a FIFO or a device — is
/// left alone, unread. Removal goes through directory descriptors and never follows a symlink.
pub fn cleanup_dead_runs() -> usize {
    let mut cleaned = 0;
    if let Ok(runs) = open_private(RUNS, &runs_dir()) {
        for name in runs.names().unwrap_or_default() {
            let name_str = name.to_string_lossy().into_owned();
            let (id, building) = match name_str.strip_prefix(".new-") {
                Some(rest) => (rest.to_string(), true),
                None => (name_str.clone(), false),
            };
            let Some(id_owner) = id_pid(&id) else {
                continue;
            };
            let Ok(run) = runs.at(&name) else { continue };
            if !run.stat().is_ok_and(|s| s.is_dir() && s.is_ours()) {
                continue;
            }
            let owner = if building {
                // Still being set up; left over only if its launcher died doing it.
                Some(id_owner)
            } else {
                match read_pid(&run, "owner.pid") {
                    Ok(Some(pid)) => Some(pid),
                    Ok(None) => Some(id_owner),
                    Err(_) => continue,
                }
            };
            drop(run);
            if owner.is_some_and(alive) {
                continue;
            }
            let _ = runs.remove_tree(&name);
            if !building {
                remove_shm_with_prefix(&format!("uio{id}_"));
                if let Ok(roots) = open_private(ROOTS, &short_roots()) {
                    let _ = roots.remove_tree(OsStr::new(&id));
                }
                cleaned += 1;
            }
        }
    }
    // Short iceoryx2 roots are named after their run id, <launcher pid>x…: the owner is in the name.
    if let Ok(roots) = open_private(ROOTS, &short_roots()) {
        for name in roots.names().unwrap_or_default() {
            let Some(pid) = name.to_str().and_then(id_pid) else {
                continue;
            };
            let ours = roots
                .stat_at(&name)
                .is_ok_and(|s| s.is_dir() && s.is_ours());
            if ours && !alive(pid) {
                let _ = roots.remove_tree(&name);
            }
        }
    }
    // Shared memory is named uio<launcher pid>x<n>x<nonce>_…: the owner is in the name.
    if let Ok(shm) = Dir::open(Path::new(SHM_DIR)) {
        for f in shm_files_with_prefix("uio") {
            let name = f.file_name().unwrap_or_default();
            let id = name
                .to_str()
                .and_then(|n| n.strip_prefix("uio"))
                .and_then(|r| r.split('_').next())
                .unwrap_or_default();
            if id_pid(id).is_some_and(|p| !alive(p)) {
                let _ = shm.remove_own_file(name);
            }
        }
    }
    cleaned
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run_dir::is_run_id;

    #[test]
    fn short_roots_and_run_ids_agree() {
        // A short root's name must be a run id, or cleanup would never recognise it.
        let id = format!("{}x0x123456", std::process::id());
        assert!(is_run_id(&id));
        let root = iox2_root(
            &Path::new("/a/very/long/runs/directory/that/is/far/too/long/for").join(&id),
            &id,
        );
        assert_eq!(root, short_roots().join(&id));
    }
}
