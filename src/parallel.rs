//! Work over many independent items on every core (`--threads N`, default all).
//!
//! `std::thread::scope` rather than rayon: the work is coarse (one object's pre-evaluation,
//! microseconds to milliseconds each), one scoped pool per call costs a few tens of
//! microseconds, and the tree stays free of a work-stealing runtime and its build time. Items
//! are taken in contiguous chunks from a shared counter, so an uneven scene still balances, and
//! every result is written to its item's slot: the output is in input order and each item is
//! computed by the same code as on one thread, so results are bit for bit those of one thread.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Threads set by `--threads` (0: not set, use every core).
static THREADS: AtomicUsize = AtomicUsize::new(0);

/// Items a worker takes at once: large enough that the shared counter is not contended, small
/// enough that the last chunks balance.
const CHUNK: usize = 16;

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

/// Threads [`map`] uses: `--threads N`, else the cores available to the process.
#[must_use]
pub fn threads() -> usize {
    if let Some(n) = HERE.with(std::cell::Cell::get) {
        return n;
    }
    match THREADS.load(Ordering::Relaxed) {
        0 => std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get),
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
    let workers = threads.min(items.len().div_ceil(CHUNK));
    if workers <= 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, Vec<R>)>> = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                loop {
                    let start = next.fetch_add(CHUNK, Ordering::Relaxed);
                    if start >= items.len() {
                        break;
                    }
                    let end = (start + CHUNK).min(items.len());
                    let out: Vec<R> = items[start..end].iter().map(&f).collect();
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
}
