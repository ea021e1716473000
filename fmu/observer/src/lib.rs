//! The shared library inside every observer FMU that `uio-launcher export-fmu` writes: FMI 2.0 and
//! FMI 3.0 co-simulation (one .so exports both APIs; the FMU's modelDescription says which one
//! an importer uses).
//!
//! It is generic: the observer z_{k+1} = F z_k + G u_k + K y_k, x̂_k = P z_k + Q y_k (the form
//! of observer/src/runtime.rs), the plant's C and dt are read at instantiation from
//! `resources/observer.json` (fmu_export::resource). Inputs u and y, outputs x̂ and r = y − C x̂
//! computed from the current inputs when read, doStep of exactly dt.

mod ffi;
pub mod fmi2;
pub mod fmi3;
mod instance;
mod observer;
