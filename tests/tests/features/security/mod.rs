//! Run directories no other user can turn against their owner.

mod run_dirs;
