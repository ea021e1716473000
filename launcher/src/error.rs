//! The launcher's failures and their exit codes.

use thiserror::Error;

use scenario::ScenarioError;

/// Exit code: `compare` found the recordings differ.
pub const EXIT_DIFFER: i32 = 1;
/// Exit code: bad input (scenario, unmet condition, refused unstable loop, output in the way).
pub const EXIT_BAD_INPUT: i32 = 2;
/// Exit code: a component crashed or the transport failed.
pub const EXIT_COMPONENT: i32 = 3;
/// Exit code: the run stopped because a state diverged.
pub const EXIT_DIVERGED: i32 = 4;
/// Exit code: the run finished but missed its `[expect]` table.
pub const EXIT_EXPECT: i32 = 5;
/// Exit code: a recording read back does not match the digest written with it.
pub const EXIT_DAMAGED: i32 = 6;
/// Exit code: interrupted by SIGINT or SIGTERM (SIGHUP gives 129, SIGQUIT 131).
pub const EXIT_INTERRUPTED: i32 = 130;

/// Why the launcher stopped.
#[derive(Debug, Error)]
pub enum LaunchError {
    /// The scenario file is wrong.
    #[error("{0}")]
    Scenario(#[from] ScenarioError),
    /// Input that is not a scenario field: output directory, existing recording, refused loop.
    #[error("{0}")]
    BadInput(String),
    /// A component failed.
    #[error("{0}")]
    Component(String),
    /// A state left its bound or became non-finite.
    #[error("{0}")]
    Diverged(String),
    /// The run missed its expectations.
    #[error("{0}")]
    Expect(String),
    /// A recording is damaged.
    #[error("{0}")]
    Damaged(String),
    /// SIGINT, SIGTERM, SIGHUP or SIGQUIT.
    #[error("{0}")]
    Interrupted(String),
}

impl LaunchError {
    /// The process exit code.
    pub fn exit_code(&self) -> i32 {
        match self {
            LaunchError::Scenario(_) | LaunchError::BadInput(_) => EXIT_BAD_INPUT,
            LaunchError::Component(_) => EXIT_COMPONENT,
            LaunchError::Diverged(_) => EXIT_DIVERGED,
            LaunchError::Expect(_) => EXIT_EXPECT,
            LaunchError::Damaged(_) => EXIT_DAMAGED,
            LaunchError::Interrupted(_) => crate::run::interrupt::exit_code(),
        }
    }
}
