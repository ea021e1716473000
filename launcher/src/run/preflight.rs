//! Before a run whose plant is one of our data- or FMU-reading components: the component that
//! will read the file (`uio-fmu-plant --check`, `uio-replay-plant --check`) reads it against the
//! scenario's map, so that a bad file is refused with exit 2 and one line before any process,
//! shared memory or output exists.
//!
//! - `[plant.fmu]`: the archive and model description (not the FMU's library: what that does
//!   when called is the run's to see) — not a zip, no `modelDescription.xml`, model exchange
//!   only, no binary for this platform, a variable that is not there or of the wrong kind.
//! - `[plant.replay]`: the whole data file with the scenario's column map and grid — a missing
//!   column, a non-finite cell, time stamps that go back or off the grid, too few rows, an
//!   `.rrd` of another plant. What it says of the data (rows, held rows, whether x is in it)
//!   goes to the summary.

use std::io::{Read, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use scenario::{FMU_PLANT_PROGRAM, REPLAY_PLANT_PROGRAM, Scenario};

use crate::error::LaunchError;

/// Exit 2 with `uio-fmu-plant`'s one line when the FMU cannot be this scenario's plant.
pub fn fmu(s: &Scenario) -> Result<(), LaunchError> {
    let (Some(_), Some(spec)) = (&s.plant_fmu, &s.plant_process) else {
        return Ok(());
    };
    // Its lines name the field (plant.fmu.inputs[2] …) themselves.
    check(
        s,
        ["plant.fmu: ", ""],
        FMU_PLANT_PROGRAM,
        "fmu-plant",
        &spec.params,
    )
    .map(drop)
}

/// The facts `uio-replay-plant --check` reports, or exit 2 with its one line when the data cannot
/// be this scenario's plant.
pub fn replay(s: &Scenario) -> Result<Option<serde_json::Value>, LaunchError> {
    let (Some(_), Some(spec)) = (&s.plant_replay, &s.plant_process) else {
        return Ok(None);
    };
    let out = check(
        s,
        ["plant.replay: "; 2],
        REPLAY_PLANT_PROGRAM,
        "replay",
        &spec.params,
    )?;
    let facts = serde_json::from_slice(&out).map_err(|e| {
        LaunchError::BadInput(format!(
            "{}: plant.replay: {REPLAY_PLANT_PROGRAM} --check: its report: {e}",
            s.path.display()
        ))
    })?;
    Ok(Some(facts))
}

/// How long a `--check` may take: reading a file against a map is seconds even for the largest
/// logs the caps allow; a hostile file must not hold the launcher longer.
pub const CHECK_TIMEOUT: Duration = Duration::from_secs(120);

/// How long `uio-fmu-plant --linearize` may take (2(n + l + q) + 1 FMU simulations of one sample
/// each, twice for Richardson's extrapolation, and the trim's Newton steps).
pub const LINEARIZE_TIMEOUT: Duration = Duration::from_secs(1800);

/// The address space a sibling may map (8 GiB of the machine's 24): an allocation a hostile
/// file asks for fails in the child instead of taking the machine's memory.
pub const SIBLING_ADDRESS_SPACE: u64 = 8 << 30;

/// The most a sibling's stdout or stderr is read (beyond: discarded): a report, not a log.
const SIBLING_OUTPUT: u64 = 16 << 20;

/// `program --check` (a kit component built beside the launcher, of cargo package `package`)
/// with `params` on stdin: its stdout, or its last line on stderr as bad input. `field` heads
/// this function's own messages and the component's line.
fn check(
    s: &Scenario,
    field: [&str; 2],
    program: &str,
    package: &str,
    params: &serde_json::Value,
) -> Result<Vec<u8>, LaunchError> {
    sibling(
        &s.path,
        field,
        program,
        "--check",
        package,
        params,
        check_timeout()?,
    )
}

/// Environment variable that sets the `--check` limit, in whole seconds (1 to 3600): a log at
/// the caps on a slow disk may need more than [`CHECK_TIMEOUT`].
pub const CHECK_TIMEOUT_ENV: &str = "UIO_CHECK_TIMEOUT";

fn check_timeout() -> Result<Duration, LaunchError> {
    let Some(v) = std::env::var_os(CHECK_TIMEOUT_ENV) else {
        return Ok(CHECK_TIMEOUT);
    };
    match v.to_str().and_then(|t| t.trim().parse::<u64>().ok()) {
        Some(secs @ 1..=3600) => Ok(Duration::from_secs(secs)),
        _ => Err(LaunchError::BadInput(format!(
            "{CHECK_TIMEOUT_ENV}={}: the pre-flight limit is a whole number of seconds from 1 to 3600",
            scenario::untrusted::quoted(&v.to_string_lossy())
        ))),
    }
}

/// `program flag` (a kit component built beside the launcher, of cargo package `package`) with
/// `input` as JSON on stdin: its stdout, or its reason on stderr as bad input of `file`.
/// `field` heads this function's own messages and the component's line. `--check` here, and
/// `uio-fmu-plant --linearize` for `uio-launcher linearize`.
///
/// The child runs in a process group of its own with its address space capped
/// ([`SIBLING_ADDRESS_SPACE`]); past `timeout`, or on SIGINT/SIGTERM/SIGHUP/SIGQUIT to the
/// launcher, the whole group is killed and waited for, so nothing is left spinning.
pub fn sibling(
    file: &std::path::Path,
    field: [&str; 2],
    program: &str,
    flag: &str,
    package: &str,
    input: &serde_json::Value,
    timeout: Duration,
) -> Result<Vec<u8>, LaunchError> {
    use std::os::unix::process::CommandExt;
    let exe = std::env::current_exe()
        .unwrap_or_else(|_| lockstep::programs::LAUNCHER.into())
        .with_file_name(program);
    let path = if exe.is_file() { exe } else { program.into() };
    let bad = |why: String| LaunchError::BadInput(format!("{}: {}{why}", file.display(), field[0]));
    super::interrupt::install();
    let mut command = Command::new(&path);
    command
        .arg(flag)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0);
    // SAFETY: setrlimit and prctl are async-signal-safe; nothing else runs between fork and
    // exec. Out of the terminal's process group, the child dies with the launcher instead
    // (PR_SET_PDEATHSIG), as the run's components do.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: SIBLING_ADDRESS_SPACE,
                rlim_max: SIBLING_ADDRESS_SPACE,
            };
            libc::setrlimit(libc::RLIMIT_AS, &limit);
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
            Ok(())
        });
    }
    let mut child = command.spawn().map_err(|e| {
        bad(format!(
            "cannot start {program} ({e}); it is built with `cargo build --release -p {package}`"
        ))
    })?;
    let text = serde_json::to_string(input).expect("serialises");
    let mut stdin = child.stdin.take().expect("piped");
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut out = Vec::new();
            if let Some(p) = pipe {
                let mut p = p.take(SIBLING_OUTPUT);
                let _ = p.read_to_end(&mut out);
                let _ = std::io::copy(&mut p.into_inner(), &mut std::io::sink());
            }
            out
        })
    };
    let stdout = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let stderr = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let writer = std::thread::spawn(move || stdin.write_all(text.as_bytes()));
    let start = Instant::now();
    let stopped = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Ok(status),
            Ok(None) => {}
            Err(e) => break Err(bad(format!("{program} {flag}: {e}"))),
        }
        let why = if let Some(sig) = super::interrupt::received() {
            Some(LaunchError::Interrupted(format!(
                "{}: interrupted by {sig} during {program} {flag}; it was stopped",
                file.display()
            )))
        } else if start.elapsed() > timeout {
            Some(bad(format!(
                "{program} {flag} did not answer within {} s; it was stopped",
                timeout.as_secs()
            )))
        } else {
            None
        };
        if let Some(why) = why {
            // SAFETY: the child leads its own group (process_group(0)); kill it whole.
            unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
            let _ = child.wait();
            break Err(why);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let _ = writer.join();
    let (out, err) = (
        stdout.join().unwrap_or_default(),
        stderr.join().unwrap_or_default(),
    );
    let status = stopped?;
    if status.success() {
        return Ok(out);
    }
    let said = String::from_utf8_lossy(&err);
    match reason(&said) {
        Some(line) => Err(LaunchError::BadInput(format!(
            "{}: {}{line}",
            file.display(),
            field[1]
        ))),
        None => Err(bad(format!("{program} {flag} failed ({status})"))),
    }
}

/// What a failed sibling said: the reason of a panic (the line after "panicked at", not the
/// backtrace note that ends it), an allocation that failed, or its last line.
fn reason(stderr: &str) -> Option<String> {
    let lines: Vec<&str> = stderr
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    if let Some(i) = lines.iter().position(|l| l.contains("panicked at")) {
        return Some(format!(
            "{} crashed: {}",
            lines[i].split(" panicked").next().unwrap_or("it"),
            lines.get(i + 1).copied().unwrap_or(lines[i])
        ));
    }
    if let Some(l) = lines.iter().find(|l| l.starts_with("memory allocation of")) {
        return Some(format!(
            "{l} (its address space is capped at {} GiB)",
            SIBLING_ADDRESS_SPACE >> 30
        ));
    }
    lines.last().map(|l| l.to_string())
}

#[cfg(test)]
mod tests {
    use super::reason;

    #[test]
    fn a_panic_is_reported_by_its_reason_not_the_backtrace_note() {
        let said = "thread 'main' (12) panicked at replay/src/mcap.rs:10:5:\nindex out of bounds\nnote: run with `RUST_BACKTRACE=1` environment variable to display a backtrace\n";
        assert_eq!(
            reason(said).unwrap(),
            "thread 'main' (12) crashed: index out of bounds"
        );
        assert!(
            reason("memory allocation of 1099511627785 bytes failed\n")
                .unwrap()
                .contains("capped at 8 GiB")
        );
        assert_eq!(
            reason("a\nplant.replay: no column 'x'\n\n").unwrap(),
            "plant.replay: no column 'x'"
        );
        assert_eq!(reason(""), None);
    }
}
