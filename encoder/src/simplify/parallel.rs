//! Small data-parallel helpers of the step loop (rayon).

use rayon::prelude::*;

/// The values `f` gives for `items`, in order, into `out` (cleared first):
/// the step's large lists keep their capacity from step to step instead of
/// faulting fresh pages in (a few percent of the run).
pub(super) fn par_filter_into<T: Sync, U: Send>(
    items: &[T],
    out: &mut Vec<U>,
    f: impl Fn(&T) -> Option<U> + Sync + Send,
) {
    out.clear();
    for part in par_chunks_map(items, |chunk| {
        chunk.iter().filter_map(&f).collect::<Vec<U>>()
    }) {
        out.extend(part);
    }
}

/// `f` over consecutive chunks of `items` in parallel, the results in
/// order. Each chunk fills its own buffers: no allocation per item and no
/// merging copies (rayon's fold/reduce re-copies at every level).
pub(super) fn par_chunks_map<T: Sync, R: Send>(
    items: &[T],
    f: impl Fn(&[T]) -> R + Sync + Send,
) -> Vec<R> {
    items.par_chunks(chunk_size(items.len())).map(f).collect()
}

/// The chunk length of the data-parallel passes over `len` items.
pub(super) fn chunk_size(len: usize) -> usize {
    (len / (8 * rayon::current_num_threads())).clamp(512, 16384)
}
