//! The iceoryx2 service variant every port of this project uses: `ipc::Service` in all but one
//! respect — the reference-counted cell iceoryx2 wraps around each loaned sample's bookkeeping.
//!
//! `ipc::Service` puts that bookkeeping in a fresh `Rc` on every loan, i.e. one heap allocation
//! per published sample. [`Recycled`] is the same single-threaded reference count, but when its
//! last reference goes its memory returns to a per-thread free list, and the next loan takes it
//! from there: after the first step, publishing allocates nothing. The shared-memory layout and
//! every other mechanism are `ipc::Service`'s own.

use core::fmt::Debug;
use core::marker::PhantomData;
use core::ops::Deref;
use core::ptr::NonNull;
use std::alloc::{Layout, alloc, dealloc, handle_alloc_error};
use std::cell::{Cell, RefCell};

use iceoryx2::prelude::ZeroCopySend;
use iceoryx2_bb_elementary_traits::testing::abandonable::Abandonable;
use iceoryx2_cal::arc_sync_policy::{ArcSyncPolicy, ArcSyncPolicyCreationError, LockGuard};
use iceoryx2_cal::shm_allocator::bump_allocator::BumpAllocator;
use iceoryx2_cal::shm_allocator::pool_allocator::PoolAllocator;
use iceoryx2_cal::*;

/// `ipc::Service` with recycled per-sample bookkeeping.
#[derive(Debug, Clone)]
pub struct Service;

impl iceoryx2::service::Service for Service {
    type StaticStorage = static_storage::recommended::Ipc;
    type ConfigSerializer = serialize::recommended::Recommended;
    type PersistentDynamicStorage<T: Debug + Send + Sync + ZeroCopySend + 'static> =
        dynamic_storage::recommended::PersistentIpc<T>;
    type Bag = bag::recommended::Recommended;
    type DynamicStorage<T: Debug + Send + Sync + ZeroCopySend + 'static> =
        dynamic_storage::recommended::Ipc<T>;
    type ServiceNameHasher = hash::recommended::Recommended;
    type SharedMemory = shared_memory::recommended::Ipc<PoolAllocator>;
    type ResizableSharedMemory = resizable_shared_memory::recommended::Ipc<PoolAllocator>;
    type Connection = zero_copy_connection::recommended::Ipc;
    type Event = event::recommended::Ipc;
    type Monitoring = monitoring::recommended::Ipc;
    type Reactor = reactor::recommended::Ipc;
    type ArcThreadSafetyPolicy<T: Send + Debug + Abandonable> = Recycled<T>;
    type BlackboardMgmt<KeyType: Send + Sync + Debug + ZeroCopySend + 'static> =
        dynamic_storage::recommended::Ipc<KeyType>;
    type BlackboardPayload = shared_memory::recommended::Ipc<BumpAllocator>;
    type UniqueId = iceoryx2::unique_id_generator::unique_system_id::UniqueSystemId;
}

impl iceoryx2::service::internal::ServiceInternal<Service> for Service {}

/// Free blocks, keyed by (size, align).
type FreeLists = Vec<((usize, usize), Vec<NonNull<u8>>)>;

thread_local! {
    /// Free memory blocks by (size, align); a block leaves the list when a cell is created and
    /// returns when its last reference drops. The few blocks still listed when a thread ends
    /// (a handful per port) are not returned to the allocator.
    static FREE: RefCell<FreeLists> = const { RefCell::new(Vec::new()) };
}

fn take(layout: Layout) -> NonNull<u8> {
    let key = (layout.size(), layout.align());
    let reused = FREE.with(|f| {
        f.borrow_mut()
            .iter_mut()
            .find(|(k, _)| *k == key)
            .and_then(|(_, v)| v.pop())
    });
    reused.unwrap_or_else(|| {
        // SAFETY: the layout is that of a non-zero-sized `Slot<T>`.
        let p = unsafe { alloc(layout) };
        NonNull::new(p).unwrap_or_else(|| handle_alloc_error(layout))
    })
}

fn give(p: NonNull<u8>, layout: Layout) {
    let key = (layout.size(), layout.align());
    let kept = FREE.try_with(|f| {
        let mut f = f.borrow_mut();
        match f.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(p),
            None => f.push((key, vec![p])),
        }
    });
    if kept.is_err() {
        // The thread's free list is already gone (thread exit): hand the block back.
        // SAFETY: `p` came from `alloc` with this layout in `take`.
        unsafe { dealloc(p.as_ptr(), layout) };
    }
}

struct Slot<T> {
    refs: Cell<usize>,
    value: T,
}

/// A single-threaded reference-counted cell whose memory is recycled (see the module docs).
pub struct Recycled<T: Send + Debug + Abandonable> {
    slot: NonNull<Slot<T>>,
    _owns: PhantomData<Slot<T>>,
}

impl<T: Send + Debug + Abandonable> Recycled<T> {
    fn slot(&self) -> &Slot<T> {
        // SAFETY: the slot is live while any reference (this one included) exists.
        unsafe { self.slot.as_ref() }
    }
}

impl<T: Send + Debug + Abandonable> Debug for Recycled<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Recycled")
            .field("value", &self.slot().value)
            .finish()
    }
}

impl<T: Send + Debug + Abandonable> Clone for Recycled<T> {
    fn clone(&self) -> Self {
        let refs = &self.slot().refs;
        refs.set(refs.get() + 1);
        Self {
            slot: self.slot,
            _owns: PhantomData,
        }
    }
}

/// Drops one reference; the last one drops the value and recycles the memory.
///
/// # Safety
/// `slot` must be live and the caller must own one of its references.
unsafe fn release<T>(slot: NonNull<Slot<T>>) {
    // SAFETY: per the contract the slot is live.
    let refs = unsafe { &slot.as_ref().refs };
    let left = refs.get() - 1;
    refs.set(left);
    if left == 0 {
        // SAFETY: this was the last reference: nothing else reads the slot again.
        unsafe { core::ptr::drop_in_place(slot.as_ptr()) };
        give(slot.cast(), Layout::new::<Slot<T>>());
    }
}

impl<T: Send + Debug + Abandonable> Drop for Recycled<T> {
    fn drop(&mut self) {
        // SAFETY: this handle owns one reference to a live slot.
        unsafe { release(self.slot) }
    }
}

impl<T: Send + Debug + Abandonable> Abandonable for Recycled<T> {
    unsafe fn abandon_in_place(this: NonNull<Self>) {
        // As iceoryx2's `SingleThreaded`: the sole owner abandons the value (leaving the memory),
        // a shared one just lets go of its reference.
        // SAFETY: per the trait's contract `this` points at a valid handle.
        let slot = unsafe { this.as_ref().slot };
        // SAFETY: the slot is live while this handle exists.
        if unsafe { slot.as_ref().refs.get() } == 1 {
            // SAFETY: sole owner: the value is abandoned in place and never touched again.
            unsafe { T::abandon_in_place(NonNull::from_mut(&mut (*slot.as_ptr()).value)) };
        } else {
            // SAFETY: this handle owns one reference.
            unsafe { release(slot) };
        }
    }
}

/// Access to the value; holds a reference while it lives.
pub struct Guard<'parent, T: Send + Debug + Abandonable> {
    slot: NonNull<Slot<T>>,
    _parent: PhantomData<&'parent Recycled<T>>,
}

impl<T: Send + Debug + Abandonable> Deref for Guard<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        // SAFETY: the guard holds a reference, so the slot is live.
        unsafe { &self.slot.as_ref().value }
    }
}

impl<T: Send + Debug + Abandonable> Drop for Guard<'_, T> {
    fn drop(&mut self) {
        // SAFETY: the guard owns one reference to a live slot.
        unsafe { release(self.slot) }
    }
}

impl<'parent, T: Send + Debug + Abandonable> LockGuard<'parent, T> for Guard<'parent, T> {}

impl<T: Send + Debug + Abandonable> ArcSyncPolicy<T> for Recycled<T> {
    type LockGuard<'parent>
        = Guard<'parent, T>
    where
        Self: 'parent,
        T: 'parent;

    fn new(value: T) -> Result<Self, ArcSyncPolicyCreationError> {
        let slot = take(Layout::new::<Slot<T>>()).cast::<Slot<T>>();
        // SAFETY: the block has the layout of Slot<T> and is not in use.
        unsafe {
            slot.as_ptr().write(Slot {
                refs: Cell::new(1),
                value,
            })
        };
        Ok(Self {
            slot,
            _owns: PhantomData,
        })
    }

    fn lock(&self) -> Guard<'_, T> {
        let refs = &self.slot().refs;
        refs.set(refs.get() + 1);
        Guard {
            slot: self.slot,
            _parent: PhantomData,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::rc::Rc;

    #[derive(Debug)]
    struct Probe(Rc<Cell<u32>>);
    // SAFETY (test only): the probe never crosses threads in these tests.
    unsafe impl Send for Probe {}
    impl Drop for Probe {
        fn drop(&mut self) {
            self.0.set(self.0.get() + 1);
        }
    }
    impl Abandonable for Probe {
        unsafe fn abandon_in_place(_: NonNull<Self>) {}
    }

    #[test]
    fn drops_once_and_recycles_memory() {
        let drops = Rc::new(Cell::new(0));
        let a = Recycled::new(Probe(drops.clone())).unwrap();
        let first = a.slot.as_ptr() as usize;
        let b = a.clone();
        {
            let g = b.lock();
            assert_eq!(g.0.get(), 0);
        }
        drop(a);
        assert_eq!(drops.get(), 0);
        drop(b);
        assert_eq!(drops.get(), 1);
        // The next cell of the same type reuses the block.
        let c = Recycled::new(Probe(drops.clone())).unwrap();
        assert_eq!(c.slot.as_ptr() as usize, first);
        drop(c);
        assert_eq!(drops.get(), 2);
    }
}
