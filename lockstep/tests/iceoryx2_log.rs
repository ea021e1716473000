//! iceoryx2's warnings — "No config file was loaded", which it prints when
//! it falls back to its global configuration although every run builds its own — do not reach
//! a process that joined a run's bus.

use std::sync::Mutex;

use lockstep::{Bus, RUNS_DIR_ENV, RunSpace, Wait};

static SEEN: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Keeps what iceoryx2 would print.
struct Capture;

impl iceoryx2_log::Log for Capture {
    fn log(
        &self,
        level: iceoryx2_log::LogLevel,
        origin: std::fmt::Arguments,
        message: std::fmt::Arguments,
    ) {
        SEEN.lock()
            .unwrap()
            .push(format!("{level:?} {origin}: {message}"));
    }
}

static CAPTURE: Capture = Capture;

#[test]
fn a_process_on_the_bus_shows_no_iceoryx2_warning() {
    assert!(iceoryx2::prelude::set_logger(&CAPTURE));
    let runs = std::env::temp_dir().join(format!("uio-iox2-log-{}", std::process::id()));
    // SAFETY: this test binary has one test, so no other thread reads the environment.
    unsafe {
        std::env::remove_var("IOX2_LOG_LEVEL");
        std::env::set_var(RUNS_DIR_ENV, &runs);
    }
    let space = RunSpace::create().unwrap();
    let bus = Bus::join(&space, "test", Wait::Yield).unwrap();
    // The fallback that warns when no config file exists.
    let _ = iceoryx2::config::Config::global_config();
    drop(bus);
    space.remove();
    let _ = std::fs::remove_dir_all(&runs);
    let seen = SEEN.lock().unwrap();
    assert!(
        seen.iter()
            .all(|m| !m.starts_with("Warn") && !m.starts_with("Info")),
        "{seen:?}"
    );
}
