//! Decoding that may panic, turned into an error. Rerun's decoders index and `expect` on data
//! from the file, so a damaged file can panic inside them; the reader reports that as damage
//! and the panic's own message ("thread 'main' panicked at …") must not reach stderr. The panic
//! hook is process-wide, so it is wrapped once and stays silent only on a thread that is
//! decoding: other threads' panics (a test's failure, say) are shown as before.

use std::cell::Cell;
use std::panic::{self, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`; a panic inside becomes Err with its message, and prints nothing.
pub fn quietly<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let shown = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                shown(info);
            }
        }));
    });
    let before = QUIET.with(|q| q.replace(true));
    // The state `f` touches is dropped or thrown away by the caller after a panic.
    let result = panic::catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(before));
    result.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic".into())
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_panic_becomes_its_message() {
        assert_eq!(super::quietly(|| 7), Ok(7));
        let v: Vec<u8> = Vec::new();
        let e = super::quietly(|| v[3]).unwrap_err();
        assert!(e.contains("index out of bounds"), "{e}");
    }
}
