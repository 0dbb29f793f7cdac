//! A global allocator that counts the allocations (and reallocations) of
//! each thread, for the tests that a hot path does not allocate
//! (`friction-fmu/tests/step_allocation.rs`, `host/tests/allocation.rs`).
//! Included with `#[path]`; the test installs it with
//! `#[global_allocator] static GLOBAL: Counting = Counting;` and reads
//! [`allocations`] before and after, on the thread that runs the hot path.
//! Per thread, because the test harness's own threads may allocate while
//! a test runs (a process-wide counter once saw 13 allocations where the
//! law makes 12).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

pub struct Counting;

thread_local! {
    /// This thread's allocations and reallocations so far (a `const`
    /// initialiser: reading it never allocates).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// Allocations and reallocations of the calling thread so far.
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

fn count() {
    // (a thread being torn down has no counter left: not counted)
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: delegates to the system allocator.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}
