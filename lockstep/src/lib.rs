//! The lockstep transport: sample types, service names and the per-step protocol over iceoryx2
//! publish–subscribe, shared by the plant, observer and controller processes and the launcher.
//!
//! ## Protocol
//!
//! PROTOCOL.md (at the repository's root) is the whole contract; this is its summary. Every run
//! has its own iceoryx2 prefix and root directory ([`RunSpace`]), so runs never meet. Each
//! component publishes one sample — a [`WireHeader`] and a slice of values whose length the
//! run's configuration fixes — per step on its own service and waits for exactly the samples of
//! the same step from the services it reads:
//!
//! ```text
//! plant:       publish y_k ─▶ wait x̂_k of every observer, and u_k of the controller ─▶ x_{k+1}
//! observer i:  wait y_k    ─▶ x̂_k = step(y_k, u_{k−1}) ─▶ publish x̂_k
//! controller:  wait x̂_k of its observer ─▶ u_k = N r_k − G x̂_k ─▶ publish u_k
//! ```
//!
//! A sample whose step counter is not the one expected is an error ([`LockstepError::Step`]).
//! In closed loop only the controller's observer is on the critical path; the other observers
//! ("followers") take exactly the same samples in the same order but may trail the plant by up
//! to [`FOLLOWER_LAG`] steps, so they can sleep between batches instead of competing for a core
//! every step. Without a controller every observer completes each step before the next.
//! No first sample is lost: components create all their ports, report "ready" to the launcher,
//! and publish only after the launcher's "go", when every subscriber already exists.
//! The launcher records every sample from its own subscribers, whose large buffers and the
//! publishers' retry-until-delivered back-pressure mean no sample is ever dropped. A component
//! is written with the kit in [`component`]: a step function and a one-line `main`.

mod clock;
pub mod component;
mod error;
mod handshake;
mod layout;
mod port;
pub mod private_shm;
pub mod programs;
mod quiet;
mod run;
mod run_dir;
mod sample;
pub mod service;
pub mod settings;
mod wait;

pub use clock::{now_ns, sleep_until_ns, tight_timers};
pub use error::LockstepError;
pub use handshake::{EXIT_USAGE, Launch, die_with_parent, parse_launch, ready_then_wait_for_go};
pub use layout::PlantLayout;
pub use port::{Bus, FOLLOWER_LAG, Inlet, Outlet, RECORDER_BUFFER, Reader};
pub use quiet::quiet_iceoryx2;
pub use run::{RUNS_DIR_ENV, RunSpace, cleanup_dead_runs, iox2_root, prepare_runs_dir};
pub use run_dir::is_run_id;
pub use sample::{Header, PROTOCOL_VERSION, WireHeader};
pub use wait::Wait;
