//! Independent jobs on a few threads, gathered in their own order: what a sweep's realisations
//! and a variation's points both are.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::LaunchError;
use crate::run;

/// Runs `job(0) … job(count − 1)` on `threads` threads and returns their results by index.
/// An error ends the pool (the jobs not yet started never run: `None`), as does an interrupt
/// (`run::interrupt`); `done` is called after each job (a progress bar's tick).
pub fn in_order<T: Send>(
    count: usize,
    threads: usize,
    job: impl Fn(usize) -> Result<T, LaunchError> + Sync,
    done: impl Fn() + Sync,
) -> Vec<Option<Result<T, LaunchError>>> {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<T, LaunchError>>>> =
        Mutex::new((0..count).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let j = next.fetch_add(1, Ordering::Relaxed);
                    if j >= count || run::interrupt::received().is_some() {
                        break;
                    }
                    let r = job(j);
                    let fatal = r.is_err();
                    results.lock().expect("no worker panics")[j] = Some(r);
                    done();
                    if fatal {
                        next.store(count, Ordering::Relaxed);
                    }
                }
            });
        }
    });
    results.into_inner().expect("no worker panics")
}
