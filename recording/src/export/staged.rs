//! Writing a file under a temporary name beside its target and renaming it into place once
//! complete: the workspace's one way to write an output (crate `outputs`: a new regular file at
//! an unpredictable name, never through a planted link), re-exported for the exports.

pub use outputs::{cannot_write, write};
