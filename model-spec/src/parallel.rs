//! Work shared out over the machine's cores in contiguous parts, for the readers and fits of
//! long records: each part computed alone, the results in the order of the parts, so that the
//! outcome (values, and which error comes first) is that of doing the parts one after the
//! other.

use std::thread;

/// The threads worth using for `items` pieces of work: one per core
/// ([`thread::available_parallelism`]), each with `per_thread` items at least; 1 when there
/// are fewer.
pub fn threads_for(items: usize, per_thread: usize) -> usize {
    thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(items / per_thread.max(1))
        .max(1)
}

/// `f` of every part, in the order of `parts`: the first part on the calling thread, each
/// other on a thread of its own (one part alone is done on the calling thread). A part that
/// panics panics the caller, after every part has finished.
pub fn map_parts<T: Send, R: Send>(parts: Vec<T>, f: impl Fn(T) -> R + Sync) -> Vec<R> {
    if parts.len() <= 1 {
        return parts.into_iter().map(f).collect();
    }
    let f = &f;
    thread::scope(|s| {
        let mut parts = parts.into_iter();
        let first = parts.next();
        let others: Vec<_> = parts.map(|p| s.spawn(move || f(p))).collect();
        let mut done: Vec<R> = first.into_iter().map(f).collect();
        for h in others {
            done.push(
                h.join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            );
        }
        done
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Results come in the order of the parts, whichever finishes first; a part may borrow
    /// mutably what no other part holds.
    #[test]
    fn parts_come_back_in_order() {
        for n in [0usize, 1, 2, 5] {
            let parts: Vec<usize> = (0..n).collect();
            let done = map_parts(parts, |p| {
                let spin = (n - p) * 10_000;
                (0..spin).fold(p * p, |a, _| std::hint::black_box(a))
            });
            assert_eq!(done, (0..n).map(|p| p * p).collect::<Vec<_>>());
        }
        let mut data = vec![0u32; 10];
        let parts: Vec<&mut [u32]> = data.chunks_mut(3).collect();
        map_parts(parts, |part| part.iter_mut().for_each(|x| *x += 1));
        assert_eq!(data, vec![1; 10]);
    }

    #[test]
    fn threads_for_needs_enough_items_per_thread() {
        assert_eq!(threads_for(0, 100), 1);
        assert_eq!(threads_for(199, 100), 1);
        assert!(threads_for(1_000_000, 100) >= 1);
        assert_eq!(threads_for(5, 0), threads_for(5, 1));
    }
}
