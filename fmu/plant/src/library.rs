//! What an FMU's library must be before anything loads it: an ELF shared object for this
//! machine's architecture that exports the FMI functions the host calls.
//!
//! Read from the archive's bytes (nothing is loaded, no constructor runs). Before, a library
//! for another architecture reached `dlopen`, whose glibc message for a foreign `e_machine` is
//! "cannot open shared object file: No such file or directory" about a file that exists; and a
//! library without the FMI symbols loaded, and the first call through the `fmi` crate's
//! bindings panicked (exit 101, "run with RUST_BACKTRACE").

use object::{Architecture, Object as _, ObjectKind, ObjectSymbol as _};

use crate::version::Version;

/// The FMI 2.0 co-simulation functions the host calls (FMI 2.0 §2.1, §4.2: every one of them
/// a co-simulation FMU exports).
const FMI2: &[&str] = &[
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2GetReal",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2DoStep",
];

/// The FMI 3.0 co-simulation functions the host calls (FMI 3.0 §2.3, §4.2).
const FMI3: &[&str] = &[
    "fmi3InstantiateCoSimulation",
    "fmi3FreeInstance",
    "fmi3EnterInitializationMode",
    "fmi3ExitInitializationMode",
    "fmi3GetFloat64",
    "fmi3SetFloat64",
    "fmi3DoStep",
];

/// This machine's architecture, as `object` names it.
fn host() -> Architecture {
    if cfg!(target_arch = "x86_64") {
        Architecture::X86_64
    } else if cfg!(target_arch = "aarch64") {
        Architecture::Aarch64
    } else {
        Architecture::Unknown
    }
}

/// Why `library` (the archive entry `name`) cannot be the FMU's library here, if it cannot.
pub fn problem(name: &str, library: &[u8], version: Version) -> Option<String> {
    let file = match object::File::parse(library) {
        Ok(f) if f.format() == object::BinaryFormat::Elf => f,
        _ => return Some(format!("{name} is not an ELF shared library")),
    };
    if file.kind() != ObjectKind::Dynamic {
        return Some(format!(
            "{name} is not a shared library (ELF kind {:?})",
            file.kind()
        ));
    }
    let (arch, here) = (file.architecture(), host());
    if arch != here || file.is_64() != cfg!(target_pointer_width = "64") {
        let bits = if file.is_64() { 64 } else { 32 };
        return Some(format!(
            "{name} is built for {arch:?} ({bits}-bit), not for this machine ({here:?})"
        ));
    }
    let exported: std::collections::HashSet<&str> = file
        .dynamic_symbols()
        .filter(|s| !s.is_undefined())
        .filter_map(|s| s.name().ok())
        .collect();
    let wanted = match version {
        Version::Two => FMI2,
        Version::Three => FMI3,
    };
    let missing: Vec<&str> = wanted
        .iter()
        .copied()
        .filter(|f| !exported.contains(f))
        .collect();
    if missing.is_empty() {
        return None;
    }
    let which = if missing.len() > 3 {
        format!("{} and {} more", missing[..3].join(", "), missing.len() - 3)
    } else {
        missing.join(", ")
    };
    let v = if version == Version::Two {
        "2.0"
    } else {
        "3.0"
    };
    Some(format!(
        "{name} does not export {which}: not an FMI {v} co-simulation library"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_that_are_not_elf_are_named_as_such() {
        let p = problem(
            "binaries/linux64/m.so",
            b"MZ\x90\0 not a library",
            Version::Two,
        )
        .unwrap();
        assert_eq!(p, "binaries/linux64/m.so is not an ELF shared library");
    }

    #[test]
    fn this_test_binary_is_not_a_shared_library() {
        let me = std::fs::read(std::env::current_exe().unwrap()).unwrap();
        let p = problem("x.so", &me, Version::Two).unwrap();
        assert!(
            p.contains("not a shared library") || p.contains("does not export fmi2Instantiate"),
            "{p}"
        );
    }
}
