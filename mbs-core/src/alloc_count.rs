//! A counting global allocator for tests that prove a computation allocates nothing.
//!
//! The count is per thread, so tests running in parallel do not disturb each other. A test
//! binary installs it and counts around the code under test:
//!
//! ```
//! use mbs_core::alloc_count::{Counting, allocations_in};
//!
//! #[global_allocator]
//! static GLOBAL: Counting = Counting;
//!
//! fn main() {
//!     let v = vec![0.5f64; 8];
//!     // Summing allocates nothing; a new vector does.
//!     assert_eq!(allocations_in(|| assert_eq!(v.iter().sum::<f64>(), 4.0)), 0);
//!     assert!(allocations_in(|| drop(std::hint::black_box(vec![1u8; 4]))) >= 1);
//! }
//! ```

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, counting allocations and reallocations on each thread.
pub struct Counting;

// SAFETY: every call is passed on to the system allocator unchanged; the count is a
// thread-local `Cell` (const-initialised, so touching it does not allocate).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations made on this thread so far (with [`Counting`] installed).
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// Allocations made on this thread while running `f` (with [`Counting`] installed).
pub fn allocations_in(f: impl FnOnce()) -> usize {
    let before = allocations();
    f();
    allocations() - before
}
