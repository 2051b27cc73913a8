//! A global allocator that counts: the bytes live now and the most that were live at once since
//! the last [`measure`] began. The binaries install it (`#[global_allocator]`); this library
//! never does, so linking it changes nothing for anyone else.

#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Bytes live now, every thread together (rayon's workers allocate for the readers too).
static LIVE: AtomicUsize = AtomicUsize::new(0);
/// The largest value [`LIVE`] reached since the last reset.
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// Allocations made: tells [`measure`] whether the allocator is installed at all.
static CALLS: AtomicUsize = AtomicUsize::new(0);

/// [`System`], counting every byte it hands out and takes back. Install it in a binary with
/// `#[global_allocator] static ALLOC: CountingAllocator = CountingAllocator;`, then run the
/// code to be measured in [`measure`].
#[derive(Debug, Default, Clone, Copy)]
pub struct CountingAllocator;

impl CountingAllocator {
    fn grew(by: usize) {
        CALLS.fetch_add(1, Ordering::Relaxed);
        let live = LIVE.fetch_add(by, Ordering::Relaxed) + by;
        PEAK.fetch_max(live, Ordering::Relaxed);
    }

    fn shrank(by: usize) {
        LIVE.fetch_sub(by, Ordering::Relaxed);
    }
}

// SAFETY: every call is forwarded to `System` unchanged; the counters only observe sizes.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is `System`'s.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            Self::grew(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is `System`'s.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            Self::grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract is `System`'s.
        unsafe { System.dealloc(ptr, layout) };
        Self::shrank(layout.size());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract is `System`'s.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            // Counted as the old block freed after the new one is live, the worst case of a
            // copy (an in-place realloc overstates the peak by the old size at most).
            Self::grew(new_size);
            Self::shrank(layout.size());
        }
        p
    }
}

/// Bytes live now, as counted by [`CountingAllocator`] (0 when it is not installed).
pub fn live_bytes() -> usize {
    LIVE.load(Ordering::Relaxed)
}

/// Runs `f` and returns its result with the most bytes that were live at once during the call,
/// beyond those live when it began (the input itself, the fuzzer's own buffers).
///
/// Everything allocated in the meantime counts, on every thread: measure one call at a time.
///
/// # Panics
///
/// When [`CountingAllocator`] is not the global allocator: a measurement of 0 would pass every
/// bound and check nothing.
pub fn measure<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let calls = CALLS.load(Ordering::Relaxed);
    drop(std::hint::black_box(vec![0u8; 64]));
    let installed = CALLS.load(Ordering::Relaxed) > calls;
    assert!(installed, "CountingAllocator is not the global allocator: add #[global_allocator] to the binary");

    let base = live_bytes();
    PEAK.store(base, Ordering::Relaxed);
    let result = f();
    let peak = PEAK.load(Ordering::Relaxed).saturating_sub(base);
    (result, peak)
}
