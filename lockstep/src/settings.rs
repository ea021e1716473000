//! The service settings every port of a run opens with (PROTOCOL.md §4): a component in any
//! language must use the same, or opening a service fails.

/// Publishers per service: the one component that owns it.
pub const MAX_PUBLISHERS: usize = 1;
/// Subscribers per service: the launcher's recorder and the components that read it.
pub const MAX_SUBSCRIBERS: usize = 8;
/// Nodes per service.
pub const MAX_NODES: usize = 16;
/// Samples kept for late subscribers: none (every subscriber exists before `go`).
pub const HISTORY: usize = 0;
/// How many steps an observer the controller does not read may trail the plant.
pub const FOLLOWER_LAG: u64 = 4096;
/// Buffer of a lockstep subscriber: a trailing input queues up to [`FOLLOWER_LAG`] samples.
pub const LOCKSTEP_BUFFER: usize = FOLLOWER_LAG as usize + 2;
/// Buffer of the recorder's subscribers: how many steps the launcher may lag behind.
pub const RECORDER_BUFFER: usize = 4096;
/// The largest subscriber buffer a service allows.
pub const SUBSCRIBER_MAX_BUFFER: usize = if RECORDER_BUFFER > LOCKSTEP_BUFFER {
    RECORDER_BUFFER
} else {
    LOCKSTEP_BUFFER
};
/// Notifiers per `<service>/wake` event service.
pub const MAX_NOTIFIERS: usize = 1;
/// Listeners per `<service>/wake` event service.
pub const MAX_LISTENERS: usize = 8;
