//! `uio-launcher design`: every condition with its value and verdict, the design matrices under the
//! papers' names, the observer and closed-loop eigenvalues (continuous and sampled), warnings.
//!
//! One typed value, [`DesignReport`], made once by [`report`] (every design made once, as a run
//! makes it) and rendered twice: [`DesignReport::text`] for people and
//! [`DesignReport::json`] for programs; both show the same sections in the same order.

pub mod freq;
mod json;
mod sections;
mod text;

pub use sections::{ControllerSection, DesignReport, ObserverSection, report};
