//! Runs in both modes, bit-identical: the shipped scenarios, sizes, initial estimates, operating points, invariant zeros, the command line.

mod cli;
mod end_to_end;
mod initial_estimate;
mod invariant_zeros;
mod operating_point;
mod scenarios;
mod sizes;
