//! Sampling a signal is per-step code (plant and controller): it must not allocate, including
//! the exact decimal comparison made next to a switching time.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

use lti::signal::{Signal, in_effect};

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: defers to the system allocator; counting touches only an atomic.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn sampling_next_to_a_switch_does_not_allocate() {
    let signals = [
        Signal::Step {
            time: 5.0000000000001,
            before: 0.0,
            after: 1.0,
        },
        Signal::Piecewise {
            times: vec![0.0, 3.3333, 5.0, 12.5],
            values: vec![0.2, -0.3, 0.5, -0.1],
        },
    ];
    let probe = ALLOCATIONS.load(Ordering::Relaxed);
    drop(std::hint::black_box(vec![1u8; 16]));
    assert!(
        ALLOCATIONS.load(Ordering::Relaxed) > probe,
        "the allocator counts"
    );
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let mut sum = 0.0;
    for k in 4990..5010u64 {
        for s in &signals {
            sum += s.sample_step(k, 0.001) + s.sample(k as f64 * 0.001, 0.001);
        }
        // Every call here takes the exact path (T/dt within 10⁻¹² of k).
        sum += in_effect(5.0, 5000, 0.001) as u8 as f64;
    }
    let n = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert_eq!(n, 0, "{n} allocations");
    assert!(sum > 0.0);
}
