//! Run directories that cannot be turned against their owner. As root, with
//! what another user (`nobody`) planted — a symlink as the runs directory, a FIFO as a dead
//! run's `owner.pid`, a symlink as a run — the real launcher neither deletes, blocks on nor
//! removes anything that is not provably a dead run of its own. Each test runs in its own
//! `UIO_RUNS_DIR` and looks only at its own files; without root the tests skip, saying why.

use std::ffi::CString;
use std::fs;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{FileTypeExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use tests::*;

/// Generous for a 0.2 s scenario (a run takes about a second); the old launcher hung 612 s.
const DEADLINE: Duration = Duration::from_secs(60);

fn root_or_skip(test: &str) -> bool {
    // SAFETY: geteuid cannot fail.
    let root = unsafe { libc::geteuid() } == 0;
    if !root {
        tests::skip(
            test,
            "needs root (it plants files owned by another user and runs the launcher as root)",
        );
    }
    root
}

/// The uid and gid of `nobody`.
fn nobody() -> (u32, u32) {
    let name = CString::new("nobody").unwrap();
    // SAFETY: getpwnam with a valid name; the entry is read at once, before any other call.
    let pw = unsafe { libc::getpwnam(name.as_ptr()) };
    assert!(!pw.is_null(), "no user 'nobody'");
    // SAFETY: pw is a valid passwd entry.
    unsafe { ((*pw).pw_uid, (*pw).pw_gid) }
}

/// Makes `path` (a file, directory or symlink, not followed) `nobody`'s.
fn give_to_nobody(path: &Path) {
    let (uid, gid) = nobody();
    std::os::unix::fs::lchown(path, Some(uid), Some(gid)).unwrap();
}

/// The pid of a process that has exited.
fn dead_pid() -> u32 {
    let mut c = Command::new("true").spawn().unwrap();
    let pid = c.id();
    c.wait().unwrap();
    pid
}

fn mkfifo(path: &Path) {
    let c = CString::new(path.as_os_str().as_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(
        unsafe { libc::mkfifo(c.as_ptr(), 0o600) },
        0,
        "mkfifo {}",
        path.display()
    );
}

fn private_dir(path: &Path) {
    fs::create_dir_all(path).unwrap();
    fs::set_permissions(path, fs::Permissions::from_mode(0o700)).unwrap();
}

/// A directory tree someone else cares about: `<dir>/a/b/`, `<dir>/c/`, `<dir>/file`.
fn victim(path: &Path) {
    fs::create_dir_all(path.join("a/b")).unwrap();
    fs::create_dir_all(path.join("c")).unwrap();
    fs::write(path.join("file"), "precious").unwrap();
}

fn assert_victim_intact(path: &Path) {
    for d in ["a", "a/b", "c"] {
        assert!(
            path.join(d).is_dir(),
            "{} was removed",
            path.join(d).display()
        );
    }
    assert_eq!(fs::read_to_string(path.join("file")).unwrap(), "precious");
}

/// Runs `uio-launcher run <scenario>` with `runs` as UIO_RUNS_DIR (None: unset, with `env` added),
/// killing it if it is not done by [`DEADLINE`].
fn run_launcher(
    s: &Scratch,
    scenario: &Path,
    runs: Option<&Path>,
    env: &[(&str, &Path)],
) -> (Output, u32) {
    let mut cmd = launcher(s);
    match runs {
        Some(r) => cmd.env(lockstep_runs_env(), r),
        None => cmd.env_remove(lockstep_runs_env()),
    };
    for (k, v) in env {
        cmd.env(k, v);
    }
    let (out, err) = (s.join("launcher.out"), s.join("launcher.err"));
    let mut child = cmd
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(s.join("out"))
        .stdin(Stdio::null())
        .stdout(fs::File::create(&out).unwrap())
        .stderr(fs::File::create(&err).unwrap())
        .spawn()
        .unwrap();
    let pid = child.id();
    let start = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if start.elapsed() > DEADLINE {
            signal(pid as i32, libc::SIGKILL);
            let _ = child.wait();
            panic!(
                "the launcher hung: not done after {DEADLINE:?}; stderr: {}",
                fs::read_to_string(&err).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (
        Output {
            status,
            stdout: fs::read(&out).unwrap(),
            stderr: fs::read(&err).unwrap(),
        },
        pid,
    )
}

fn scenario_of(s: &Scratch) -> PathBuf {
    variant(s, "seed002-sine", 0.2, false)
}

/// The launcher refused with exit code 2 and one `error:` line naming `path` and `why`, before
/// any output existed.
fn assert_refused(s: &Scratch, o: &Output, path: &Path, why: &str) {
    let (_, err) = text(o);
    assert_eq!(
        o.status.code(),
        Some(2),
        "expected a refusal (exit 2): {err}"
    );
    let line = err
        .lines()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_else(|| panic!("no error line: {err}"));
    assert!(
        line.contains(&path.display().to_string()) && line.contains(why),
        "{line}"
    );
    assert!(
        !s.join("out/seed002-sine.rrd.partial").exists()
            && !s.join("out/seed002-sine.rrd").exists(),
        "output written"
    );
}

#[test]
fn a_symlink_planted_as_the_runs_directory_is_refused_and_its_target_untouched() {
    if !root_or_skip("a_symlink_planted_as_the_runs_directory_is_refused_and_its_target_untouched")
    {
        return;
    }
    let s = Scratch::new("rd-link");
    // A world-writable sticky folder like /tmp, where nobody plants the runs directory's name.
    let public = s.join("public");
    fs::create_dir(&public).unwrap();
    fs::set_permissions(&public, fs::Permissions::from_mode(0o1777)).unwrap();
    let target = s.join("victim");
    victim(&target);
    let runs = public.join("uio-observers");
    std::os::unix::fs::symlink(&target, &runs).unwrap();
    give_to_nobody(&runs);
    let (o, _) = run_launcher(&s, &scenario_of(&s), Some(&runs), &[]);
    assert_victim_intact(&target);
    assert_refused(&s, &o, &runs, "is a symbolic link");
    assert!(
        fs::symlink_metadata(&runs)
            .unwrap()
            .file_type()
            .is_symlink(),
        "the planted link is not ours to remove"
    );
}

#[test]
fn another_users_or_an_open_runs_directory_is_refused() {
    if !root_or_skip("another_users_or_an_open_runs_directory_is_refused") {
        return;
    }
    let s = Scratch::new("rd-owner");
    let theirs = s.join("theirs");
    private_dir(&theirs);
    victim(&theirs.join("data"));
    give_to_nobody(&theirs);
    let (o, _) = run_launcher(&s, &scenario_of(&s), Some(&theirs), &[]);
    assert_victim_intact(&theirs.join("data"));
    assert_refused(&s, &o, &theirs, "is owned by uid");

    let open = s.join("open");
    fs::create_dir(&open).unwrap();
    fs::set_permissions(&open, fs::Permissions::from_mode(0o755)).unwrap();
    let (o, _) = run_launcher(&s, &scenario_of(&s), Some(&open), &[]);
    assert_refused(&s, &o, &open, "accessible to group or others");
    assert_eq!(
        fs::metadata(&open).unwrap().mode() & 0o777,
        0o755,
        "a refused directory is left as it was"
    );
}

#[test]
fn a_fifo_as_a_dead_runs_owner_pid_neither_hangs_nor_is_removed() {
    if !root_or_skip("a_fifo_as_a_dead_runs_owner_pid_neither_hangs_nor_is_removed") {
        return;
    }
    let s = Scratch::new("rd-fifo");
    let runs = s.runs();
    private_dir(&runs);
    let dead = dead_pid();
    // One of ours, one of nobody's: both dead-pid run directories whose owner.pid is a FIFO.
    let ours = runs.join(format!("{dead}x0x1"));
    private_dir(&ours);
    mkfifo(&ours.join("owner.pid"));
    let theirs = runs.join(format!("{dead}x0x2"));
    private_dir(&theirs);
    mkfifo(&theirs.join("owner.pid"));
    give_to_nobody(&theirs.join("owner.pid"));
    give_to_nobody(&theirs);
    let start = Instant::now();
    let (o, pid) = run_launcher(&s, &scenario_of(&s), Some(&runs), &[]);
    assert!(o.status.success(), "{:?}", text(&o));
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "took {:?}",
        start.elapsed()
    );
    for d in [&ours, &theirs] {
        let m = fs::symlink_metadata(d.join("owner.pid"))
            .unwrap_or_else(|e| panic!("{}: {e}", d.display()));
        assert!(m.file_type().is_fifo(), "{} replaced", d.display());
    }
    assert!(
        shm_of(pid).is_empty(),
        "shared memory left: {:?}",
        shm_of(pid)
    );
}

#[test]
fn only_our_own_dead_runs_are_cleaned() {
    if !root_or_skip("only_our_own_dead_runs_are_cleaned") {
        return;
    }
    let s = Scratch::new("rd-dead");
    let runs = s.runs();
    private_dir(&runs);
    let dead = dead_pid();
    let plant_run = |n: u32| {
        let dir = runs.join(format!("{dead}x0x{n}"));
        private_dir(&dir.join("iox2/sub"));
        fs::write(dir.join("owner.pid"), format!("{dead}\n")).unwrap();
        let shm = PathBuf::from(format!("/dev/shm/uio{dead}x0x{n}_test"));
        fs::write(&shm, "x").unwrap();
        (dir, shm)
    };
    // A dead run of ours: cleaned, shared memory included (the cleanup still works).
    let (ours, ours_shm) = plant_run(3);
    // A dead run of nobody's, with shared memory of nobody's named like one of ours: left.
    let (theirs, theirs_shm) = plant_run(4);
    for p in [
        theirs.join("iox2/sub"),
        theirs.join("iox2"),
        theirs.join("owner.pid"),
        theirs.clone(),
        theirs_shm.clone(),
    ] {
        give_to_nobody(&p);
    }
    let (o, _) = run_launcher(&s, &scenario_of(&s), Some(&runs), &[]);
    let theirs_shm_left = theirs_shm.exists();
    let _ = fs::remove_file(&theirs_shm);
    let _ = fs::remove_file(&ours_shm);
    assert!(o.status.success(), "{:?}", text(&o));
    assert!(!ours.exists(), "our dead run was not cleaned");
    assert!(
        !ours_shm.exists(),
        "our dead run's shared memory was not cleaned"
    );
    assert!(
        theirs.join("iox2/sub").is_dir() && theirs.join("owner.pid").is_file(),
        "nobody's run was removed"
    );
    assert!(theirs_shm_left, "nobody's shared memory was removed");
}

#[test]
fn a_symlink_planted_as_a_run_is_neither_followed_nor_removed() {
    if !root_or_skip("a_symlink_planted_as_a_run_is_neither_followed_nor_removed") {
        return;
    }
    let s = Scratch::new("rd-entry");
    let runs = s.runs();
    private_dir(&runs);
    let dead = dead_pid();
    // The victim looks like a dead run: an owner.pid naming a dead process, an iox2 root.
    let target = s.join("victim");
    victim(&target);
    fs::create_dir(target.join("iox2")).unwrap();
    fs::write(target.join("owner.pid"), format!("{dead}\n")).unwrap();
    let links = [
        runs.join(format!("{dead}x0x5")),
        runs.join(format!(".new-{dead}x0x6")),
    ];
    for l in &links {
        std::os::unix::fs::symlink(&target, l).unwrap();
        give_to_nobody(l);
    }
    let (o, _) = run_launcher(&s, &scenario_of(&s), Some(&runs), &[]);
    assert!(o.status.success(), "{:?}", text(&o));
    assert_victim_intact(&target);
    assert!(target.join("iox2").is_dir() && target.join("owner.pid").is_file());
    for l in &links {
        assert!(
            fs::symlink_metadata(l).is_ok_and(|m| m.file_type().is_symlink()),
            "{}: not ours, yet removed",
            l.display()
        );
    }
}

#[test]
fn the_default_runs_directory_is_a_private_one_in_xdg_runtime_dir() {
    if !root_or_skip("the_default_runs_directory_is_a_private_one_in_xdg_runtime_dir") {
        return;
    }
    let s = Scratch::new("rd-xdg");
    // Deep enough that the iceoryx2 root moves to /tmp/uio-iox2-<uid>/<run>.
    let xdg = s.join("xdg");
    private_dir(&xdg);
    let (o, pid) = run_launcher(&s, &scenario_of(&s), None, &[("XDG_RUNTIME_DIR", &xdg)]);
    assert!(o.status.success(), "{:?}", text(&o));
    let runs = xdg.join("uio-observers");
    let m = fs::symlink_metadata(&runs)
        .unwrap_or_else(|e| panic!("{} was not used: {e}", runs.display()));
    assert!(
        m.is_dir() && m.uid() == 0 && m.mode() & 0o777 == 0o700,
        "mode {:o}, uid {}",
        m.mode(),
        m.uid()
    );
    let left: Vec<_> = fs::read_dir(&runs)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    assert!(left.is_empty(), "run directories left: {left:?}");
    let short: Vec<_> = fs::read_dir("/tmp/uio-iox2-0")
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name())
                .filter(|n| n.to_string_lossy().starts_with(&format!("{pid}x")))
                .collect()
        })
        .unwrap_or_default();
    assert!(short.is_empty(), "short iceoryx2 roots left: {short:?}");
    assert!(
        shm_of(pid).is_empty(),
        "shared memory left: {:?}",
        shm_of(pid)
    );
}
