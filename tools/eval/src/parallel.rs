//! Independent jobs over a few threads, for the in-process experiments (`rins mc`, `rins sweep`).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

/// Runs `job(k)` for every k below `total` on at most `threads` threads and returns the results in
/// k's order, so that they do not depend on the number of threads. `progress(done, total)` is
/// called on the calling thread after each finished job. The first error stops the workers from
/// taking new jobs and is returned.
pub fn run_indexed<T: Send, E: Send>(
    total: usize,
    threads: usize,
    job: impl Fn(usize) -> Result<T, E> + Sync,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<T>, E> {
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let mut results: Vec<Option<T>> = (0..total).map(|_| None).collect();
    let mut first_error = None;
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel();
        for _ in 0..threads.clamp(1, total.max(1)) {
            let tx = tx.clone();
            let (job, next, stop) = (&job, &next, &stop);
            scope.spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= total || tx.send((k, job(k))).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        let mut done = 0;
        for (k, result) in rx {
            match result {
                Ok(value) => results[k] = Some(value),
                Err(e) => {
                    stop.store(true, Ordering::Relaxed);
                    first_error.get_or_insert(e);
                }
            }
            done += 1;
            progress(done, total);
        }
    });
    match first_error {
        Some(e) => Err(e),
        // Without an error every index was taken by exactly one worker and sent back.
        None => Ok(results.into_iter().flatten().collect()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_in_job_order_and_the_first_error_is_returned() {
        let mut seen = Vec::new();
        let squares = run_indexed(50, 3, |k| Ok::<_, ()>(k * k), |d, t| seen.push((d, t)));
        assert_eq!(squares, Ok((0..50).map(|k| k * k).collect::<Vec<_>>()));
        assert_eq!(seen.last(), Some(&(50, 50)));
        let failed = run_indexed(50, 2, |k| if k == 7 { Err(k) } else { Ok(k) }, |_, _| {});
        assert_eq!(failed, Err(7));
    }
}
