//! Work spread over rayon's pool (feature `parallel`) with results in a
//! fixed order, so that the numbers do not depend on the thread count.

/// `(0..n).map(f)` collected in index order: on rayon's pool with the
/// feature `parallel`, else on this thread.
#[cfg(feature = "parallel")]
pub(crate) fn map_indices<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    use rayon::prelude::*;
    (0..n).into_par_iter().map(f).collect()
}

/// `(0..n).map(f)` collected in index order: on rayon's pool with the
/// feature `parallel`, else on this thread.
#[cfg(not(feature = "parallel"))]
pub(crate) fn map_indices<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    (0..n).map(f).collect()
}
