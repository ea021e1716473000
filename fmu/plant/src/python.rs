//! FMUs whose library embeds Python (pythonfmu, pythonfmu3 and their kind). Such a library
//! leaves the interpreter's symbols (`Py_Initialize`, `_Py_NoneStruct`, …) undefined and
//! expects its host to have loaded libpython with global symbol visibility, as a Python
//! process (FMPy) has; a plain host fails in fmi2Instantiate with "undefined symbol".
//!
//! The host here is the `python3` on PATH (the launcher's, as for Python components): it says
//! where its shared libpython is (`sysconfig`: LIBDIR/INSTSONAME) and what its `sys.path` is.
//! Before the FMU's library is loaded, that libpython is opened with `RTLD_GLOBAL`, and its
//! `sys.path` becomes the embedded interpreter's `PYTHONPATH`, so that the FMU's script
//! imports what `python3` imports (numpy, a virtual environment's packages).

use std::ffi::CString;
use std::process::Command;

/// What the library needs from Python: the first undefined `Py…` symbol of its dynamic
/// symbol table, or `None` for a library that needs no Python (or is not ELF).
pub fn needs(library: &[u8]) -> Option<String> {
    use object::{Object as _, ObjectSymbol as _};
    let file = object::File::parse(library).ok()?;
    file.dynamic_symbols()
        .filter(|s| s.is_undefined())
        .filter_map(|s| s.name().ok())
        .find(|n| n.starts_with("Py") || n.starts_with("_Py"))
        .map(str::to_string)
}

/// A Python installation to embed.
#[derive(Debug, Clone)]
pub struct Python {
    /// Its shared libpython (absolute).
    pub library: String,
    /// Its `sys.path`, joined with ':'.
    pub path: String,
}

/// The `python3` on PATH as a host for an FMU whose library needs `symbol`; the refusal names
/// what is missing.
pub fn find(symbol: &str) -> Result<Python, String> {
    let why = |what: String| {
        format!("its library embeds Python (it needs {symbol} from libpython): {what}")
    };
    const ASK: &str = "import os, sys, sysconfig\n\
        d, so = sysconfig.get_config_var('LIBDIR') or '', sysconfig.get_config_var('INSTSONAME') or ''\n\
        print(os.path.join(d, so) if so and '.so' in so else '')\n\
        print(os.pathsep.join(p for p in sys.path if p))";
    let out = Command::new("python3")
        .args(["-c", ASK])
        .env_remove("PYTHONHOME")
        .output()
        .map_err(|e| why(format!("no python3 on PATH ({e})")))?;
    if !out.status.success() {
        return Err(why(format!(
            "python3 failed: {}",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut lines = text.lines();
    let (library, path) = (
        lines.next().unwrap_or("").to_string(),
        lines.next().unwrap_or("").to_string(),
    );
    if library.is_empty() {
        return Err(why("the python3 on PATH was built without a shared libpython (sysconfig INSTSONAME is not a .so)".into()));
    }
    if !std::path::Path::new(&library).is_file() {
        return Err(why(format!(
            "the python3 on PATH names {library}, which is not there (Debian: the libpython3.X package)"
        )));
    }
    Ok(Python { library, path })
}

static LOADED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Whether this process loaded a libpython for an FMU.
pub fn loaded() -> bool {
    LOADED.load(std::sync::atomic::Ordering::Relaxed)
}

/// Opens the library with global symbols and hands its `sys.path` to the embedded
/// interpreter. Call before the FMU's library is loaded, while the process has one thread
/// (it sets an environment variable).
pub fn load(py: &Python) -> Result<(), String> {
    let name = CString::new(py.library.as_str())
        .map_err(|_| format!("{}: a path with a NUL byte", py.library))?;
    // SAFETY: dlopen with a valid C string; the handle is kept for the life of the process
    // (never closed: the FMU's library refers to its symbols until the process ends).
    let handle = unsafe { libc::dlopen(name.as_ptr(), libc::RTLD_NOW | libc::RTLD_GLOBAL) };
    if handle.is_null() {
        // SAFETY: dlerror returns a static message or NULL.
        let e = unsafe { libc::dlerror() };
        let msg = if e.is_null() {
            "unknown error".to_string()
        } else {
            unsafe { std::ffi::CStr::from_ptr(e) }
                .to_string_lossy()
                .into_owned()
        };
        return Err(format!("cannot load {}: {msg}", py.library));
    }
    LOADED.store(true, std::sync::atomic::Ordering::Relaxed);
    if std::env::var_os("PYTHONPATH").is_none() && !py.path.is_empty() {
        // SAFETY: the caller holds the process's only thread.
        unsafe { std::env::set_var("PYTHONPATH", &py.path) };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_library_without_python_symbols_needs_no_python() {
        // This test binary itself: ELF, and no undefined Py… symbol.
        let me = std::fs::read(std::env::current_exe().unwrap()).unwrap();
        assert_eq!(needs(&me), None);
        assert_eq!(needs(b"not an ELF file"), None);
    }
}
