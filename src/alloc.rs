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
//! The helper writes a byte to each page, so that the kernel faults it in
//! under the region's own lock: asking for the pages (`MADV_POPULATE_WRITE`)
//! would hold the process's map lock, and every `mmap` of the other threads
//! (a thread's stack, mimalloc's segments) would wait for it. It writes
//! only pages no buffer has been served from, one chunk at a time: it
//! claims the chunk, then checks that no buffer reached it meanwhile; a
//! buffer that reaches a claimed chunk waits for its writing to end.
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

/// How much the helper claims at a time: small, as a buffer that reaches
/// the chunk waits until its pages are in.
const CHUNK: usize = 128 << 10;

/// mimalloc, with the region in front of it for large allocations.
pub struct Alloc;

/// The region: `[start, end)`, served up to `next`; the helper is writing
/// the chunk at `claimed` (0: none). `start == 0` while there is none.
struct Region {
    start: AtomicUsize,
    end: AtomicUsize,
    next: AtomicUsize,
    claimed: AtomicUsize,
}

static REGION: Region = Region {
    start: AtomicUsize::new(0),
    end: AtomicUsize::new(0),
    next: AtomicUsize::new(0),
    claimed: AtomicUsize::new(0),
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
                .compare_exchange_weak(next, after, Ordering::SeqCst, Ordering::Relaxed)
            {
                Ok(_) => {
                    self.wait_for_helper(at, after);
                    return at as *mut u8;
                }
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
        let grown = self
            .next
            .compare_exchange(p + old, after, Ordering::SeqCst, Ordering::Relaxed)
            .is_ok();
        if grown {
            self.wait_for_helper(p, after);
        }
        grown
    }

    /// Waits while the helper writes a chunk that `[from, to)`, just
    /// served, reaches. The served end is published (`next`) before the
    /// claim is read, and the helper publishes its claim before it reads
    /// `next`: one of the two sees the other.
    fn wait_for_helper(&self, from: usize, to: usize) {
        let mut spins = 0u32;
        loop {
            let c = self.claimed.load(Ordering::SeqCst);
            if c == 0 || c >= to || c + CHUNK <= from {
                return;
            }
            spins += 1;
            if spins < 64 {
                std::hint::spin_loop();
            } else {
                // The helper may have lost its core; give it back.
                std::thread::yield_now();
            }
        }
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
                // Space given back may hold a freed buffer's bytes.
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

/// Makes a region for the large buffers to come, about `bytes` of them,
/// and has a second thread write in that many of its pages, front to back,
/// ahead of the buffers. The region is twice as large (its address space
/// only): buffers beyond the estimate still come from it, their pages
/// faulted in as used. Once per process; nothing where [`Alloc`] is not
/// the global allocator or the system refuses the memory (allocations
/// then go to mimalloc as before).
pub fn expect_large(bytes: usize) {
    static ONCE: std::sync::Once = std::sync::Once::new();
    if !INSTALLED.load(Ordering::Relaxed) || bytes < 2 * CHUNK {
        return;
    }
    ONCE.call_once(|| {
        let Some(room) = bytes.checked_mul(2) else {
            return;
        };
        let Ok(start) = (unsafe {
            rustix::mm::mmap_anonymous(
                std::ptr::null_mut(),
                room,
                rustix::mm::ProtFlags::READ | rustix::mm::ProtFlags::WRITE,
                rustix::mm::MapFlags::PRIVATE | rustix::mm::MapFlags::NORESERVE,
            )
        }) else {
            return;
        };
        let start = start as usize;
        REGION.next.store(start, Ordering::Relaxed);
        REGION.end.store(start + room, Ordering::Relaxed);
        REGION.start.store(start, Ordering::Release);
        let _ = std::thread::Builder::new()
            .name("btc-pages".into())
            .spawn(move || write_in(start, start + bytes));
    });
}

/// Writes the pages of `[start, end)` in, a chunk at a time, from the
/// first page no buffer has been served from.
fn write_in(start: usize, end: usize) {
    let page = rustix::param::page_size();
    let mut front = start;
    loop {
        let served = REGION.next.load(Ordering::SeqCst);
        let from = front.max(served.next_multiple_of(page));
        if from >= end {
            return;
        }
        let to = (from + CHUNK).min(end);
        REGION.claimed.store(from, Ordering::SeqCst);
        if REGION.next.load(Ordering::SeqCst) > from {
            // A buffer reached the chunk first: start again after it.
            REGION.claimed.store(0, Ordering::SeqCst);
            continue;
        }
        for p in (from..to).step_by(page) {
            // Safety: the page is in the region, and no buffer has been
            // served from it (any that reaches it waits for the claim to
            // end), so no one else reads or writes it now.
            unsafe { std::ptr::write_volatile(p as *mut u8, 0) };
        }
        REGION.claimed.store(0, Ordering::Release);
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
        // Meanwhile: buffers served while the helper writes pages in keep
        // every byte written to them.
        let size = 64 << 20;
        let start = region_over(size);
        let helper = std::thread::spawn(move || write_in(start, start + size));
        let mut buffers = Vec::new();
        for k in 0..120usize {
            let len = LARGE + (k * 7919) % (3 * LARGE);
            unsafe {
                let mut p = a.alloc(layout(len));
                std::ptr::write_bytes(p, 1 + (k % 250) as u8, len);
                if k % 3 == 0 {
                    // The last buffer grows in place, into pages not yet in.
                    p = a.realloc(p, layout(len), 2 * len);
                    std::ptr::write_bytes(p.add(len), 1 + (k % 250) as u8, len);
                    buffers.push((p, 2 * len, k));
                } else {
                    buffers.push((p, len, k));
                }
            }
        }
        helper.join().unwrap();
        for &(p, len, k) in &buffers {
            let kept = unsafe { std::slice::from_raw_parts(p, len) };
            assert!(kept.iter().all(|&b| b == 1 + (k % 250) as u8), "buffer {k}");
        }
    }
}
