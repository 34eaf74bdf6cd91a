//! Output memory of the array calls, kept for reuse.
//!
//! A fresh result array of millions of values costs a page fault per page
//! the kernels first touch: the kernel zeroes every page before the first
//! write, which for the 190 MB of a `sample` + `eval_pdf` pair at N = 2²²
//! takes about as long as the kernels themselves. When a result array dies
//! its buffer comes back here (the Python glue ties each array to a
//! [`Pooled`] owner whose drop calls [`give`]), and the next call of the
//! same size takes it instead of new memory: a loop that calls `sample`
//! with fresh arrays runs at the speed of `out=`.
//!
//! Only buffers of at least [`MIN_BYTES`] are kept, up to [`limit`] bytes in
//! all (the rest is freed as usual); [`clear`] frees what is kept. A taken
//! buffer holds the values of its last use: every caller overwrites all of
//! them (the kernels write every output) or zeroes it itself.

use std::sync::Mutex;

/// Smaller buffers are left to the allocator, which is fast for them.
pub const MIN_BYTES: usize = 1 << 20;

/// The default of [`limit`]: 1 GiB.
pub const DEFAULT_LIMIT: usize = 1 << 30;

/// A buffer of one of the element types the results use.
pub enum Buffer {
    F32(Vec<f32>),
    F64(Vec<f64>),
    U8(Vec<u8>),
}

impl Buffer {
    fn bytes(&self) -> usize {
        match self {
            Buffer::F32(v) => v.len() * 4,
            Buffer::F64(v) => v.len() * 8,
            Buffer::U8(v) => v.len(),
        }
    }
}

struct Kept {
    buffers: Vec<Buffer>,
    bytes: usize,
    limit: usize,
}

static POOL: Mutex<Kept> = Mutex::new(Kept {
    buffers: Vec::new(),
    bytes: 0,
    limit: DEFAULT_LIMIT,
});

fn pool() -> std::sync::MutexGuard<'static, Kept> {
    // A panic while the lock was held cannot leave the list inconsistent
    // (each change is one push or one remove), so a poisoned lock is used.
    POOL.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Element types the pool keeps.
pub trait Element: Copy + Default + Send + 'static {
    fn wrap(v: Vec<Self>) -> Buffer;
    fn unwrap(b: Buffer) -> Result<Vec<Self>, Buffer>;
    /// Whether `b` holds `n` values of this type.
    fn matches(b: &Buffer, n: usize) -> bool;
}

impl Element for f32 {
    fn wrap(v: Vec<f32>) -> Buffer {
        Buffer::F32(v)
    }
    fn unwrap(b: Buffer) -> Result<Vec<f32>, Buffer> {
        match b {
            Buffer::F32(v) => Ok(v),
            other => Err(other),
        }
    }
    fn matches(b: &Buffer, n: usize) -> bool {
        matches!(b, Buffer::F32(v) if v.len() == n)
    }
}

impl Element for f64 {
    fn wrap(v: Vec<f64>) -> Buffer {
        Buffer::F64(v)
    }
    fn unwrap(b: Buffer) -> Result<Vec<f64>, Buffer> {
        match b {
            Buffer::F64(v) => Ok(v),
            other => Err(other),
        }
    }
    fn matches(b: &Buffer, n: usize) -> bool {
        matches!(b, Buffer::F64(v) if v.len() == n)
    }
}

impl Element for u8 {
    fn wrap(v: Vec<u8>) -> Buffer {
        Buffer::U8(v)
    }
    fn unwrap(b: Buffer) -> Result<Vec<u8>, Buffer> {
        match b {
            Buffer::U8(v) => Ok(v),
            other => Err(other),
        }
    }
    fn matches(b: &Buffer, n: usize) -> bool {
        matches!(b, Buffer::U8(v) if v.len() == n)
    }
}

/// A kept buffer of exactly `n` values of `T` (holding the values of its
/// last use), if there is one.
#[must_use]
pub fn take<T: Element>(n: usize) -> Option<Vec<T>> {
    if n * std::mem::size_of::<T>() < MIN_BYTES {
        return None;
    }
    let mut p = pool();
    let i = p.buffers.iter().position(|b| T::matches(b, n))?;
    let b = p.buffers.remove(i);
    p.bytes -= b.bytes();
    T::unwrap(b).ok()
}

/// Keep `v` for a later [`take`] if it is large enough and the pool has
/// room; otherwise free it. When full, the oldest kept buffers make room.
pub fn give<T: Element>(v: Vec<T>) {
    let b = T::wrap(v);
    let bytes = b.bytes();
    if bytes < MIN_BYTES {
        return;
    }
    let mut p = pool();
    if bytes > p.limit {
        return;
    }
    while p.bytes + bytes > p.limit {
        let old = p.buffers.remove(0);
        p.bytes -= old.bytes();
    }
    p.bytes += bytes;
    p.buffers.push(b);
}

/// Set the most bytes kept (0 keeps nothing); frees what is over it.
pub fn set_limit(bytes: usize) {
    let mut p = pool();
    p.limit = bytes;
    while p.bytes > p.limit {
        let old = p.buffers.remove(0);
        p.bytes -= old.bytes();
    }
}

/// The most bytes kept, and the bytes kept now.
#[must_use]
pub fn limit() -> (usize, usize) {
    let p = pool();
    (p.limit, p.bytes)
}

/// Free every kept buffer.
pub fn clear() {
    let mut p = pool();
    p.buffers.clear();
    p.bytes = 0;
}

#[cfg(test)]
mod tests {
    use super::*;

    // One test for the whole module: the pool is process-wide.
    #[test]
    fn buffers_come_back_by_type_and_length_within_the_limit() {
        clear();
        let n = MIN_BYTES / 4;
        assert!(take::<f32>(n).is_none());
        let mut v = vec![0f32; n];
        v[0] = 7.0;
        let ptr = v.as_ptr();
        give(v);
        assert_eq!(limit().1, n * 4);
        // Another length or type does not match.
        assert!(take::<f32>(n + 1).is_none());
        assert!(take::<u8>(n * 4).is_none());
        let w = take::<f32>(n).expect("kept");
        assert_eq!((w.as_ptr(), w[0]), (ptr, 7.0));
        assert_eq!(limit().1, 0);
        // Small buffers are not kept.
        give(vec![0u8; 100]);
        assert_eq!(limit().1, 0);
        // The limit evicts the oldest.
        set_limit(2 * MIN_BYTES);
        give(w);
        give(vec![1u8; MIN_BYTES]);
        give(vec![2u8; MIN_BYTES]);
        assert_eq!(limit(), (2 * MIN_BYTES, 2 * MIN_BYTES));
        assert!(take::<f32>(n).is_none(), "the oldest was freed");
        assert_eq!(take::<u8>(MIN_BYTES).map(|v| v[0]), Some(1));
        set_limit(0);
        assert_eq!(limit(), (0, 0));
        give(vec![0u8; MIN_BYTES]);
        assert_eq!(limit().1, 0);
        set_limit(DEFAULT_LIMIT);
        clear();
    }
}
