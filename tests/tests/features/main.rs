//! The integration tests, by feature, in one binary: one link of the launcher, Rerun and the
//! rest instead of one per file (31 binaries before, 5.5 GB of them). Each feature is a folder
//! of modules (ARCHITECTURE.md, "Where the tests are"). Apart, in binaries of their own:
//! `no_alloc.rs` (a counting global allocator for the whole process), `realtime.rs` and
//! `bench.rs` (pace and speed: no other feature's runs share their two cores), `two_hosts.rs`
//! (network namespaces and their agents).

mod design;
mod diagnosis;
mod input;
mod recording_tools;
mod runs;
mod security;
mod supervision;
