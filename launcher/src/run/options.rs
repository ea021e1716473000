//! How to run (where the components run, what is recorded, pacing) and how a run ended.

use std::path::{Path, PathBuf};

use lockstep::Wait;

/// Where the components run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// One process per component, over iceoryx2.
    Processes,
    /// All step functions in the launcher's process.
    InProcess,
}

impl Mode {
    /// "processes" or "in-process".
    pub fn name(self) -> &'static str {
        match self {
            Mode::Processes => "processes",
            Mode::InProcess => "in-process",
        }
    }
}

/// How to run.
#[derive(Debug, Clone)]
pub struct Options {
    /// Output directory.
    pub out: PathBuf,
    /// Where the components run.
    pub mode: Mode,
    /// Wait strategy of the components.
    pub wait: Wait,
    /// Overwrite an existing recording.
    pub force: bool,
    /// Run a scenario whose closed loop is unstable.
    pub allow_unstable: bool,
    /// Write the `.rrd` (off for benchmarks).
    pub record: bool,
    /// Place the lockstep ring's processes on CPUs (processes mode).
    pub pin: bool,
    /// Which steps and entities are written to the recording (`--record-every`, `--record`).
    pub select: recording::write::Selection,
    /// Show a progress bar on a terminal (not in benchmarks: it would disturb their timing).
    pub progress: bool,
    /// Real-time pacing at this speed (`--realtime --speed X`): step k starts at k·dt/X.
    pub realtime: Option<f64>,
}

impl Options {
    /// A run of the launcher's own (benchmarks, sweeps, calibration): no progress bar, no
    /// pacing, the whole run recorded (when `record`) over whatever `out` holds.
    pub fn quiet(out: &Path, mode: Mode, wait: Wait, record: bool) -> Self {
        Options {
            out: out.to_path_buf(),
            mode,
            wait,
            force: true,
            allow_unstable: false,
            record,
            pin: false,
            select: recording::write::Selection::default(),
            progress: false,
            realtime: None,
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Stop {
    /// Every step done.
    Completed,
    /// A state left its bound or became non-finite.
    Diverged(String),
    /// SIGINT or SIGTERM.
    Interrupted(&'static str),
    /// A component failed.
    Failed(String),
}
