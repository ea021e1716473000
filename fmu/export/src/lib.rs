//! Our sampled observers as FMI co-simulation FMUs (FMI 2.0 and 3.0).
//!
//! Every observer of this workspace reduces to the sampled form of observer/src/runtime.rs,
//! z_{k+1} = F z_k + G u_k + K y_k, x̂_k = P z_k + Q y_k. An FMU ships those matrices as
//! `resources/observer.json` ([`resource`]) beside one shared library (crate `fmu-observer`,
//! the same for every observer) that steps them with the run's own arithmetic, so an FMI
//! importer driving it with a recording's y and u gets the recording's x̂ bit for bit.
//!
//! This crate writes the resource, the modelDescription.xml and the archive; it has no FMI
//! bindings and builds without a C toolchain (the launcher depends on it).

pub mod model_description;
pub mod package;
pub mod resource;
pub mod variables;

use std::path::Path;

pub use model_description::{Description, Fmi, Signal};
pub use resource::{ObserverResource, OperatingPoint};

/// Writes the FMU of `res` to `path` (atomically), with the library read from `library`.
pub fn export(
    res: &ObserverResource,
    d: &Description,
    fmi: Fmi,
    library: &Path,
    path: &Path,
) -> Result<(), String> {
    let xml = model_description::model_description(res, d, fmi)?;
    let lib =
        std::fs::read(library).map_err(|e| format!("{}: cannot read: {e}", library.display()))?;
    let contents = package::Contents {
        model_description: &xml,
        resource_json: &res.to_json(),
        library: &lib,
        model_identifier: &d.model_identifier,
        fmi,
    };
    package::write(path, &contents)
}

/// A C identifier from an observer's name (letters, digits, `_`; `-` and the rest become `_`),
/// for the modelIdentifier.
pub fn identifier(name: &str) -> String {
    let mut id: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if !id.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        id.insert(0, '_');
    }
    id
}

#[cfg(test)]
mod tests {
    #[test]
    fn identifiers_are_c_identifiers() {
        assert_eq!(super::identifier("dgo-uio"), "dgo_uio");
        assert_eq!(super::identifier("2nd"), "_2nd");
        assert_eq!(super::identifier(""), "_");
    }
}
