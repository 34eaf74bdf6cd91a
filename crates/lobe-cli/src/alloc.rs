//! The process's allocator: the system's, except that large blocks are
//! mappings of their own that the kernel may back with 2 MiB pages
//! (Linux's transparent huge pages in `madvise` mode, the common default).
//!
//! `lobe render` reads a map into a few buffers of megabytes (a 1024 × 512
//! map: 8 MiB of texels, two samplers' tables of 6 MiB each) and touches
//! every page of them once, at start: with 4 KiB pages that is thousands
//! of page faults, a tenth of a short render's time, and lookups at
//! random places in the map that miss the TLB. A block of
//! [`HUGE_THRESHOLD`] bytes or more is `mmap`ed directly (zeroed by the
//! kernel, so `alloc_zeroed` touches nothing) and `madvise`d
//! `MADV_HUGEPAGE` before its first touch, which glibc's `malloc` cannot
//! do (it writes its header into the block first). Advice only: where the
//! kernel has no huge pages to give, or on other systems, nothing changes
//! but the page size. `bench/mitsuba_render.py` measures the effect.

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks at least this large (and aligned to at most a page) get a
/// mapping of their own.
pub const HUGE_THRESHOLD: usize = 1 << 20;

/// The system allocator, with large blocks mapped on their own and
/// advised to use huge pages (Linux), see the module doc.
pub struct Allocator;

#[cfg(target_os = "linux")]
const PAGE: usize = 4096;

#[cfg(target_os = "linux")]
#[inline]
fn mapped(layout: Layout) -> bool {
    layout.size() >= HUGE_THRESHOLD && layout.align() <= PAGE
}

#[cfg(target_os = "linux")]
#[inline]
fn mapping_len(size: usize) -> usize {
    size.next_multiple_of(PAGE)
}

// SAFETY: every block comes from `System` or from `mmap`, and goes back the
// way it came: `mapped(layout)` depends only on the layout, which the
// caller passes unchanged to `dealloc` (and `realloc`'s default moves the
// contents between two blocks each allocated and freed here).
unsafe impl GlobalAlloc for Allocator {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        #[cfg(target_os = "linux")]
        if mapped(layout) {
            return map(layout.size());
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc(layout) }
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        #[cfg(target_os = "linux")]
        if mapped(layout) {
            // (A fresh anonymous mapping reads as zeros.)
            return map(layout.size());
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc_zeroed(layout) }
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        #[cfg(target_os = "linux")]
        if mapped(layout) {
            // SAFETY: `ptr` is a mapping of this length made by `map`.
            unsafe {
                libc::munmap(ptr.cast(), mapping_len(layout.size()));
            }
            return;
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(ptr, layout) }
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        #[cfg(target_os = "linux")]
        {
            // SAFETY: the caller guarantees that `new_size`, rounded up to
            // `layout.align()`, does not overflow `isize`.
            let new = unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
            match (mapped(layout), mapped(new)) {
                (true, true) => {
                    // SAFETY: `ptr` is a mapping of the old length made by
                    // `map`; the kernel moves it if it must (its advice
                    // goes with it).
                    let p = unsafe {
                        libc::mremap(
                            ptr.cast(),
                            mapping_len(layout.size()),
                            mapping_len(new_size),
                            libc::MREMAP_MAYMOVE,
                        )
                    };
                    return if p == libc::MAP_FAILED {
                        std::ptr::null_mut()
                    } else {
                        p.cast()
                    };
                }
                (false, false) => {}
                _ => {
                    // Across the threshold: a new block, the contents
                    // copied, the old block freed the way it came.
                    // SAFETY: `new` has a non-zero size (one side is at
                    // least the threshold, and the other is `layout`'s or
                    // `new_size`, non-zero by the caller's contract); the
                    // two blocks are distinct and each holds the bytes
                    // copied.
                    unsafe {
                        let p = self.alloc(new);
                        if !p.is_null() {
                            std::ptr::copy_nonoverlapping(ptr, p, layout.size().min(new_size));
                            self.dealloc(ptr, layout);
                        }
                        return p;
                    }
                }
            }
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// A fresh private anonymous mapping of at least `size` bytes, advised to
/// use huge pages; null when the kernel refuses the mapping (an
/// allocation failure, as `GlobalAlloc` reports it).
#[cfg(target_os = "linux")]
fn map(size: usize) -> *mut u8 {
    let len = mapping_len(size);
    // SAFETY: a new mapping at an address the kernel picks: no existing
    // memory is affected.
    let p = unsafe {
        libc::mmap(
            std::ptr::null_mut(),
            len,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
            -1,
            0,
        )
    };
    if p == libc::MAP_FAILED {
        return std::ptr::null_mut();
    }
    // SAFETY: advice on the mapping just made; its result changes no
    // memory (a kernel without transparent huge pages says EINVAL, which
    // is of no consequence).
    unsafe {
        libc::madvise(p, len, libc::MADV_HUGEPAGE);
    }
    p.cast()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Large and small blocks, plain and zeroed, grown and shrunk across
    /// the threshold, keep their contents and come back zeroed when asked.
    #[test]
    fn blocks_of_every_size_keep_their_contents() {
        for &n in &[1usize, 100, HUGE_THRESHOLD - 1, HUGE_THRESHOLD, 3 << 20] {
            let z = vec![0u8; n];
            assert!(z.iter().all(|&b| b == 0), "zeroed block of {n} bytes");
            let mut v: Vec<u32> = (0..n as u32 / 4 + 1).collect();
            v.extend(0..(HUGE_THRESHOLD as u32));
            v.truncate(n / 4 + 1);
            v.shrink_to_fit();
            assert!(
                v.iter().enumerate().all(|(i, &x)| x == i as u32),
                "{n} bytes"
            );
        }
    }
}
