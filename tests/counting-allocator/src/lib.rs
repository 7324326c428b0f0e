//! A global allocator for tests: [`Counting`] forwards every call to the system allocator and
//! counts the allocations (`alloc`, `alloc_zeroed`, `realloc`) that a thread makes while it runs
//! [`allocations_during`]'s closure. Only that thread's are counted: the test harness runs other
//! tests, and allocates, in threads of its own.
//!
//! ```
//! use trocar_counting_allocator::{allocations_during, Counting};
//!
//! #[global_allocator]
//! static ALLOCATOR: Counting = Counting;
//!
//! fn main() {
//!     let mut sum = 0.0;
//!     assert_eq!(allocations_during(|| sum += [1.0, 2.0].iter().sum::<f64>()), 0);
//!     assert_eq!(allocations_during(|| drop(std::hint::black_box(vec![sum]))), 1);
//! }
//! ```
#![forbid(missing_docs)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting the allocations of a thread within [`allocations_during`]; a
/// test binary makes it its `#[global_allocator]`.
pub struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

/// One allocation of this thread, counted if it is within [`allocations_during`]. `try_with`:
/// an allocation while the thread's locals are torn down is not counted, and does not panic.
fn count() {
    let _ = ARMED.try_with(|armed| {
        if armed.get() {
            COUNT.with(|n| n.set(n.get() + 1));
        }
    });
}

// SAFETY: every method forwards its arguments unchanged to `System`, which upholds
// `GlobalAlloc`'s contract; the counting beside it touches only this thread's `Cell`s (const-
// initialised thread locals, which do not allocate) and never unwinds.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller's contract for `alloc`, passed on.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller's contract for `alloc_zeroed`, passed on.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: the caller's contract for `realloc`, passed on (`ptr` came from `System`).
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract for `dealloc`, passed on (`ptr` came from `System`).
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// The allocations this thread makes while it runs `f` (with [`Counting`] as the global
/// allocator; 0 under any other).
pub fn allocations_during(f: impl FnOnce()) -> usize {
    let before = COUNT.with(Cell::get);
    let was = ARMED.with(|armed| armed.replace(true));
    f();
    ARMED.with(|armed| armed.set(was));
    COUNT.with(Cell::get) - before
}

#[cfg(test)]
mod tests {
    use super::*;

    #[global_allocator]
    static ALLOCATOR: Counting = Counting;

    #[test]
    fn it_counts_this_threads_allocations_within_the_closure() {
        assert_eq!(
            allocations_during(|| drop(std::hint::black_box(vec![1u8; 16]))),
            1
        );
        let mut v: Vec<u8> = Vec::with_capacity(1);
        // A growth is a `realloc`.
        assert_eq!(
            allocations_during(|| v.extend(std::hint::black_box([1u8; 64]))),
            1
        );
        assert_eq!(
            allocations_during(|| {
                std::hint::black_box(v.len());
            }),
            0
        );
        // Another thread's allocations are its own.
        let inner = std::thread::spawn(|| allocations_during(|| drop(vec![0u8; 8])))
            .join()
            .unwrap();
        assert_eq!(inner, 1);
    }
}
