//! The component kit: a component is a type with a step function, and its `main` is one line.
//!
//! ```ignore
//! struct Gain(f64);
//! impl Component for Gain {
//!     fn new(cfg: &ComponentConfig) -> Result<Self, String> { Ok(Gain(cfg.params::<f64>()?)) }
//!     fn step(&mut self, _k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError> {
//!         for (o, x) in out.iter_mut().zip(inputs.get(0)) { *o = self.0 * x; }
//!         Ok(())
//!     }
//! }
//! fn main() -> std::process::ExitCode { lockstep::component::main::<Gain>("gain") }
//! ```
//!
//! [`main`] does what PROTOCOL.md asks of every component — checks how it was started, reads
//! `$UIO_CONFIG`, joins the run's iceoryx2 world, creates the ports, `ready`/`go`, steps in the
//! order of §5, sends the plant's end sample — and turns a failure into one line on stderr and
//! an exit code. Our own plant, observer and controller are written this way.

mod config;
mod runner;

use std::process::ExitCode;

pub use config::{ComponentConfig, Iceoryx2Place, PublishSpec, ReadSpec, Role};
pub use runner::{Inputs, Runner};

use crate::error::LockstepError;
use crate::handshake::{EXIT_USAGE, die_with_parent, parse_launch, ready_then_wait_for_go};
use crate::port::Bus;
use crate::sample::PROTOCOL_VERSION;

/// Exit code: the component failed (transport, configuration, its own step).
pub const EXIT_FAILED: i32 = 3;

/// A participant of a run.
pub trait Component: Sized {
    /// Builds the component from its configuration (`params` holds what the scenario, or the
    /// launcher's design, gave it).
    fn new(cfg: &ComponentConfig) -> Result<Self, String>;

    /// Step k. `inputs` holds the latest samples of the services it reads, in `reads` order:
    /// for the plant those of step k − 1 (zeros at k = 0), for the others those of step k.
    /// `out` receives its sample of step k (the plant also gets k = K, its end sample).
    fn step(&mut self, k: u64, inputs: &Inputs, out: &mut [f64]) -> Result<(), StepError>;
}

/// Why a step failed, with the exit code the process ends with.
#[derive(Debug, Clone, PartialEq)]
pub struct StepError {
    /// Process exit code.
    pub code: i32,
    /// One line.
    pub message: String,
}

impl StepError {
    /// A failure with [`EXIT_FAILED`].
    pub fn failed(message: impl Into<String>) -> Self {
        StepError {
            code: EXIT_FAILED,
            message: message.into(),
        }
    }

    /// A transport failure.
    pub fn transport(e: LockstepError) -> Self {
        StepError::failed(e.to_string())
    }
}

/// Reads the configuration a launched component was given (`$UIO_CONFIG`), refusing one of
/// another protocol version.
pub fn read_config() -> Result<ComponentConfig, String> {
    match std::env::var("UIO_PROTOCOL") {
        Ok(v) if v.trim() == PROTOCOL_VERSION.to_string() => {}
        Ok(v) => {
            return Err(format!(
                "the run speaks protocol version {v}, this component {PROTOCOL_VERSION}"
            ));
        }
        Err(_) => {
            return Err("UIO_PROTOCOL is not set: components are started by the launcher".into());
        }
    }
    let path = std::env::var_os("UIO_CONFIG").ok_or("UIO_CONFIG is not set")?;
    let text =
        std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.to_string_lossy()))?;
    let cfg: ComponentConfig =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.to_string_lossy()))?;
    if cfg.protocol != PROTOCOL_VERSION {
        return Err(format!(
            "configuration of protocol version {}, this component speaks {PROTOCOL_VERSION}",
            cfg.protocol
        ));
    }
    Ok(cfg)
}

/// The whole life of a component process of type `C`; `kind` names it in messages when it was
/// started the wrong way.
pub fn main<C: Component>(kind: &str) -> ExitCode {
    main_with_args::<C>(kind, std::env::args().skip(1))
}

/// [`main`] with the command-line arguments given (the launcher's `component` fallback).
pub fn main_with_args<C: Component>(
    kind: &str,
    args: impl IntoIterator<Item = String>,
) -> ExitCode {
    ExitCode::from(exit_status::<C>(kind, args) as u8)
}

/// [`main_with_args`] as the process's exit status, for a component that must end its
/// process itself (`_exit`: an FMU plant whose libraries must not run their exit handlers).
pub fn exit_status<C: Component>(kind: &str, args: impl IntoIterator<Item = String>) -> i32 {
    die_with_parent();
    let launch = match parse_launch(kind, args) {
        Ok(l) => l,
        Err(msg) => {
            eprintln!("{msg}");
            return EXIT_USAGE;
        }
    };
    let label = if launch.name == kind {
        kind.to_string()
    } else {
        format!("{kind} {}", launch.name)
    };
    let cfg = match read_config() {
        Ok(c) => c,
        Err(msg) => {
            eprintln!("{label}: {msg}");
            return EXIT_USAGE;
        }
    };
    match live::<C>(&launch, &cfg) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("{label}: {}", e.message);
            e.code
        }
    }
}

fn live<C: Component>(launch: &crate::Launch, cfg: &ComponentConfig) -> Result<(), StepError> {
    let comp = C::new(cfg).map_err(|e| StepError::failed(format!("configuration: {e}")))?;
    let wait = cfg
        .wait
        .parse()
        .map_err(|e| StepError::failed(format!("configuration: wait: {e}")))?;
    let bus = Bus::join(&launch.run, &cfg.name, wait).map_err(StepError::transport)?;
    let mut runner = Runner::new(cfg, &bus, comp).map_err(StepError::transport)?;
    ready_then_wait_for_go().map_err(StepError::transport)?;
    // stdout was the handshake's; from here on what a component prints goes to stderr.
    // SAFETY: dup2 of the process's own standard descriptors.
    unsafe { libc::dup2(libc::STDERR_FILENO, libc::STDOUT_FILENO) };
    for k in 0..cfg.steps {
        runner.step(k)?;
    }
    runner.finish()
}
