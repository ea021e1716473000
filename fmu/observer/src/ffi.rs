//! What both FMI versions need at the C boundary: no panic crosses it, pointers and arrays
//! from the importer are checked before use, and resource locations become paths.

use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

use crate::instance::Instance;

/// Runs `f`, turning a panic into `fallback` (a panic must not unwind into the importer).
pub fn guard<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// The instance behind an FMI instance pointer, or `None` for a null pointer.
///
/// # Safety
/// `p` is null or a pointer this library returned from instantiate and has not freed.
pub unsafe fn instance<'a>(p: *mut std::ffi::c_void) -> Option<&'a mut Instance> {
    // SAFETY: by the caller's contract, a non-null `p` is a live `Box<Instance>`.
    unsafe { p.cast::<Instance>().as_mut() }
}

/// A slice from an importer's (pointer, length); `None` for a null pointer with a length > 0.
///
/// # Safety
/// A non-null `p` points at `n` valid values.
pub unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: by the caller's contract.
        Some(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

/// As [`slice`], mutable.
///
/// # Safety
/// A non-null `p` points at `n` writable values.
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: by the caller's contract.
        Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

/// A C string as text ("" for null; invalid UTF-8 replaced).
///
/// # Safety
/// A non-null `s` is NUL-terminated.
pub unsafe fn text(s: *const c_char) -> String {
    if s.is_null() {
        String::new()
    } else {
        // SAFETY: by the caller's contract.
        unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned()
    }
}

/// The folder an FMI 2 `fmuResourceLocation` names: a `file:` URI (`file:///p`,
/// `file://localhost/p` or `file:/p`), percent-decoded.
pub fn uri_path(uri: &str) -> Result<PathBuf, String> {
    let rest = uri
        .strip_prefix("file:")
        .ok_or_else(|| format!("the resource location {uri:?} is not a file: URI"))?;
    let path = match rest.strip_prefix("//") {
        Some(authority) if authority.starts_with('/') => authority,
        Some(authority) => authority
            .strip_prefix("localhost")
            .filter(|p| p.starts_with('/'))
            .ok_or_else(|| format!("the resource location {uri:?} is on another host"))?,
        None => rest,
    };
    let bytes = path.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            out.push(
                hex.ok_or_else(|| format!("the resource location {uri:?} has a bad %-escape"))?,
            );
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    use std::os::unix::ffi::OsStringExt;
    Ok(PathBuf::from(std::ffi::OsString::from_vec(out)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_uris_become_paths() {
        assert_eq!(
            uri_path("file:///tmp/a%20b/resources").unwrap(),
            PathBuf::from("/tmp/a b/resources")
        );
        assert_eq!(
            uri_path("file://localhost/tmp/r/").unwrap(),
            PathBuf::from("/tmp/r/")
        );
        assert_eq!(uri_path("file:/tmp/r").unwrap(), PathBuf::from("/tmp/r"));
        assert!(uri_path("http://x/r").is_err());
        assert!(uri_path("file://host/r").is_err());
        assert!(uri_path("file:///r%2").is_err());
    }

    #[test]
    fn a_panic_becomes_the_fallback() {
        let prev = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| ()));
        assert_eq!(guard(3, || panic!("no")), 3);
        std::panic::set_hook(prev);
        assert_eq!(guard(3, || 4), 4);
    }
}
