//! Issue 24: the recording writer allocates nothing per step. Between two sends of a group, a
//! row and its values go into buffers sized for a whole batch ([`FLUSH_STEPS`]).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

use recording::write::{RrdSink, FLUSH_STEPS};

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
thread_local! {
    static TRACKING: Cell<bool> = const { Cell::new(false) };
}

// SAFETY: defers to the system allocator; counting touches only an atomic and a const TLS cell.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if TRACKING.with(|t| t.get()) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if TRACKING.with(|t| t.get()) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn rows_between_sends_allocate_nothing() {
    let dir = std::env::temp_dir().join(format!("uio-noalloc-writer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut sink = RrdSink::create(&dir.join("r.rrd"), "r", |_| rerun::blueprint::Blueprint::new(rerun::blueprint::Vertical::new(Vec::<rerun::blueprint::ContainerLike>::new())), "", Default::default()).unwrap();
    let (g, late) = (sink.group("signals"), sink.group("late"));
    let ids: Vec<_> = ["/plant/x/1", "/plant/y/1", "/observer/a/xhat/1", "/observer/a/error/1", "/controller/u/1"].iter().map(|p| sink.series(g, p, p, [0, 0, 0], 1.0)).collect();
    let step = sink.series(late, "/latency/step", "step", [0, 0, 0], 1.0);
    let mut k = 0u64;
    let mut one = |sink: &mut RrdSink| {
        sink.row(g, k, k as f64 * 1e-3);
        for (i, id) in ids.iter().enumerate() {
            sink.push(*id, (k + i as u64) as f64);
        }
        sink.row(late, k, k as f64 * 1e-3);
        sink.push(step, 1.0);
        sink.flush_full().unwrap();
        k += 1;
    };
    // Two batches sent: every buffer has been made for a whole batch.
    for _ in 0..2 * FLUSH_STEPS {
        one(&mut sink);
    }
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    TRACKING.with(|t| t.set(true));
    for _ in 0..FLUSH_STEPS - 1 {
        one(&mut sink);
    }
    TRACKING.with(|t| t.set(false));
    let allocations = ALLOCATIONS.load(Ordering::Relaxed) - before;
    sink.finish(k).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(allocations, 0, "{allocations} allocations in {} rows", FLUSH_STEPS - 1);
}
