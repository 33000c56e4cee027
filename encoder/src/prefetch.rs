//! Software prefetch: asking the cache for data a few steps before it is
//! read, where a chain of dependent loads would otherwise wait for memory
//! at each link.

/// Asks the cache for element `i` of `items` (all of its cache lines), where
/// the target has a prefetch instruction; a hint, never a fault.
#[inline(always)]
pub fn prefetch<T>(items: &[T], i: usize) {
    if let Some(x) = items.get(i) {
        prefetch_at(x as *const T);
    }
}

/// Asks the cache for the `T` at `at` (all of its cache lines). A prefetch
/// reads nothing the program sees and never faults, so any address will
/// do; callers pass addresses inside their arrays.
#[inline(always)]
pub fn prefetch_at<T>(at: *const T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let first = at.cast::<i8>();
        let last = first.wrapping_add(std::mem::size_of::<T>().max(1) - 1);
        // SAFETY: SSE is part of the x86-64 baseline, and a prefetch reads
        // nothing the program sees and never faults.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(first);
            if std::mem::size_of::<T>() > 64 {
                _mm_prefetch::<_MM_HINT_T0>(first.wrapping_add(64));
            }
            _mm_prefetch::<_MM_HINT_T0>(last);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}
