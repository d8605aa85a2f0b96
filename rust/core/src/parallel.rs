//! Independent jobs (channels, recordings) on scoped threads inside one call.
//!
//! Jobs are handed out longest first (the longest-processing-time rule: with unequal lengths
//! the threads finish close together) from one shared queue, one job at a time, so a thread
//! that drew short jobs takes more of them. The queue is touched once per job; each job
//! writes only its own output, so the threads share no cache line while they work. After the
//! first error no thread starts a new job, and the error of the lowest-numbered failing job
//! is returned (whatever the number of threads).
//!
//! Each thread reports what it did ([`ThreadStats`]): its jobs and samples, its wall time
//! from the call's start to its end, and, where Linux's `/proc/thread-self/schedstat` is
//! readable, its CPU time and the time it waited for a CPU while runnable (the sign of other
//! load on a shared machine). These say what limits the scaling without a profiler: unequal
//! work (samples), start-up (`start`), a thread that did not get a core (`wait`).

use crate::error::CoreError;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// What one worker thread did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ThreadStats {
    /// Jobs it ran.
    pub jobs: usize,
    /// Their total size (samples).
    pub samples: usize,
    /// Seconds from the call's start until the thread began work.
    pub start: f64,
    /// Seconds from the call's start until the thread ran out of jobs.
    pub end: f64,
    /// CPU seconds of the thread (None where schedstat is not available).
    pub cpu: Option<f64>,
    /// Seconds the thread was runnable but waited for a CPU (None where not available).
    pub wait: Option<f64>,
    /// Seconds of a first phase before the jobs (the pre-pass of
    /// `crate::masing::channels::force_channels`), 0 without one.
    pub prepass: f64,
    /// CPU seconds of that phase (None where not available or without one).
    pub prepass_cpu: Option<f64>,
}

/// `(on-CPU ns, run-queue wait ns)` of the calling thread from `/proc/thread-self/schedstat`.
pub(crate) fn schedstat() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let mut it = s.split_ascii_whitespace().map(str::parse::<u64>);
    match (it.next(), it.next()) {
        (Some(Ok(run)), Some(Ok(wait))) => Some((run, wait)),
        _ => None,
    }
}

/// Threads that pay: `asked`, capped by the CPUs this process may run on
/// (`available_parallelism`: the affinity mask and the cgroup quota) less the other
/// runnable tasks of the machine now (`/proc/loadavg`'s running count, this thread
/// excluded), at least one. A split onto a CPU that another task holds makes the call wait
/// for the slowest piece (1.3-1.8× slower than one thread at load 4 on two cores), so with
/// no idle CPU the work runs on one thread. Where `/proc/loadavg` is absent (not Linux) the
/// CPU count alone caps it.
pub fn threads_that_pay(asked: usize) -> usize {
    if asked <= 1 {
        return 1;
    }
    let cpus = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    let others = running_tasks().map_or(0, |r| r.saturating_sub(1));
    asked.min(cpus.saturating_sub(others)).max(1)
}

/// Runnable tasks of the machine now (`/proc/loadavg`'s fourth field `running/total`,
/// counting the reader).
fn running_tasks() -> Option<usize> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    let field = s.split_ascii_whitespace().nth(3)?;
    field.split('/').next()?.parse().ok()
}

/// Run `work(i, job)` for every job on `min(threads, jobs)` scoped threads (at least one),
/// longest first by `size(job)`. Returns the per-thread statistics (`cpu` and `wait` only
/// when `cpu_times`: two small file reads per thread), or the error of the lowest-numbered
/// job that failed.
pub fn run_jobs<J, S, W>(
    jobs: Vec<J>,
    threads: usize,
    cpu_times: bool,
    size: S,
    work: W,
) -> Result<Vec<ThreadStats>, CoreError>
where
    J: Send,
    S: Fn(&J) -> usize,
    W: Fn(usize, J) -> Result<(), CoreError> + Sync,
{
    let t0 = Instant::now();
    let mut queue: Vec<(usize, usize, J)> = jobs
        .into_iter()
        .enumerate()
        .map(|(i, j)| (i, size(&j), j))
        .collect();
    // Popped from the end: the longest last in the vector; ties in channel order.
    queue.sort_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)));
    let workers = threads.min(queue.len()).max(1);
    let queue = Mutex::new(queue);
    let failed = AtomicBool::new(false);
    let worker = || -> (ThreadStats, Option<(usize, CoreError)>) {
        let before = if cpu_times { schedstat() } else { None };
        let mut st = ThreadStats {
            start: t0.elapsed().as_secs_f64(),
            ..ThreadStats::default()
        };
        let mut err = None;
        while !failed.load(Ordering::Relaxed) {
            let job = match queue.lock() {
                Ok(mut q) => q.pop(),
                Err(_) => None,
            };
            let Some((i, n, j)) = job else { break };
            st.jobs = st.jobs.saturating_add(1);
            st.samples = st.samples.saturating_add(n);
            if let Err(e) = work(i, j) {
                failed.store(true, Ordering::Relaxed);
                err = Some((i, e));
                break;
            }
        }
        st.end = t0.elapsed().as_secs_f64();
        if let (Some(a), Some(b)) = (before, before.and_then(|_| schedstat())) {
            st.cpu = Some(b.0.saturating_sub(a.0) as f64 * 1e-9);
            st.wait = Some(b.1.saturating_sub(a.1) as f64 * 1e-9);
        }
        (st, err)
    };
    let results: Vec<(ThreadStats, Option<(usize, CoreError)>)> = if workers == 1 {
        vec![worker()]
    } else {
        // the calling thread is one of the workers: it starts at once, and one thread
        // fewer waits to be woken on a core (on a VM a few milliseconds)
        std::thread::scope(|s| {
            let handles: Vec<_> = (1..workers).map(|_| s.spawn(worker)).collect();
            let mine = worker();
            std::iter::once(mine)
                .chain(
                    handles
                        .into_iter()
                        .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p))),
                )
                .collect()
        })
    };
    let mut stats = Vec::with_capacity(results.len());
    let mut first: Option<(usize, CoreError)> = None;
    for (st, err) in results {
        stats.push(st);
        if let Some((i, e)) = err {
            if first.as_ref().is_none_or(|(k, _)| i < *k) {
                first = Some((i, e));
            }
        }
    }
    match first {
        Some((_, e)) => Err(e),
        None => Ok(stats),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threads_that_pay_stay_within_what_was_asked() {
        assert_eq!(threads_that_pay(0), 1);
        assert_eq!(threads_that_pay(1), 1);
        let t = threads_that_pay(64);
        assert!((1..=64).contains(&t));
        let cpus = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
        assert!(t <= cpus);
        assert!(running_tasks().is_none_or(|r| r >= 1));
    }

    #[test]
    fn every_job_runs_once_longest_first_and_stats_add_up() {
        for threads in [1, 2, 3, 8] {
            let lens = [5_usize, 300, 0, 42, 300, 7];
            let done = Mutex::new(Vec::new());
            let stats = run_jobs(
                lens.to_vec(),
                threads,
                true,
                |n| *n,
                |i, n| {
                    done.lock().unwrap().push((i, n));
                    Ok(())
                },
            )
            .unwrap();
            let mut got = done.into_inner().unwrap();
            if threads == 1 {
                // one thread: strictly longest first, ties in channel order
                let order: Vec<usize> = got.iter().map(|p| p.0).collect();
                assert_eq!(order, vec![1, 4, 3, 5, 0, 2]);
            }
            got.sort_unstable();
            assert_eq!(got, lens.iter().copied().enumerate().collect::<Vec<_>>());
            assert_eq!(stats.len(), threads.min(lens.len()));
            assert_eq!(stats.iter().map(|s| s.jobs).sum::<usize>(), lens.len());
            assert_eq!(
                stats.iter().map(|s| s.samples).sum::<usize>(),
                lens.iter().sum::<usize>()
            );
            for s in &stats {
                assert!(s.start >= 0.0 && s.end >= s.start);
                if let (Some(c), Some(w)) = (s.cpu, s.wait) {
                    assert!(c >= 0.0 && w >= 0.0);
                }
                // where Linux reports them, CPU times come when asked for
                let linux = std::path::Path::new("/proc/thread-self/schedstat").exists();
                assert_eq!(s.cpu.is_some(), linux);
            }
        }
    }

    #[test]
    fn the_lowest_failing_job_wins_whatever_the_threads() {
        for threads in [1, 2, 4] {
            let r = run_jobs(
                (0..9_usize).collect(),
                threads,
                false,
                |_| 1,
                |i, _| {
                    if i == 3 || i == 6 {
                        Err(CoreError::NonFinite {
                            name: "x",
                            index: i,
                            value: f64::NAN,
                        })
                    } else {
                        Ok(())
                    }
                },
            );
            // equal sizes go in channel order: job 3 is always taken before job 6
            match r {
                Err(CoreError::NonFinite { index, .. }) => assert_eq!(index, 3),
                other => panic!("{other:?}"),
            }
        }
        assert!(
            run_jobs(Vec::<usize>::new(), 2, false, |_| 0, |_, _| Ok(()))
                .unwrap()
                .iter()
                .all(|s| s.jobs == 0)
        );
    }
}
