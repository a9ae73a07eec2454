//! Small helpers for deterministic parallel loops: fixed-size chunks, per-chunk partial sums
//! reduced sequentially in chunk order, and a pointer wrapper for disjoint row writes.

/// Items per parallel task for element and vector loops.
pub const CHUNK: usize = 512;

/// A raw pointer that may be shared across threads. Safety: the users write disjoint indices.
#[derive(Clone, Copy)]
pub struct SyncPtr<T>(pub *mut T);
// SAFETY: only used for writes to disjoint elements, from one thread per element.
unsafe impl<T> Sync for SyncPtr<T> {}
// SAFETY: as above.
unsafe impl<T> Send for SyncPtr<T> {}

impl<T> SyncPtr<T> {
    /// Pointer to element `i`.
    ///
    /// # Safety
    /// `i` must be in bounds and no other thread may touch element `i` meanwhile.
    #[inline]
    pub unsafe fn at(&self, i: usize) -> *mut T {
        unsafe { self.0.add(i) }
    }
}

/// Number of chunks of `CHUNK` items covering `n` items.
pub fn chunks(n: usize, chunk: usize) -> usize {
    n.div_ceil(chunk)
}

/// Sums `partials` in order (the deterministic reduction of per-chunk sums).
pub fn ordered_sum(partials: &[f64]) -> f64 {
    partials.iter().fold(0.0, |a, b| a + b)
}

/// Below this many particles, loops run on the calling thread: handing work to other threads
/// costs more than it saves. Set low: a multigrid V-cycle alternates between levels of very
/// different sizes, and worker threads left idle through the small levels go to sleep and
/// must be woken for the next large one (measured on the 64² hang, interleaved runs: the
/// fastest of five runs 3.40–4.62 ms per substep at 200 against 3.44–5.54 ms at 800).
pub const PAR_MIN: usize = 200;

/// Calls `f(i)` for `i in 0..count`, in parallel when `par`.
#[inline]
pub fn for_each_index<F: Fn(usize) + Sync + Send>(count: usize, par: bool, f: F) {
    use rayon::prelude::*;
    if par {
        (0..count).into_par_iter().for_each(f);
    } else {
        (0..count).for_each(f);
    }
}

/// Calls `f(i, &mut items[i])` for every item, over chunks of `CHUNK` in parallel when `par`.
#[inline]
pub fn for_each_mut<T: Send, F: Fn(usize, &mut T) + Sync + Send>(items: &mut [T], par: bool, f: F) {
    use rayon::prelude::*;
    if par {
        items
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                for (k, item) in chunk.iter_mut().enumerate() {
                    f(c * CHUNK + k, item);
                }
            });
    } else {
        items
            .iter_mut()
            .enumerate()
            .for_each(|(i, item)| f(i, item));
    }
}

/// Copies `src` to `dst` with non-temporal stores where the CPU has them and `dst` is 8-byte
/// aligned: for large arrays written once per step and read only later (the assembled
/// matrix's copies at 256² are 80 MB, beyond the last-level cache), streaming stores skip the
/// read of each destination cache line that an ordinary store makes first. Whoever calls it
/// must call [`stream_fence`] before another thread reads `dst`.
///
/// # Safety
/// `dst` must be valid for writing `src.len()` values of `T`, which must be plain data.
#[inline]
pub unsafe fn stream_copy<T: Copy>(dst: *mut T, src: &[T]) {
    let bytes = std::mem::size_of_val(src);
    #[cfg(target_arch = "x86_64")]
    {
        if bytes.is_multiple_of(8) && (dst as usize).is_multiple_of(8) {
            use std::arch::x86_64::_mm_stream_si64;
            let (d, s) = (dst as *mut i64, src.as_ptr() as *const i64);
            for k in 0..bytes / 8 {
                // SAFETY: in bounds by the caller's contract; `d` is 8-byte aligned and `s`
                // is read unaligned.
                unsafe { _mm_stream_si64(d.add(k), s.add(k).read_unaligned()) };
            }
            return;
        }
    }
    // SAFETY: forwarded from the caller.
    unsafe { std::ptr::copy_nonoverlapping(src.as_ptr(), dst, src.len()) };
}

/// Orders this thread's earlier non-temporal stores before its later stores (and so before
/// the end of a parallel pass is seen by other threads).
#[inline]
pub fn stream_fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of x86_64.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}
