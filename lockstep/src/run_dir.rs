//! Directories another user cannot turn against us.
//!
//! The runs directory defaults to a fixed name in `/tmp`, which every user may write, and the
//! launcher often runs as root: a symlink or a FIFO planted there must never make it delete,
//! chmod or block on something of someone else's. So every directory is opened with
//! `O_NOFOLLOW`, checked on its open descriptor (`fstat`: a directory, ours), and all work below
//! it happens relative to that descriptor (`openat`, `fstatat`, `unlinkat`), whatever its path
//! comes to name; files whose content is read are opened `O_NOFOLLOW | O_NONBLOCK` and checked
//! to be regular files of ours before a byte is read.

use std::ffi::{CStr, CString, OsStr, OsString};
use std::io;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::os::unix::fs::{DirBuilderExt, MetadataExt};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use crate::error::LockstepError;

/// The effective uid: what the kernel checks our access with, so what "ours" means.
pub(crate) fn euid() -> u32 {
    // SAFETY: geteuid cannot fail and touches no memory.
    unsafe { libc::geteuid() }
}

fn cstr(name: &OsStr) -> io::Result<CString> {
    CString::new(name.as_bytes()).map_err(|_| io::Error::from(io::ErrorKind::InvalidInput))
}

fn check(ret: libc::c_int) -> io::Result<libc::c_int> {
    if ret < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(ret)
    }
}

/// What `fstat`/`fstatat` say about one file.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stat {
    mode: u32,
    uid: u32,
}

impl Stat {
    fn of(st: &libc::stat) -> Self {
        Stat {
            mode: st.st_mode,
            uid: st.st_uid,
        }
    }

    fn kind(self) -> u32 {
        self.mode & libc::S_IFMT
    }

    /// A directory.
    pub(crate) fn is_dir(self) -> bool {
        self.kind() == libc::S_IFDIR
    }

    /// A regular file: not a FIFO, a device, a socket or a symlink.
    pub(crate) fn is_file(self) -> bool {
        self.kind() == libc::S_IFREG
    }

    /// Owned by our effective uid.
    pub(crate) fn is_ours(self) -> bool {
        self.uid == euid()
    }
}

/// An open directory, reached without following a symlink in its last component.
#[derive(Debug)]
pub(crate) struct Dir {
    fd: OwnedFd,
}

const DIR_FLAGS: libc::c_int =
    libc::O_RDONLY | libc::O_DIRECTORY | libc::O_NOFOLLOW | libc::O_CLOEXEC;

impl Dir {
    /// Opens `path`; a symlink as its last component fails (`ELOOP`), a non-directory too.
    pub(crate) fn open(path: &Path) -> io::Result<Dir> {
        let c = cstr(path.as_os_str())?;
        // SAFETY: a valid NUL-terminated path; the returned fd is owned below.
        let fd = check(unsafe { libc::open(c.as_ptr(), DIR_FLAGS) })?;
        // SAFETY: fd was just opened and is owned by nobody else.
        Ok(Dir {
            fd: unsafe { OwnedFd::from_raw_fd(fd) },
        })
    }

    /// Opens the directory `name` inside this one, never following a symlink.
    pub(crate) fn at(&self, name: &OsStr) -> io::Result<Dir> {
        let c = cstr(name)?;
        // SAFETY: valid directory fd and NUL-terminated name.
        let fd = check(unsafe { libc::openat(self.fd.as_raw_fd(), c.as_ptr(), DIR_FLAGS) })?;
        // SAFETY: as in `open`.
        Ok(Dir {
            fd: unsafe { OwnedFd::from_raw_fd(fd) },
        })
    }

    /// The directory itself.
    pub(crate) fn stat(&self) -> io::Result<Stat> {
        // SAFETY: an all-zero stat is a valid value; fstat fills it.
        let mut st: libc::stat = unsafe { std::mem::zeroed() };
        // SAFETY: valid fd and a writable stat.
        check(unsafe { libc::fstat(self.fd.as_raw_fd(), &mut st) })?;
        Ok(Stat::of(&st))
    }

    /// The entry `name` itself, a symlink not followed.
    pub(crate) fn stat_at(&self, name: &OsStr) -> io::Result<Stat> {
        let c = cstr(name)?;
        // SAFETY: as in `stat`.
        let mut st: libc::stat = unsafe { std::mem::zeroed() };
        // SAFETY: valid fd, name and a writable stat.
        check(unsafe {
            libc::fstatat(
                self.fd.as_raw_fd(),
                c.as_ptr(),
                &mut st,
                libc::AT_SYMLINK_NOFOLLOW,
            )
        })?;
        Ok(Stat::of(&st))
    }

    /// Sets the directory's own mode.
    pub(crate) fn chmod(&self, mode: u32) -> io::Result<()> {
        // SAFETY: valid fd.
        check(unsafe { libc::fchmod(self.fd.as_raw_fd(), mode as libc::mode_t) }).map(drop)
    }

    /// Makes the directory `name` inside this one (mode 0700).
    pub(crate) fn mkdir(&self, name: &OsStr) -> io::Result<()> {
        let c = cstr(name)?;
        // SAFETY: valid fd and name.
        check(unsafe { libc::mkdirat(self.fd.as_raw_fd(), c.as_ptr(), 0o700) }).map(drop)
    }

    /// The names of the entries, without `.` and `..`.
    pub(crate) fn names(&self) -> io::Result<Vec<OsString>> {
        // fdopendir takes its fd over: hand it a duplicate, rewound, and close that when done.
        // SAFETY: valid fd; the duplicate is owned by the DIR stream from here on.
        let dup = check(unsafe { libc::fcntl(self.fd.as_raw_fd(), libc::F_DUPFD_CLOEXEC, 0) })?;
        // SAFETY: dup is a directory fd we own.
        let stream = unsafe { libc::fdopendir(dup) };
        if stream.is_null() {
            let e = io::Error::last_os_error();
            // SAFETY: dup is still ours when fdopendir failed.
            unsafe { libc::close(dup) };
            return Err(e);
        }
        let mut names = Vec::new();
        // SAFETY: stream is a valid DIR*; readdir's entries live until the next readdir call,
        // and each name is copied out before it.
        unsafe {
            libc::rewinddir(stream);
            loop {
                let entry = libc::readdir(stream);
                if entry.is_null() {
                    break;
                }
                let name = CStr::from_ptr((*entry).d_name.as_ptr()).to_bytes();
                if name != b"." && name != b".." {
                    names.push(OsString::from_vec(name.to_vec()));
                }
            }
            libc::closedir(stream);
        }
        Ok(names)
    }

    /// Opens the regular file `name` of ours for reading: never follows a symlink, never blocks
    /// on a FIFO or a device (which are refused, as are files of other users).
    pub(crate) fn open_own_file(&self, name: &OsStr) -> io::Result<std::fs::File> {
        let c = cstr(name)?;
        let flags =
            libc::O_RDONLY | libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_NOCTTY | libc::O_CLOEXEC;
        // SAFETY: valid fd and name; the returned fd is owned by the File below.
        let fd = check(unsafe { libc::openat(self.fd.as_raw_fd(), c.as_ptr(), flags) })?;
        // SAFETY: fd was just opened and is owned by nobody else.
        let file = unsafe { std::fs::File::from_raw_fd(fd) };
        let meta = file.metadata()?;
        if !meta.file_type().is_file() || meta.uid() != euid() {
            return Err(io::Error::new(
                io::ErrorKind::PermissionDenied,
                "not a regular file of ours",
            ));
        }
        Ok(file)
    }

    /// Removes the entry `name`: a file or symlink itself, a directory with everything in it,
    /// each level opened with `O_NOFOLLOW` and emptied through its descriptor.
    pub(crate) fn remove_tree(&self, name: &OsStr) -> io::Result<()> {
        let c = cstr(name)?;
        // SAFETY: valid fd and name.
        match check(unsafe { libc::unlinkat(self.fd.as_raw_fd(), c.as_ptr(), 0) }) {
            Ok(_) => return Ok(()),
            Err(e) if e.raw_os_error() == Some(libc::EISDIR) => {}
            Err(e) => return Err(e),
        }
        let sub = self.at(name)?;
        let mut first = None;
        for n in sub.names()? {
            if let Err(e) = sub.remove_tree(&n) {
                first.get_or_insert(e);
            }
        }
        drop(sub);
        // SAFETY: valid fd and name.
        let gone =
            check(unsafe { libc::unlinkat(self.fd.as_raw_fd(), c.as_ptr(), libc::AT_REMOVEDIR) });
        match first {
            Some(e) => Err(e),
            None => gone.map(drop),
        }
    }

    /// Removes `name` if it is a regular file of ours (never a symlink, never another user's).
    pub(crate) fn remove_own_file(&self, name: &OsStr) -> io::Result<()> {
        let st = self.stat_at(name)?;
        if !st.is_file() || !st.is_ours() {
            return Err(io::Error::new(
                io::ErrorKind::PermissionDenied,
                "not a regular file of ours",
            ));
        }
        let c = cstr(name)?;
        // SAFETY: valid fd and name.
        check(unsafe { libc::unlinkat(self.fd.as_raw_fd(), c.as_ptr(), 0) }).map(drop)
    }
}

/// Why a directory is not private to us, in words; None when it is.
fn not_private(st: Stat) -> Option<String> {
    if !st.is_dir() {
        Some("is not a directory".into())
    } else if !st.is_ours() {
        Some(format!(
            "is owned by uid {}, not by us (uid {})",
            st.uid,
            euid()
        ))
    } else if st.mode & 0o077 != 0 {
        Some(format!(
            "is accessible to group or others (mode {:04o}, needs 0700)",
            st.mode & 0o7777
        ))
    } else {
        None
    }
}

/// Directories the machine's root owns, noted by (device, inode) before this process entered a
/// user namespace of its own ([`crate::private_shm`]): inside it only our uid is mapped, and root's
/// files show as the overflow uid (65534) like any other user's. These stay root's.
static ROOT_OWNED: OnceLock<Vec<(u64, u64)>> = OnceLock::new();

/// Notes which of `paths` root owns (see [`ROOT_OWNED`]); called once, before the namespace.
pub(crate) fn note_root_owned(paths: &[PathBuf]) {
    let owned = paths
        .iter()
        .filter_map(|p| std::fs::metadata(p).ok())
        .filter(|m| m.uid() == 0)
        .map(|m| (m.dev(), m.ino()))
        .collect();
    let _ = ROOT_OWNED.set(owned);
}

fn noted_root_owned(meta: &std::fs::Metadata) -> bool {
    ROOT_OWNED
        .get()
        .is_some_and(|v| v.contains(&(meta.dev(), meta.ino())))
}

/// Why `parent` would let another user swap a directory inside it; None when it would not.
/// Like ssh's StrictModes: owned by root or us, and not writable by others unless sticky
/// (`/tmp` is root's and sticky: others cannot rename or remove what we make there).
fn unsafe_parent(parent: &Path) -> Option<String> {
    let meta = std::fs::metadata(parent).ok()?;
    if meta.uid() != 0 && meta.uid() != euid() && !noted_root_owned(&meta) {
        Some(format!(
            "its parent {} is owned by uid {}, neither root nor us",
            parent.display(),
            meta.uid()
        ))
    } else if meta.mode() & 0o022 != 0 && meta.mode() & libc::S_ISVTX == 0 {
        Some(format!(
            "its parent {} is writable by others and not sticky (mode {:04o})",
            parent.display(),
            meta.mode() & 0o7777
        ))
    } else {
        None
    }
}

fn refuse(what: &str, path: &Path, why: &str) -> LockstepError {
    let hint = if what == "runs directory" {
        " (UIO_RUNS_DIR may name another, of yours, mode 0700)"
    } else {
        ""
    };
    LockstepError::Io(format!(
        "{what} {}: {why}; refusing to use it{hint}",
        path.display()
    ))
}

/// Opens the existing private directory `path` (a real directory, ours, mode 0700, in a parent
/// no other user can swap it in), or says in one line why it is not one. `what` names it.
pub(crate) fn open_private(what: &str, path: &Path) -> Result<Dir, LockstepError> {
    if let Some(why) = path.parent().and_then(unsafe_parent) {
        return Err(refuse(what, path, &why));
    }
    let dir = Dir::open(path).map_err(|e| match e.raw_os_error() {
        // Linux says ENOTDIR or ELOOP for a symlink opened O_DIRECTORY | O_NOFOLLOW: ask lstat.
        Some(libc::ELOOP | libc::ENOTDIR)
            if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) =>
        {
            refuse(what, path, "is a symbolic link")
        }
        Some(libc::ELOOP | libc::ENOTDIR) => refuse(what, path, "is not a directory"),
        _ => LockstepError::Io(format!("cannot open {what} {}: {e}", path.display())),
    })?;
    let st = dir
        .stat()
        .map_err(|e| LockstepError::Io(format!("cannot stat {what} {}: {e}", path.display())))?;
    match not_private(st) {
        Some(why) => Err(refuse(what, path, &why)),
        None => Ok(dir),
    }
}

/// [`open_private`], making the directory (mode 0700, its parents as needed) when it is absent.
pub(crate) fn ensure_private(what: &str, path: &Path) -> Result<Dir, LockstepError> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent)
            .map_err(|e| LockstepError::Io(format!("cannot create {}: {e}", parent.display())))?;
    }
    let made = match std::fs::DirBuilder::new().mode(0o700).create(path) {
        Ok(()) => true,
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => false,
        Err(e) => {
            return Err(LockstepError::Io(format!(
                "cannot create {what} {}: {e}",
                path.display()
            )));
        }
    };
    if made {
        // A umask may have taken bits from 0700; what we just made is ours to set right.
        if let Ok(dir) = Dir::open(path)
            && dir.stat().is_ok_and(|s| s.is_dir() && s.is_ours())
        {
            let _ = dir.chmod(0o700);
        }
    }
    open_private(what, path)
}

/// The default runs directory: `$XDG_RUNTIME_DIR/uio-observers` when `xdg` (that variable) is
/// an absolute path to a real directory of ours — per user and on tmpfs — else
/// `/tmp/uio-observers-<uid>`, one per user (a shared name belongs to whoever makes it first and
/// would lock every other user out).
pub(crate) fn default_runs_dir(xdg: Option<&OsStr>) -> PathBuf {
    let usable = xdg
        .map(Path::new)
        .filter(|p| p.is_absolute())
        .is_some_and(|p| {
            std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_dir() && m.uid() == euid())
        });
    match xdg {
        Some(x) if usable => Path::new(x).join("uio-observers"),
        _ => PathBuf::from(format!("/tmp/uio-observers-{}", euid())),
    }
}

/// A run id as [`crate::RunSpace::create`] makes them: `<pid>x<n>x<nonce>`, all decimal.
pub fn is_run_id(name: &str) -> bool {
    let parts: Vec<&str> = name.split('x').collect();
    parts.len() == 3
        && parts
            .iter()
            .all(|p| !p.is_empty() && p.len() <= 20 && p.bytes().all(|b| b.is_ascii_digit()))
}

/// The launcher pid a run id starts with.
pub(crate) fn id_pid(id: &str) -> Option<i32> {
    if is_run_id(id) {
        id.split('x').next()?.parse().ok()
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    fn scratch(tag: &str) -> PathBuf {
        let p = std::env::temp_dir().join(format!("uio-rundir-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir(&p).unwrap();
        p
    }

    #[test]
    fn a_symlink_a_file_and_an_open_directory_are_refused() {
        let s = scratch("refuse");
        std::fs::create_dir(s.join("target")).unwrap();
        std::os::unix::fs::symlink(s.join("target"), s.join("link")).unwrap();
        std::fs::write(s.join("file"), "x").unwrap();
        std::fs::create_dir(s.join("open")).unwrap();
        std::fs::set_permissions(s.join("open"), std::fs::Permissions::from_mode(0o755)).unwrap();
        for (name, why) in [
            ("link", "is a symbolic link"),
            ("file", "is not a directory"),
            ("open", "accessible to group or others"),
        ] {
            let e = ensure_private("runs directory", &s.join(name))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(why)
                    && e.contains(&s.join(name).display().to_string())
                    && !e.contains('\n'),
                "{name}: {e}"
            );
        }
        // Nothing was changed: the link's target is still there and still 0755-or-whatever.
        assert!(s.join("target").is_dir());
        assert_eq!(
            std::fs::metadata(s.join("open"))
                .unwrap()
                .permissions()
                .mode()
                & 0o777,
            0o755
        );
        std::fs::remove_dir_all(&s).unwrap();
    }

    #[test]
    fn a_missing_directory_is_made_private() {
        let s = scratch("make");
        let d = s.join("a/b/runs");
        ensure_private("runs directory", &d).unwrap();
        let m = std::fs::symlink_metadata(&d).unwrap();
        assert!(
            m.is_dir() && m.uid() == euid() && m.mode() & 0o777 == 0o700,
            "{:o}",
            m.mode()
        );
        std::fs::remove_dir_all(&s).unwrap();
    }

    #[test]
    fn a_parent_writable_by_others_without_the_sticky_bit_is_refused() {
        let s = scratch("parent");
        std::fs::set_permissions(&s, std::fs::Permissions::from_mode(0o777)).unwrap();
        let e = ensure_private("runs directory", &s.join("runs"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("not sticky"), "{e}");
        std::fs::set_permissions(&s, std::fs::Permissions::from_mode(0o1777)).unwrap();
        ensure_private("runs directory", &s.join("runs")).unwrap();
        std::fs::remove_dir_all(&s).unwrap();
    }

    #[test]
    fn removal_never_follows_a_symlink() {
        let s = scratch("remove");
        std::fs::create_dir_all(s.join("victim/sub")).unwrap();
        std::fs::create_dir_all(s.join("tree/inner")).unwrap();
        std::os::unix::fs::symlink(s.join("victim"), s.join("tree/inner/link")).unwrap();
        std::os::unix::fs::symlink(s.join("victim"), s.join("top")).unwrap();
        let d = Dir::open(&s).unwrap();
        d.remove_tree(OsStr::new("tree")).unwrap();
        d.remove_tree(OsStr::new("top")).unwrap();
        assert!(!s.join("tree").exists() && std::fs::symlink_metadata(s.join("top")).is_err());
        assert!(s.join("victim/sub").is_dir());
        std::fs::remove_dir_all(&s).unwrap();
    }

    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let s = scratch("fifo");
        let c = CString::new(s.join("owner.pid").as_os_str().as_bytes()).unwrap();
        // SAFETY: a valid path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        std::os::unix::fs::symlink("/etc/hostname", s.join("link.pid")).unwrap();
        let d = Dir::open(&s).unwrap();
        assert!(d.open_own_file(OsStr::new("owner.pid")).is_err());
        assert!(d.open_own_file(OsStr::new("link.pid")).is_err());
        assert!(d.remove_own_file(OsStr::new("owner.pid")).is_err());
        std::fs::remove_dir_all(&s).unwrap();
    }

    #[test]
    fn the_default_is_the_runtime_directory_only_when_it_is_a_real_one_of_ours() {
        let s = scratch("xdg");
        std::os::unix::fs::symlink(&s, s.join("link")).unwrap();
        assert_eq!(
            default_runs_dir(Some(s.as_os_str())),
            s.join("uio-observers")
        );
        for bad in [s.join("link"), s.join("missing"), PathBuf::from("relative")] {
            assert_eq!(
                default_runs_dir(Some(bad.as_os_str())),
                Path::new(&format!("/tmp/uio-observers-{}", euid())),
                "{}",
                bad.display()
            );
        }
        assert_eq!(
            default_runs_dir(None),
            Path::new(&format!("/tmp/uio-observers-{}", euid()))
        );
        std::fs::remove_dir_all(&s).unwrap();
    }

    #[test]
    fn run_ids() {
        assert!(is_run_id("123x0x456") && id_pid("123x0x456") == Some(123));
        for bad in ["", "123", "123x0", "12ax0x1", "123x0x1x2", "..", "123x0x"] {
            assert!(!is_run_id(bad), "{bad}");
        }
    }
}
