//! Independent pieces of work spread over the machine's cores, their results in the order of
//! the work: the same results, bit for bit, as a loop that does them one after the other
//! (each piece computes alone; nothing is summed across pieces here).

use model_spec::parallel;
use std::thread;

/// `f` of every item, in the order of `items`, computed on up to
/// [`thread::available_parallelism`] threads (the calling thread among them). With one core,
/// or one item, the items are done in turn on the calling thread.
pub(crate) fn map_in_order<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let workers = thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len());
    if workers <= 1 {
        return items.iter().map(f).collect();
    }
    // Worker w takes the items w, w + workers, … (pieces of unequal cost spread evenly).
    let f = &f;
    let parts: Vec<Vec<(usize, R)>> = thread::scope(|s| {
        let others: Vec<_> = (1..workers)
            .map(|w| s.spawn(move || strided(items, w, workers, f)))
            .collect();
        let mut parts = vec![strided(items, 0, workers, f)];
        parts.extend(others.into_iter().map(|h| match h.join() {
            Ok(p) => p,
            Err(panic) => std::panic::resume_unwind(panic),
        }));
        parts
    });
    let mut done: Vec<(usize, R)> = parts.into_iter().flatten().collect();
    done.sort_unstable_by_key(|&(k, _)| k);
    done.into_iter().map(|(_, r)| r).collect()
}

/// `f` of every column of `data` (columns of `n` values one after the other), each column
/// changed alone, the columns shared out in contiguous runs over up to
/// [`thread::available_parallelism`] threads. Fewer than `MIN_COLUMNS` columns per thread are
/// not worth a thread.
pub(crate) fn for_each_column(data: &mut [f64], n: usize, f: impl Fn(&mut [f64]) + Sync) {
    const MIN_COLUMNS: usize = 64;
    if n == 0 {
        return;
    }
    let columns = data.len() / n;
    let workers = parallel::threads_for(columns, MIN_COLUMNS);
    let each = |part: &mut [f64]| part.chunks_exact_mut(n).for_each(&f);
    if workers == 1 {
        return each(data);
    }
    let run = columns.div_ceil(workers) * n;
    parallel::map_parts(data.chunks_mut(run).collect(), each);
}

/// `f` of the items `first`, `first + step`, …, with their indices.
fn strided<T, R>(items: &[T], first: usize, step: usize, f: &impl Fn(&T) -> R) -> Vec<(usize, R)> {
    (first..items.len())
        .step_by(step)
        .map(|k| (k, f(&items[k])))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::map_in_order;

    #[test]
    fn results_come_in_the_order_of_the_items() {
        for n in [0, 1, 2, 3, 17] {
            let items: Vec<u64> = (0..n).collect();
            let squares = map_in_order(&items, |&x| {
                // Unequal costs, so the workers finish out of order.
                let spin = (n - x) * 1000;
                (0..spin).fold(x * x, |a, _| std::hint::black_box(a))
            });
            assert_eq!(squares, items.iter().map(|x| x * x).collect::<Vec<_>>());
        }
    }
}
