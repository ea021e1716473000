//! Scenario files and other input: bad input refused with one line and its exit code, limits, .npy bounds, the README's and docs' examples.

mod bad_input;
mod limits;
mod npy_bounds;
mod readme;
