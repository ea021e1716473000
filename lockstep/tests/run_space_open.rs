//! A component opening its run (`RunSpace::open`) refuses a runs directory or
//! run directory that is a symlink, and an `owner.pid` that is not a regular file — a FIFO is
//! refused without blocking.

use std::ffi::CString;
use std::os::unix::ffi::OsStrExt;
use std::time::{Duration, Instant};

use lockstep::{RUNS_DIR_ENV, RunSpace};

#[test]
fn open_refuses_symlinks_and_a_fifo_owner() {
    let scratch = std::env::temp_dir().join(format!("uio-open-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&scratch);
    std::fs::create_dir(&scratch).unwrap();
    let runs = scratch.join("runs");
    // SAFETY: this test binary has one test, so no other thread reads the environment.
    unsafe { std::env::set_var(RUNS_DIR_ENV, &runs) };
    let space = RunSpace::create().unwrap();
    RunSpace::open(space.id()).expect("a run the launcher made opens");

    // A run directory that is a symlink to a real run.
    std::os::unix::fs::symlink(space.dir(), runs.join("999999x0x1")).unwrap();
    let e = RunSpace::open("999999x0x1").unwrap_err().to_string();
    assert!(e.contains("refusing") && e.contains("999999x0x1"), "{e}");

    // A run whose owner.pid is a FIFO: refused at once, not a blocked open.
    std::fs::create_dir(runs.join("999999x0x2")).unwrap();
    let fifo = CString::new(runs.join("999999x0x2/owner.pid").as_os_str().as_bytes()).unwrap();
    // SAFETY: a valid path.
    assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
    let t = Instant::now();
    let e = RunSpace::open("999999x0x2").unwrap_err().to_string();
    assert!(
        t.elapsed() < Duration::from_secs(2) && e.contains("owner.pid") && e.contains("refusing"),
        "{e}"
    );

    // The runs directory itself a symlink to the real one.
    std::os::unix::fs::symlink(&runs, scratch.join("link")).unwrap();
    // SAFETY: as above.
    unsafe { std::env::set_var(RUNS_DIR_ENV, scratch.join("link")) };
    let e = RunSpace::open(space.id()).unwrap_err().to_string();
    assert!(
        e.contains("is a symbolic link") && e.contains("link"),
        "{e}"
    );

    // SAFETY: as above.
    unsafe { std::env::set_var(RUNS_DIR_ENV, &runs) };
    space.remove();
    assert!(!space.dir().exists());
    std::fs::remove_dir_all(&scratch).unwrap();
}
