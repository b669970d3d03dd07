//! The `btc` binary's allocator: mimalloc, and, for one command that will
//! fill large buffers (a long plan's text, steps and tree), a region for
//! those buffers whose pages a second core writes in beforehand.
//!
//! Why: the first write to a fresh page costs its thread a fault, the
//! kernel's zeroing and, on a virtual machine, the host's too: about as
//! much as the work done on the page. A long compile touches some 25 MB
//! once, on its critical path, while its second core waits for the plan to
//! be read. [`expect_large`] hands that wait to the faults instead.
//!
//! Only allocations of [`LARGE`] bytes or more are served from the region,
//! by moving a pointer; a freed buffer is given back only when it was the
//! last one served (a growing vector extends in place), else its space is
//! left until the process ends. The region is bounded: once it is used up,
//! allocations go to mimalloc as before. Where this allocator is not the
//! global one (the library inside Python, tests), [`expect_large`] does
//! nothing.

use std::alloc::{GlobalAlloc, Layout};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The smallest allocation served from the region: smaller ones are many
/// and freed often, and mimalloc reuses their pages.
pub const LARGE: usize = 256 << 10;

/// How much the helper writes in at a time: small enough that it stays
/// just ahead of the allocations, large enough to keep its calls few.
const CHUNK: usize = 256 << 10;

/// mimalloc, with the region in front of it for large allocations.
pub struct Alloc;

/// The region: `[start, end)`, served up to `next`. `start == 0` while
/// there is none.
struct Region {
    start: AtomicUsize,
    end: AtomicUsize,
    next: AtomicUsize,
}

static REGION: Region = Region {
    start: AtomicUsize::new(0),
    end: AtomicUsize::new(0),
    next: AtomicUsize::new(0),
};

/// Set by the first allocation through [`Alloc`]: the region is worth
/// making only where this allocator serves it.
static INSTALLED: AtomicBool = AtomicBool::new(false);

impl Region {
    fn contains(&self, p: *mut u8) -> bool {
        let p = p as usize;
        let start = self.start.load(Ordering::Acquire);
        start != 0 && p >= start && p < self.end.load(Ordering::Acquire)
    }

    /// `layout`'s bytes from the region, or null when it has no room.
    fn take(&self, layout: Layout) -> *mut u8 {
        if self.start.load(Ordering::Acquire) == 0 {
            return std::ptr::null_mut();
        }
        let end = self.end.load(Ordering::Acquire);
        let mut next = self.next.load(Ordering::Relaxed);
        loop {
            let at = next.next_multiple_of(layout.align());
            let Some(after) = at.checked_add(layout.size()).filter(|&a| a <= end) else {
                return std::ptr::null_mut();
            };
            match self
                .next
                .compare_exchange_weak(next, after, Ordering::AcqRel, Ordering::Relaxed)
            {
                Ok(_) => return at as *mut u8,
                Err(now) => next = now,
            }
        }
    }

    /// Gives `size` bytes at `p` back when they are the last served.
    fn give_back(&self, p: *mut u8, size: usize) {
        let p = p as usize;
        let _ = self
            .next
            .compare_exchange(p + size, p, Ordering::AcqRel, Ordering::Relaxed);
    }

    /// Grows (or shrinks) the last buffer served in place; false when `p`
    /// is not the last one or the region has no room.
    fn resize_last(&self, p: *mut u8, old: usize, new: usize) -> bool {
        let p = p as usize;
        let Some(after) = p
            .checked_add(new)
            .filter(|&a| a <= self.end.load(Ordering::Acquire))
        else {
            return false;
        };
        self.next
            .compare_exchange(p + old, after, Ordering::AcqRel, Ordering::Relaxed)
            .is_ok()
    }
}

unsafe impl GlobalAlloc for Alloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !INSTALLED.load(Ordering::Relaxed) {
            INSTALLED.store(true, Ordering::Relaxed);
        }
        if layout.size() >= LARGE {
            let p = REGION.take(layout);
            if !p.is_null() {
                return p;
            }
        }
        unsafe { mimalloc::MiMalloc.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() >= LARGE {
            let p = REGION.take(layout);
            if !p.is_null() {
                // Pages of the region are fresh (zero) or were served and
                // given back: only those need clearing.
                unsafe { std::ptr::write_bytes(p, 0, layout.size()) };
                return p;
            }
        }
        unsafe { mimalloc::MiMalloc.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        if REGION.contains(p) {
            REGION.give_back(p, layout.size());
        } else {
            unsafe { mimalloc::MiMalloc.dealloc(p, layout) }
        }
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new: usize) -> *mut u8 {
        let in_region = REGION.contains(p);
        if in_region && (REGION.resize_last(p, layout.size(), new) || new <= layout.size()) {
            // A buffer that shrinks keeps its place (the rest is left).
            return p;
        }
        if !in_region && new < LARGE {
            return unsafe { mimalloc::MiMalloc.realloc(p, layout, new) };
        }
        // Safety: the caller gives a size that, aligned, fits `isize`.
        let to = unsafe { Layout::from_size_align_unchecked(new, layout.align()) };
        let q = unsafe { self.alloc(to) };
        if !q.is_null() {
            unsafe {
                std::ptr::copy_nonoverlapping(p, q, layout.size().min(new));
                self.dealloc(p, layout);
            }
        }
        q
    }
}

/// Makes a region of `bytes` for the large buffers to come and has a
/// second thread write its pages in, front to back, ahead of them. Once
/// per process; nothing where [`Alloc`] is not the global allocator or the
/// system refuses the memory (allocations then go to mimalloc as before).
pub fn expect_large(bytes: usize) {
    static ONCE: std::sync::Once = std::sync::Once::new();
    if !INSTALLED.load(Ordering::Relaxed) || bytes < 2 * CHUNK {
        return;
    }
    ONCE.call_once(|| {
        let Ok(start) = (unsafe {
            rustix::mm::mmap_anonymous(
                std::ptr::null_mut(),
                bytes,
                rustix::mm::ProtFlags::READ | rustix::mm::ProtFlags::WRITE,
                rustix::mm::MapFlags::PRIVATE | rustix::mm::MapFlags::NORESERVE,
            )
        }) else {
            return;
        };
        let start = start as usize;
        REGION.next.store(start, Ordering::Relaxed);
        REGION.end.store(start + bytes, Ordering::Relaxed);
        REGION.start.store(start, Ordering::Release);
        let _ = std::thread::Builder::new()
            .name("btc-pages".into())
            .spawn(move || write_in(start, start + bytes));
    });
}

/// Writes the pages of `[start, end)` in, a chunk at a time, from the
/// first not yet served: a page a thread has touched already is left as
/// it is (the kernel writes in only missing pages, never data).
fn write_in(start: usize, end: usize) {
    let mut front = start;
    while front < end {
        let page = rustix::param::page_size();
        front = front.max(REGION.next.load(Ordering::Relaxed) / page * page);
        let to = (front + CHUNK).min(end);
        let advised = unsafe {
            rustix::mm::madvise(
                front as *mut std::ffi::c_void,
                to - front,
                rustix::mm::Advice::LinuxPopulateWrite,
            )
        };
        if advised.is_err() {
            // A kernel before 5.14: the pages are faulted in as used.
            return;
        }
        front = to;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn region_over(bytes: usize) -> usize {
        let start = unsafe {
            rustix::mm::mmap_anonymous(
                std::ptr::null_mut(),
                bytes,
                rustix::mm::ProtFlags::READ | rustix::mm::ProtFlags::WRITE,
                rustix::mm::MapFlags::PRIVATE,
            )
        }
        .unwrap() as usize;
        REGION.next.store(start, Ordering::Relaxed);
        REGION.end.store(start + bytes, Ordering::Relaxed);
        REGION.start.store(start, Ordering::Release);
        start
    }

    fn layout(size: usize) -> Layout {
        Layout::from_size_align(size, 64).unwrap()
    }

    /// One test, as the region is the process's: large buffers come from
    /// it, small ones and those it has no room for from mimalloc; a buffer
    /// keeps its bytes when it grows, in place or moved; writing pages in
    /// keeps what a buffer holds.
    #[test]
    fn the_region_serves_large_buffers_and_mimalloc_the_rest() {
        let size = 8 << 20;
        let start = region_over(size);
        let a = Alloc;
        unsafe {
            let small = a.alloc(layout(1024));
            assert!(!REGION.contains(small));
            let first = a.alloc(layout(LARGE));
            assert_eq!(first as usize, start);
            std::ptr::write_bytes(first, 7, LARGE);
            // The last buffer grows in place.
            let grown = a.realloc(first, layout(LARGE), 2 * LARGE);
            assert_eq!(grown, first);
            let second = a.alloc(layout(LARGE + 1));
            assert_eq!(second as usize % 64, 0);
            assert_eq!(second as usize, start + 2 * LARGE);
            // One that is not the last moves, with its bytes.
            let moved = a.realloc(grown, layout(2 * LARGE), 3 * LARGE);
            assert_ne!(moved, grown);
            assert!(REGION.contains(moved));
            assert!((0..LARGE).all(|i| *moved.add(i) == 7));
            // The last one freed is given back; another is left.
            let before = REGION.next.load(Ordering::Relaxed);
            a.dealloc(moved, layout(3 * LARGE));
            assert!(REGION.next.load(Ordering::Relaxed) < before);
            let after_second = REGION.next.load(Ordering::Relaxed);
            a.dealloc(second, layout(LARGE + 1));
            assert!(REGION.next.load(Ordering::Relaxed) == after_second);
            // Writing the pages in keeps what they hold.
            std::ptr::write_bytes(second, 9, LARGE + 1);
            write_in(start, start + size);
            assert!((0..=LARGE).all(|i| *second.add(i) == 9));
            // Full: mimalloc takes over, shrinking included.
            let too_big = a.alloc(layout(size));
            assert!(!too_big.is_null() && !REGION.contains(too_big));
            let shrunk = a.realloc(too_big, layout(size), 512);
            *shrunk.add(511) = 1;
            a.dealloc(shrunk, layout(512));
            let zeroed = a.alloc_zeroed(layout(LARGE));
            assert!(REGION.contains(zeroed));
            assert!((0..LARGE).all(|i| *zeroed.add(i) == 0));
            a.dealloc(small, layout(1024));
        }
    }
}
