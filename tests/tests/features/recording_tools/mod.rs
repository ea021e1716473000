//! The recording tools (inspect, compare, export, plot) on clean and damaged recordings.

mod damaged;
mod damaged_fuzz;
mod plot;
mod tools;
