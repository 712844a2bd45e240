//! Work over many independent items on every core (`--threads N`, default all).
//!
//! `std::thread::scope` rather than rayon: the work is coarse (one object's pre-evaluation,
//! microseconds to milliseconds each), one scoped pool per call costs a few tens of
//! microseconds, and the tree stays free of a work-stealing runtime and its build time. Items
//! are taken in contiguous chunks from a shared counter, so an uneven scene still balances, and
//! every result is written to its item's slot: the output is in input order and each item is
//! computed by the same code as on one thread, so results are bit for bit those of one thread.

use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Threads set by `--threads` (0: not set, use every core).
static THREADS: AtomicUsize = AtomicUsize::new(0);

/// Most items a worker takes at once: large enough that the shared counter is not contended,
/// small enough that the last chunks balance. Lists of fewer than [`CHUNKS_PER_THREAD`] such
/// chunks per thread are taken in smaller chunks, down to one item: a CAD model's dozens of
/// faces each take milliseconds, and one chunk of 16 would leave the other threads idle.
const CHUNK: usize = 16;
const CHUNKS_PER_THREAD: usize = 4;

/// Sets the number of threads [`map`] uses (`--threads N`); 0 means every core.
pub fn set_threads(n: usize) {
    THREADS.store(n, Ordering::Relaxed);
}

thread_local! {
    /// A per-thread override of [`THREADS`] ([`on_one_thread`]).
    static HERE: std::cell::Cell<Option<usize>> = const { std::cell::Cell::new(None) };
}

/// Runs `f` with every [`map`] it calls on this thread kept on this thread (what a measurement
/// of one thread's allocations needs, without changing `--threads` for other threads).
pub fn on_one_thread<R>(f: impl FnOnce() -> R) -> R {
    let before = HERE.with(|h| h.replace(Some(1)));
    let r = f();
    HERE.with(|h| h.set(before));
    r
}

/// The cores available to the process, once known.
static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();

/// Threads [`map`] uses: `--threads N`, else the cores available to the process.
#[must_use]
pub fn threads() -> usize {
    if let Some(n) = HERE.with(std::cell::Cell::get) {
        return n;
    }
    match THREADS.load(Ordering::Relaxed) {
        // Asked once: the standard library reads the cgroup quota files on every call (a few
        // milliseconds of a 60 ms `info`).
        0 => *CORES.get_or_init(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        }),
        n => n,
    }
}

/// `items.iter().map(f).collect()`, on [`threads`] threads; the same results in the same order.
pub fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    map_with(threads(), items, f)
}

/// [`map`] on exactly `threads` threads (at most one per chunk of items).
pub fn map_with<T: Sync, R: Send>(
    threads: usize,
    items: &[T],
    f: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    let chunk = (items.len() / (threads.max(1) * CHUNKS_PER_THREAD)).clamp(1, CHUNK);
    let workers = threads.min(items.len().div_ceil(chunk));
    if workers <= 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, Vec<R>)>> = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                loop {
                    let start = next.fetch_add(chunk, Ordering::Relaxed);
                    if start >= items.len() {
                        break;
                    }
                    let end = (start + chunk).min(items.len());
                    // Each worker is one thread: work inside an item stays on it
                    // (for_each_mut), rather than spawning threads per item on a full machine.
                    let out: Vec<R> = on_one_thread(|| items[start..end].iter().map(&f).collect());
                    done.lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                        .push((start, out));
                }
            });
        }
    });
    let mut chunks = done
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    chunks.sort_unstable_by_key(|c| c.0);
    let mut out = Vec::with_capacity(items.len());
    for (_, c) in chunks {
        out.extend(c);
    }
    out
}

/// Rectangles of at least this many samples are split into row blocks across threads
/// ([`row_blocks`]); smaller ones (a single drag's support, small grids) take microseconds, less
/// than starting the threads.
pub const MIN_PARALLEL_SAMPLES: usize = 1 << 15;

/// Blocks per thread, so that uneven rows (degenerate normals, clamped ends) still balance.
const BLOCKS_PER_THREAD: usize = 4;

/// Splits sample rows `rows` of a rectangle `width` samples wide into contiguous blocks for
/// [`for_each_mut`]: every block but the last starts a multiple of `align` rows after
/// `rows.start`, so kernels that group `align` rows group them as on one thread. One block when
/// the rectangle is small or there is one thread.
#[must_use]
pub fn row_blocks(rows: Range<usize>, width: usize, align: usize) -> Vec<Range<usize>> {
    let threads = threads();
    let align = align.max(1);
    if threads <= 1 || rows.len() * width < MIN_PARALLEL_SAMPLES || rows.len() < 2 * align {
        return vec![rows];
    }
    let per = rows
        .len()
        .div_ceil(threads * BLOCKS_PER_THREAD)
        .next_multiple_of(align);
    (rows.start..rows.end)
        .step_by(per)
        .map(|s| s..(s + per).min(rows.end))
        .collect()
}

/// The parts of `data` (row-major, `row_len` values per row, starting at row 0) that hold the
/// rows of each of `blocks` (ascending, disjoint), as disjoint mutable slices.
#[must_use]
pub fn split_rows<'a, T>(
    mut data: &'a mut [T],
    blocks: &[Range<usize>],
    row_len: usize,
) -> Vec<&'a mut [T]> {
    let mut at = 0;
    let mut out = Vec::with_capacity(blocks.len());
    for b in blocks {
        let rest = std::mem::take(&mut data);
        let (_, rest) = rest.split_at_mut((b.start - at) * row_len);
        let (mine, rest) = rest.split_at_mut(b.len() * row_len);
        out.push(mine);
        data = rest;
        at = b.end;
    }
    out
}

/// Runs `f` on every item on [`threads`] threads, one item at a time (for a few coarse items,
/// such as the row blocks of one large rectangle). Each item is only touched by its own call, so
/// the results are those of one thread whatever the order the items are taken in.
pub fn for_each_mut<T: Send>(items: &mut [T], f: impl Fn(&mut T) + Sync) {
    let workers = threads().min(items.len());
    if workers <= 1 {
        items.iter_mut().for_each(f);
        return;
    }
    let queue = Mutex::new(items.iter_mut());
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                loop {
                    let next = queue
                        .lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                        .next();
                    match next {
                        Some(item) => f(item),
                        None => break,
                    }
                }
            });
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_are_in_input_order_on_any_number_of_threads() {
        let items: Vec<u64> = (0..1000).collect();
        let one = map_with(1, &items, |x| x * x + 1);
        for n in [2, 3, 8] {
            assert_eq!(map_with(n, &items, |x| x * x + 1), one);
        }
        // Negative control: the comparison sees a reordering.
        let mut swapped = one.clone();
        swapped.swap(0, 999);
        assert_ne!(swapped, one);
    }

    #[test]
    fn row_blocks_cover_the_rows_aligned_and_split_rows_matches_them() {
        set_threads(2);
        let blocks = row_blocks(3..515, 512, 4);
        set_threads(0);
        assert!(blocks.len() > 1, "a 512² rectangle is split: {blocks:?}");
        assert_eq!(blocks.first().map(|b| b.start), Some(3));
        assert_eq!(blocks.last().map(|b| b.end), Some(515));
        for w in blocks.windows(2) {
            assert_eq!(w[0].end, w[1].start);
            assert_eq!((w[0].start - 3) % 4, 0);
        }
        let mut data: Vec<usize> = (0..515 * 2).collect();
        let parts = split_rows(&mut data, &blocks, 2);
        for (b, p) in blocks.iter().zip(&parts) {
            assert_eq!(p.first(), Some(&(b.start * 2)));
            assert_eq!(p.len(), b.len() * 2);
        }
        // Small rectangles stay whole.
        assert_eq!(on_one_thread(|| row_blocks(0..512, 512, 4)), vec![0..512]);
        assert_eq!(row_blocks(0..8, 8, 4), vec![0..8]);
    }
}
