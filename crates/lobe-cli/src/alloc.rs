//! The process's allocator: the system's, except that under `lobe render`
//! large blocks are mappings of their own that the kernel may back with
//! 2 MiB pages (Linux's transparent huge pages in `madvise` mode, the
//! common default).
//!
//! `lobe render` reads a map into a few buffers of megabytes (a 1024 × 512
//! map: 8 MiB of texels, two samplers' tables of 6 MiB each) and touches
//! every page of them once, at start: with 4 KiB pages that is thousands
//! of page faults, a tenth of a short render's time. A block of
//! [`HUGE_THRESHOLD`] bytes or more is `mmap`ed directly (zeroed by the
//! kernel, so `alloc_zeroed` touches nothing) and `madvise`d
//! `MADV_HUGEPAGE` before its first touch, which glibc's `malloc` cannot
//! do (it writes its header into the block first). Advice only: where the
//! kernel has no huge pages to give, or on other systems, nothing changes
//! but the page size.
//!
//! Only `render` asks for it ([`Allocator::use_huge_pages`], called by `main` before
//! any large block exists): `lobe bench`'s kernels stream several arrays
//! of megabytes at the same index, and with 2 MiB pages those arrays sit at
//! the same offsets of their physical pages, so that they compete for the
//! same cache sets (measured: 8–12% fewer samples per second for GGX brdf
//! on a Zen 3); and glibc reuses a freed large block for the next one where
//! a mapping of its own would be faulted in anew.

use std::alloc::{GlobalAlloc, Layout, System};

use std::sync::atomic::{AtomicU8, Ordering};

/// Blocks at least this large (and aligned to at most a page) get a
/// mapping of their own, once [`Allocator::use_huge_pages`] has switched it on.
pub const HUGE_THRESHOLD: usize = 1 << 20;

/// The system allocator, with large blocks mapped on their own and
/// advised to use huge pages (Linux) when its switch is on, see the module
/// doc. The switch is set at most once, before any large block exists, so
/// that every block is freed the way it was allocated.
pub struct Allocator {
    state: AtomicU8,
}

/// No large block yet, switch off.
const UNSET: u8 = 0;
/// Large blocks come from the system allocator (a large block was
/// allocated before the switch, or the switch said no).
const OFF: u8 = 1;
/// Large blocks are mappings of their own.
const ON: u8 = 2;

impl Allocator {
    #[must_use]
    pub const fn new() -> Self {
        Allocator {
            state: AtomicU8::new(UNSET),
        }
    }

    /// Switch the huge-page mappings on (`true`) or keep them off, once:
    /// the first call decides, if no large block was allocated before it;
    /// later calls change nothing. Returns whether they are on.
    pub fn use_huge_pages(&self, on: bool) -> bool {
        self.decide(if on { ON } else { OFF })
    }

    /// Set the switch to `want` if it is still unset; whether it is on.
    fn decide(&self, want: u8) -> bool {
        let _ = self
            .state
            .compare_exchange(UNSET, want, Ordering::AcqRel, Ordering::Acquire);
        self.state.load(Ordering::Acquire) == ON
    }

    /// Whether a block of `layout` is (or gets) a mapping of its own; the
    /// first large block decides the switch for good if nothing did.
    #[cfg(target_os = "linux")]
    #[inline]
    fn mapped(&self, layout: Layout) -> bool {
        if layout.size() < HUGE_THRESHOLD || layout.align() > PAGE {
            return false;
        }
        match self.state.load(Ordering::Acquire) {
            ON => true,
            OFF => false,
            _ => self.decide(OFF),
        }
    }
}

impl Default for Allocator {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(target_os = "linux")]
const PAGE: usize = 4096;

#[cfg(target_os = "linux")]
#[inline]
fn mapping_len(size: usize) -> usize {
    size.next_multiple_of(PAGE)
}

// SAFETY: every block comes from `System` or from `mmap`, and goes back the
// way it came: `self.mapped(layout)` depends only on the layout (which the
// caller passes unchanged to `dealloc` and `realloc`) and on the switch,
// which is decided before the first large block and never changes after.
unsafe impl GlobalAlloc for Allocator {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        #[cfg(target_os = "linux")]
        if self.mapped(layout) {
            return map(layout.size());
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc(layout) }
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        #[cfg(target_os = "linux")]
        if self.mapped(layout) {
            // (A fresh anonymous mapping reads as zeros.)
            return map(layout.size());
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc_zeroed(layout) }
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        #[cfg(target_os = "linux")]
        if self.mapped(layout) {
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
            match (self.mapped(layout), self.mapped(new)) {
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

    /// Large and small blocks of an allocator switched on, plain and
    /// zeroed, grown and shrunk across the threshold (`mremap` between two
    /// mappings, a copy across), keep their contents and come back zeroed
    /// when asked; the switch is decided once.
    #[test]
    fn blocks_of_every_size_keep_their_contents() {
        let a = Allocator::new();
        assert!(a.use_huge_pages(true));
        assert!(a.use_huge_pages(false), "the first call decides");
        let sizes = [1usize, 100, HUGE_THRESHOLD - 1, HUGE_THRESHOLD, 3 << 20];
        for &n in &sizes {
            let l = Layout::from_size_align(n, 8).unwrap();
            // SAFETY: non-zero sizes; each block freed once with its
            // layout, by the allocator that made it.
            unsafe {
                let z = a.alloc_zeroed(l);
                assert!(!z.is_null());
                assert!((0..n).all(|i| *z.add(i) == 0), "zeroed block of {n} bytes");
                for i in 0..n {
                    *z.add(i) = (i % 251) as u8;
                }
                for &m in &sizes {
                    let p = a.alloc(l);
                    assert!(!p.is_null());
                    std::ptr::copy_nonoverlapping(z, p, n);
                    let q = a.realloc(p, l, m);
                    assert!(!q.is_null());
                    let kept = n.min(m);
                    assert!(
                        (0..kept).all(|i| *q.add(i) == (i % 251) as u8),
                        "{n} -> {m} bytes"
                    );
                    a.dealloc(q, Layout::from_size_align(m, 8).unwrap());
                }
                a.dealloc(z, l);
            }
        }
        // An allocator whose first large block came before the switch
        // keeps the system's blocks.
        let b = Allocator::new();
        let l = Layout::from_size_align(HUGE_THRESHOLD, 8).unwrap();
        // SAFETY: as above.
        unsafe {
            let p = b.alloc(l);
            assert!(!p.is_null());
            assert!(!b.use_huge_pages(true));
            b.dealloc(p, l);
        }
    }
}
