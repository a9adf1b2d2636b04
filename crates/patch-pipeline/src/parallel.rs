//! Independent runs on all cores, their results in input order: what makes an experiment's
//! output independent of the thread count.

use std::num::NonZeroUsize;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The thread count `threads` asks for, or one per core.
pub fn threads_or_cores(threads: Option<NonZeroUsize>) -> NonZeroUsize {
    threads.unwrap_or_else(|| std::thread::available_parallelism().unwrap_or(NonZeroUsize::MIN))
}

/// `f(0), f(1), …, f(n − 1)` on up to `threads` threads (each takes the next index when it is
/// done), returned in index order. With one thread, or one item, everything runs on the
/// calling thread. A panic in `f` propagates.
pub fn map_in_order<T: Send>(
    n: usize,
    threads: NonZeroUsize,
    f: impl Fn(usize) -> T + Sync,
) -> Vec<T> {
    let threads = threads.get().min(n);
    if threads <= 1 {
        return (0..n).map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let slots: Vec<Mutex<Option<T>>> = (0..n).map(|_| Mutex::new(None)).collect();
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= n {
                        break;
                    }
                    let value = f(i);
                    *slots[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(value);
                }
            });
        }
    });
    slots
        .into_iter()
        .map(|s| {
            s.into_inner().unwrap_or_else(|e| e.into_inner()).expect("every index is computed")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_in_index_order_for_any_thread_count() {
        let square = |i: usize| {
            // Uneven work, so that threads finish out of order.
            std::thread::sleep(std::time::Duration::from_micros(((i * 7919) % 13) as u64 * 50));
            i * i
        };
        let one = map_in_order(40, NonZeroUsize::MIN, square);
        for t in [2, 3, 8, 100] {
            assert_eq!(map_in_order(40, NonZeroUsize::new(t).unwrap(), square), one);
        }
        assert!(map_in_order(0, NonZeroUsize::new(4).unwrap(), square).is_empty());
    }
}
