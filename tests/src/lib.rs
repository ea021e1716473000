//! Helpers for tests that run the real binaries: where they are, a private directory per test,
//! and checks that a run left no process and no shared memory behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

pub use recording::{Recording, Series, read};

/// The directory holding the built binaries (next to this test executable's `deps/`).
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>")
        .to_path_buf();
    for b in [
        "uio-launcher",
        "uio-plant",
        "uio-observer",
        "uio-controller",
    ] {
        assert!(
            dir.join(b).is_file(),
            "{} is missing: build the workspace binaries first (cargo test --release --workspace builds them)",
            dir.join(b).display()
        );
    }
    dir
}

/// The repository root. `cargo test` sets `CARGO_MANIFEST_DIR` at run time too; preferring it
/// keeps a test binary built in another checkout (a shared target directory) on this one.
pub fn repo() -> PathBuf {
    let dir = std::env::var_os("CARGO_MANIFEST_DIR")
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")), PathBuf::from);
    dir.parent().expect("workspace root").to_path_buf()
}

/// A shipped scenario.
pub fn scenario(name: &str) -> PathBuf {
    repo().join("scenarios").join(format!("{name}.toml"))
}

/// A fresh empty directory under the system temp dir, removed by [`Scratch::drop`].
pub struct Scratch(pub PathBuf);

impl Scratch {
    /// Creates one, named after `tag`.
    pub fn new(tag: &str) -> Self {
        static N: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "uio-test-{}-{}-{tag}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    /// A path inside.
    pub fn join(&self, p: &str) -> PathBuf {
        self.0.join(p)
    }

    /// The runs directory the launcher is pointed at.
    pub fn runs(&self) -> PathBuf {
        self.0.join("iox-runs")
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A launcher command whose runs live in `scratch`. The Python environment that
/// `scripts/test.sh` makes (`.venv/`, with the Python kit) comes first in its `PATH`, so the
/// Python components' `python3` finds the kit under plain `cargo test` too.
pub fn launcher(scratch: &Scratch) -> Command {
    let mut c = Command::new(bin_dir().join("uio-launcher"));
    c.env(lockstep_runs_env(), scratch.runs())
        .current_dir(&scratch.0);
    let venv = std::env::var_os("UIO_VENV")
        .map_or_else(|| repo().join(".venv"), std::path::PathBuf::from)
        .join("bin");
    if venv.is_dir() {
        let path = std::env::var_os("PATH").unwrap_or_default();
        let joined =
            std::env::join_paths(std::iter::once(venv).chain(std::env::split_paths(&path)))
                .expect("PATH entries");
        c.env("PATH", joined);
    }
    c
}

/// The environment variable naming the runs directory.
pub fn lockstep_runs_env() -> &'static str {
    "UIO_RUNS_DIR"
}

/// Runs `uio-launcher run <scenario> --out <scratch>/out` with extra args; returns the output.
pub fn run(scratch: &Scratch, scenario: &Path, extra: &[&str]) -> Output {
    launcher(scratch)
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(scratch.join("out"))
        .args(extra)
        .output()
        .expect("launcher starts")
}

/// Text of stdout and stderr.
pub fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// A JSON list of [re, im] pairs (as `lti::re_im` writes poles and eigenvalues) as complex
/// numbers.
pub fn complex_list(v: &serde_json::Value) -> Vec<lti::C64> {
    v.as_array()
        .expect("a list of [re, im]")
        .iter()
        .map(|z| lti::C64::new(z[0].as_f64().unwrap(), z[1].as_f64().unwrap()))
        .collect()
}

/// The summary a run wrote.
pub fn summary(scratch: &Scratch, name: &str) -> serde_json::Value {
    let p = scratch.join("out").join(format!("{name}.summary.json"));
    serde_json::from_str(
        &std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())),
    )
    .unwrap()
}

/// Shared-memory files of runs of launcher `pid`.
pub fn shm_of(pid: u32) -> Vec<String> {
    let prefix = format!("uio{pid}x");
    std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(&prefix))
                .collect()
        })
        .unwrap_or_default()
}

/// Processes of a run of launcher `pid`: our components (their command line names the run) and
/// external ones and whatever they started (their environment holds `UIO_RUN=<run>`, inherited
/// by their children).
pub fn processes_of(pid: u32) -> Vec<String> {
    let (arg, env) = (format!("--run\0{pid}x"), format!("UIO_RUN={pid}x"));
    let mut found = Vec::new();
    for e in std::fs::read_dir("/proc").into_iter().flatten().flatten() {
        let cmd = std::fs::read(e.path().join("cmdline"))
            .map(|c| String::from_utf8_lossy(&c).into_owned())
            .unwrap_or_default();
        let environ = std::fs::read(e.path().join("environ"))
            .map(|c| String::from_utf8_lossy(&c).into_owned())
            .unwrap_or_default();
        if cmd.contains(&arg) || environ.split('\0').any(|v| v.starts_with(&env)) {
            found.push(format!(
                "{}: {}",
                e.file_name().to_string_lossy(),
                cmd.replace('\0', " ")
            ));
        }
    }
    found
}

/// Asserts a finished launcher `pid` left nothing behind in `scratch`, /dev/shm or /proc.
pub fn assert_clean(scratch: &Scratch, pid: u32) {
    let procs = processes_of(pid);
    assert!(procs.is_empty(), "processes left behind: {procs:?}");
    let shm = shm_of(pid);
    assert!(shm.is_empty(), "shared memory left behind: {shm:?}");
    let runs: Vec<_> = std::fs::read_dir(scratch.runs())
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    assert!(runs.is_empty(), "run directories left behind: {runs:?}");
}

/// Every series except latency (which is timing, not trajectory).
pub fn trajectories(r: &Recording) -> Vec<(&String, &Series)> {
    r.series
        .iter()
        .filter(|(k, _)| !k.starts_with("/latency"))
        .collect()
}

/// The pid of a component of launcher `launcher_pid` named `name`: by its `--run` and `--name`
/// arguments (ours), or by the `UIO_RUN` and `UIO_NAME` every component is started with
/// (PROTOCOL.md §1), which is all an external command gets.
pub fn component_pid(launcher_pid: u32, name: &str) -> Option<i32> {
    let (run, named) = (
        format!("--run\0{launcher_pid}x"),
        format!("--name\0{name}\0"),
    );
    let (run_env, name_env) = (
        format!("UIO_RUN={launcher_pid}x"),
        format!("UIO_NAME={name}"),
    );
    for e in std::fs::read_dir("/proc").ok()?.flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let read = |f: &str| {
            std::fs::read(e.path().join(f))
                .map(|c| String::from_utf8_lossy(&c).into_owned())
                .unwrap_or_default()
        };
        let cmd = read("cmdline");
        if cmd.contains(&run) && cmd.contains(&named) {
            return Some(pid);
        }
        let environ = read("environ");
        if environ.split('\0').any(|v| v.starts_with(&run_env))
            && environ.split('\0').any(|v| v == name_env)
        {
            return Some(pid);
        }
    }
    None
}

/// Waits until every named component of launcher `launcher_pid` is up, and a little longer.
pub fn wait_running(launcher_pid: u32, names: &[&str]) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    while names
        .iter()
        .any(|n| component_pid(launcher_pid, n).is_none())
    {
        assert!(
            std::time::Instant::now() < deadline,
            "components did not start"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    std::thread::sleep(std::time::Duration::from_millis(100));
}

/// Waits until the recording being written (`<out>/<name>.rrd.partial`) grows past what it
/// held when it appeared: its writer has sent a batch of steps, so the run is stepping — its
/// components said ready. A test that stops a component or the launcher "mid-run" waits for
/// this: only having seen the processes, it may stop one before the run began (a loaded
/// machine can take that long to start them), which is another failure with another message.
pub fn wait_stepping(partial: &Path) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let size = || std::fs::metadata(partial).map(|m| m.len()).ok();
    let first = loop {
        if let Some(n) = size() {
            break n;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "{} did not appear",
            partial.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    while size().is_some_and(|n| n <= first) {
        assert!(
            std::time::Instant::now() < deadline,
            "{} did not grow",
            partial.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// Sends `sig` to `pid` (a process the test started).
pub fn signal(pid: i32, sig: i32) {
    // SAFETY: kill(2) with a pid and signal number; no memory is shared.
    unsafe { libc::kill(pid, sig) };
}

/// A shipped scenario rewritten for a test: `duration` replaced, `[expect]` kept or dropped.
pub fn variant(s: &Scratch, name: &str, seconds: f64, keep_expect: bool) -> PathBuf {
    let text = std::fs::read_to_string(scenario(name)).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with("duration") {
            out += &format!("duration = {seconds:?}\n");
        } else {
            out += line;
            out += "\n";
        }
    }
    if !keep_expect {
        out = out.split("\n[expect]").next().unwrap().to_string();
    }
    let p = s.join(&format!("{name}-{seconds}.toml"));
    std::fs::write(&p, out).unwrap();
    p
}

/// Runs `uio-launcher run <path> --out <scratch>/out <args>`; returns its exit code, its stderr and
/// how long it took, and asserts that it left nothing behind (processes, shared memory).
pub fn run_checked(
    s: &Scratch,
    path: &Path,
    args: &[&str],
) -> (Option<i32>, String, std::time::Duration) {
    let started = std::time::Instant::now();
    let child = launcher(s)
        .arg("run")
        .arg(path)
        .arg("--out")
        .arg(s.join("out"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let out = child.wait_with_output().unwrap();
    let took = started.elapsed();
    assert_clean(s, pid);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        took,
    )
}

/// Reports a test that cannot run here as skipped, and why. The caller returns right after:
/// libtest has no run-time skip, so the test counts as passed in cargo's own line, and the test
/// command subtracts these lines (`skipped: <test>: <reason>`) from it and counts them apart.
/// The line goes to the process's stderr directly, past libtest's capture of `eprintln!`, so
/// that it is seen whether or not the test passes.
pub fn skip(test: &str, reason: &str) {
    use std::io::Write;
    let line = format!("skipped: {test}: {reason}\n");
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}
