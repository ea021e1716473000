//! One run's private corner of the machine: an iceoryx2 prefix, a root directory, and the
//! component configurations, all removed when the run ends.
//!
//! Layout: `$UIO_RUNS_DIR/<id>/` (default `/tmp/uio-observers/<id>/`, mode 0700) holds
//! `owner.pid` (the launcher's pid), one `<component>.json` per component, and `iox2/`, the
//! iceoryx2 root path; shared memory lives in `/dev/shm/uio<id>_*`.

use std::fs;
use std::io::Write;
use std::os::unix::fs::{DirBuilderExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use iceoryx2::prelude::*;
use iceoryx2_bb_system_types::path::Path as IoxPath;

use crate::error::LockstepError;

/// Environment variable naming the directory that holds run directories.
pub const RUNS_DIR_ENV: &str = "UIO_RUNS_DIR";

const SHM_DIR: &str = "/dev/shm";

/// Where a run's iceoryx2 root goes when `<run dir>/iox2/` is too long: iceoryx2 names the
/// unix sockets of its event services (the `block`, `waitset` and `spin-then-block` waits)
/// after the root, and a socket's path holds at most 108 bytes.
const SHORT_ROOTS: &str = "/tmp/uio-iox2";

/// The longest root that leaves room for iceoryx2's socket names (measured: a 62-byte root
/// fails, a 57-byte one works).
const MAX_ROOT: usize = 56;

/// The iceoryx2 root of run `id` in `dir`: `<dir>/iox2/`, or `/tmp/uio-iox2/<id>/` when that is
/// too long (a deep `UIO_RUNS_DIR`). A function of the two, so every process finds the same.
pub fn iox2_root(dir: &Path, id: &str) -> PathBuf {
    let inside = dir.join("iox2");
    if inside.as_os_str().len() < MAX_ROOT { inside } else { Path::new(SHORT_ROOTS).join(id) }
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
    let dir = std::env::var_os(RUNS_DIR_ENV).map_or_else(|| PathBuf::from("/tmp/uio-observers"), PathBuf::from);
    std::path::absolute(&dir).unwrap_or(dir)
}

fn io(what: &str, path: &Path, e: std::io::Error) -> LockstepError {
    LockstepError::Io(format!("{what} {}: {e}", path.display()))
}

impl RunSpace {
    /// A new run owned by this process.
    pub fn create() -> Result<Self, LockstepError> {
        static COUNTER: AtomicU32 = AtomicU32::new(0);
        let base = runs_dir();
        fs::DirBuilder::new().recursive(true).mode(0o700).create(&base).map_err(|e| io("cannot create", &base, e))?;
        let id = format!(
            "{}x{}x{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed),
            crate::now_ns() % 1_000_000
        );
        // Built under a hidden name and renamed into place, so a concurrent launcher cleaning
        // up dead runs never sees a run directory without its owner.
        let tmp = base.join(format!(".new-{id}"));
        fs::DirBuilder::new().mode(0o700).create(&tmp).map_err(|e| io("cannot create", &tmp, e))?;
        fs::DirBuilder::new().mode(0o700).create(tmp.join("iox2")).map_err(|e| io("cannot create", &tmp, e))?;
        let mut f = fs::File::create(tmp.join("owner.pid")).map_err(|e| io("cannot write", &tmp, e))?;
        writeln!(f, "{}", std::process::id()).map_err(|e| io("cannot write", &tmp, e))?;
        fs::set_permissions(tmp.join("owner.pid"), fs::Permissions::from_mode(0o600)).map_err(|e| io("cannot chmod", &tmp, e))?;
        let dir = base.join(&id);
        let root = iox2_root(&dir, &id);
        if !root.starts_with(&dir) {
            fs::DirBuilder::new().recursive(true).mode(0o700).create(&root).map_err(|e| io("cannot create", &root, e))?;
        }
        fs::rename(&tmp, &dir).map_err(|e| io("cannot create", &dir, e))?;
        Self::at(id, dir)
    }

    /// An existing run, as a component started by the launcher sees it.
    pub fn open(id: &str) -> Result<Self, LockstepError> {
        if id.is_empty() || !id.chars().all(|c| c.is_ascii_alphanumeric()) {
            return Err(LockstepError::Io(format!("'{id}' is not a run id")));
        }
        let dir = runs_dir().join(id);
        if !dir.join("owner.pid").is_file() {
            return Err(LockstepError::Io(format!("no run '{id}' in {}", runs_dir().display())));
        }
        Self::at(id.to_string(), dir)
    }

    fn at(id: String, dir: PathBuf) -> Result<Self, LockstepError> {
        // The built-in defaults, not a config file: runs must not depend on what /etc holds.
        let mut config = Config::default();
        config.global.prefix = FileName::new(format!("uio{id}_").as_bytes()).map_err(LockstepError::ipc)?;
        let root = format!("{}/", iox2_root(&dir, &id).display());
        config.global.set_root_path(&IoxPath::new(root.as_bytes()).map_err(LockstepError::ipc)?);
        Ok(Self { id, dir, config })
    }

    /// The pid of the launcher that owns the run.
    pub fn owner(&self) -> Option<i32> {
        fs::read_to_string(self.dir.join("owner.pid")).ok().and_then(|s| s.trim().parse().ok())
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
        fs::set_permissions(&path, fs::Permissions::from_mode(0o600)).map_err(|e| io("cannot chmod", &path, e))
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
        for f in self.shm_files() {
            fs::set_permissions(&f, fs::Permissions::from_mode(0o600)).map_err(|e| io("cannot chmod", &f, e))?;
        }
        Ok(())
    }

    /// Removes every file of the run: its shared memory and its directory.
    pub fn remove(&self) {
        for f in self.shm_files() {
            let _ = fs::remove_file(f);
        }
        let _ = fs::remove_dir_all(&self.dir);
        let _ = fs::remove_dir_all(Path::new(SHORT_ROOTS).join(&self.id));
    }
}

fn shm_files_with_prefix(prefix: &str) -> Vec<PathBuf> {
    let Ok(entries) = fs::read_dir(SHM_DIR) else { return Vec::new() };
    entries
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with(prefix))
        .map(|e| e.path())
        .collect()
}

fn alive(pid: i32) -> bool {
    // SAFETY: kill with signal 0 only checks for existence and permission.
    unsafe { libc::kill(pid, 0) == 0 || *libc::__errno_location() == libc::EPERM }
}

/// Removes what runs whose launcher has died left behind — their directories and their shared
/// memory, also shared memory whose directory is already gone; returns how many runs were cleaned.
pub fn cleanup_dead_runs() -> usize {
    let mut cleaned = 0;
    if let Ok(entries) = fs::read_dir(runs_dir()) {
        for entry in entries.flatten() {
            let id = entry.file_name().to_string_lossy().to_string();
            if let Some(rest) = id.strip_prefix(".new-") {
                // A directory still being set up; left over only if its launcher died doing it.
                let owner = rest.split('x').next().and_then(|p| p.parse::<i32>().ok());
                if !owner.is_some_and(alive) {
                    let _ = fs::remove_dir_all(entry.path());
                }
                continue;
            }
            let owner = fs::read_to_string(entry.path().join("owner.pid")).ok().and_then(|s| s.trim().parse::<i32>().ok());
            if !owner.is_some_and(alive) {
                for f in shm_files_with_prefix(&format!("uio{id}_")) {
                    let _ = fs::remove_file(f);
                }
                let _ = fs::remove_dir_all(entry.path());
                let _ = fs::remove_dir_all(Path::new(SHORT_ROOTS).join(&id));
                cleaned += 1;
            }
        }
    }
    // Short iceoryx2 roots are named after their run id, <launcher pid>x…: the owner is in the name.
    if let Ok(entries) = fs::read_dir(SHORT_ROOTS) {
        for entry in entries.flatten() {
            let pid = entry.file_name().to_string_lossy().split('x').next().and_then(|p| p.parse::<i32>().ok());
            if pid.is_some_and(|p| !alive(p)) {
                let _ = fs::remove_dir_all(entry.path());
            }
        }
    }
    // Shared memory is named uio<launcher pid>x<n>x<nonce>_…: the owner is in the name.
    for f in shm_files_with_prefix("uio") {
        let name = f.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        let pid = name.strip_prefix("uio").and_then(|r| r.split('x').next()).and_then(|p| p.parse::<i32>().ok());
        if pid.is_some_and(|p| !alive(p)) {
            let _ = fs::remove_file(f);
        }
    }
    cleaned
}
