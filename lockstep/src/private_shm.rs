//! A `/dev/shm` of the run's own: the launcher and every process it starts see a fresh tmpfs
//! there, mode 0700, that no other process on the machine can see, let alone open.
//!
//! Why: iceoryx2 0.10 creates its node-counter segment
//! (`…node.<version>.global_mgmt`) and then sets it to 0666 with an explicit `fchmod`
//! (`FINAL_PERMISSIONS_GLOBAL_ACCESS`), so no umask and no chmod after the fact closes the
//! window in which another local user can open it: a watcher as `nobody` broke 20 of 20 runs
//! that way (`UnableToGenerateUniqueNodeId`). In a mount namespace of its own the run's segments
//! are not in the machine's `/dev/shm` at all.
//!
//! How: `unshare(CLONE_NEWNS)`, `/` made recursively private so nothing mounted here propagates
//! back, and a tmpfs mounted on `/dev/shm` (`nosuid,nodev,noexec`, mode 0700, the size of the
//! machine's `/dev/shm`). Every other path is the machine's, so outputs, scenarios, FMUs and the
//! runs directory are where they were. The tmpfs goes away with the last process in the
//! namespace: a run killed with SIGKILL leaves no segment behind.
//!
//! As root, a mount namespace. As another user, a user namespace first (unprivileged user
//! namespaces: most distributions allow them), in which the process holds CAP_SYS_ADMIN; only our
//! uid and gid are mapped (to themselves), so files keep their owners as we see them, except
//! that every other uid, root's included, shows as the overflow uid (65534). The ownership checks
//! of the runs directory ([`crate::run_dir`]: a parent owned by root or by us) would then refuse
//! `/tmp` itself, so the parents they judge are noted as root's, by device and inode, before the
//! namespace is entered. Children inherit both namespaces and lose the capabilities when they
//! exec (their uid is not 0 there).
//!
//! Preconditions: called before the process starts a thread (a mount namespace entered by one
//! thread is that thread's alone) and before any segment is created. Where the kernel refuses
//! (a container without `CAP_SYS_ADMIN`, unprivileged user namespaces switched off) the run uses
//! the machine's `/dev/shm`, and [`enter`] says why. (A user namespace also needs the process
//! to be single-threaded: the same precondition.)

use std::ffi::CString;
use std::io;

/// Where the run's shared memory lives.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Shm {
    /// A tmpfs of the run's own on `/dev/shm`.
    Private,
    /// The machine's `/dev/shm`, and why the private one could not be made.
    Shared(String),
}

/// Environment variable that, set to `1`, keeps the machine's `/dev/shm` (for tests of the
/// shared case and for debugging a run's segments from outside).
pub const SHARED_ENV: &str = "UIO_SHARED_SHM";

const SHM: &str = "/dev/shm";

/// Moves this process (and everything it starts afterwards) to a private `/dev/shm`; see the
/// module docs for the preconditions.
pub fn enter() -> Shm {
    if std::env::var_os(SHARED_ENV).is_some_and(|v| v == "1") {
        return Shm::Shared(format!("{SHARED_ENV}=1"));
    }
    match try_enter() {
        Ok(()) => Shm::Private,
        Err(e) => Shm::Shared(e),
    }
}

fn try_enter() -> Result<(), String> {
    // The private tmpfs gets the machine's /dev/shm size: the run's budget check compares its
    // shared memory against that, and tmpfs pages are the machine's memory either way.
    let size = shm_size().map_err(|e| format!("{SHM}: {e}"))?;
    // SAFETY: geteuid, getegid and unshare take no pointers.
    let (uid, gid) = unsafe { (libc::geteuid(), libc::getegid()) };
    if uid == 0 {
        if unsafe { libc::unshare(libc::CLONE_NEWNS) } != 0 {
            return Err(format!("unshare: {}", io::Error::last_os_error()));
        }
    } else {
        // Another user: a user namespace of our own first (the mount needs CAP_SYS_ADMIN, which
        // we hold there), mapping our uid and gid to themselves only, so every file keeps its
        // owner as far as we are concerned; root's show as the overflow uid there, so the
        // folders the run-directory checks trust as root's are noted first.
        crate::run_dir::note_root_owned(&crate::run::checked_parents());
        if unsafe { libc::unshare(libc::CLONE_NEWUSER | libc::CLONE_NEWNS) } != 0 {
            return Err(format!(
                "unshare (a user namespace): {}",
                io::Error::last_os_error()
            ));
        }
        write_proc("/proc/self/setgroups", "deny")?;
        write_proc("/proc/self/uid_map", &format!("{uid} {uid} 1"))?;
        write_proc("/proc/self/gid_map", &format!("{gid} {gid} 1"))?;
    }
    mount(None, "/", None, libc::MS_REC | libc::MS_PRIVATE, None)?;
    let options = format!("mode=0700,size={size}");
    mount(
        Some("uio-shm"),
        SHM,
        Some("tmpfs"),
        libc::MS_NOSUID | libc::MS_NODEV | libc::MS_NOEXEC,
        Some(&options),
    )
}

fn write_proc(path: &str, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{path}: {e}"))
}

fn shm_size() -> io::Result<u64> {
    let path = CString::new(SHM).expect("no NUL in a constant");
    // SAFETY: statvfs writes into the zeroed struct we own.
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(path.as_ptr(), &mut st) } != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(st.f_blocks as u64 * st.f_frsize as u64)
}

fn mount(
    source: Option<&str>,
    target: &str,
    fstype: Option<&str>,
    flags: libc::c_ulong,
    data: Option<&str>,
) -> Result<(), String> {
    let c = |s: &str| CString::new(s).expect("no NUL in our mount arguments");
    let (source, target, fstype, data) = (source.map(c), c(target), fstype.map(c), data.map(c));
    let ptr = |s: &Option<CString>| s.as_ref().map_or(std::ptr::null(), |s| s.as_ptr());
    // SAFETY: every pointer is a NUL-terminated string alive for the call, or null where
    // mount(2) allows it.
    let rc = unsafe {
        libc::mount(
            ptr(&source),
            target.as_ptr(),
            ptr(&fstype),
            flags,
            ptr(&data).cast(),
        )
    };
    if rc != 0 {
        return Err(format!(
            "mount {}: {}",
            target.to_string_lossy(),
            io::Error::last_os_error()
        ));
    }
    Ok(())
}
