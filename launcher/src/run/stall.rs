//! When a run that makes no progress is looked at.

use std::time::Duration;

/// How long the run may make no progress before the component it waits for is looked at: named
/// at once when the kernel has it stopped or blocked; waited for, up to the scenario's stall
/// limit, when it runs or waits for a core (`processes::liveness`).
pub const STALL_BLOCKED: Duration = Duration::from_secs(5);
