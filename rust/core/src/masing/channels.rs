//! Forces of several channels on scoped threads: one queue of jobs (the pre-passes of the
//! channels chosen for splitting, whole channels, pieces), bit for bit the serial kernel.

use super::split::{force_piece, split_each, Walked};
use super::{BranchRule, MasingState};
use crate::curve::Backbone;
use crate::error::CoreError;
use crate::parallel::{schedstat, ThreadStats};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Instant;

/// A channel's model, as [`force_channels`] sees it.
pub trait Channel: Sync {
    /// The pieces of `x` from `state`, each boundary to `emit` as found ([`split_each`];
    /// [`Walked::Whole`] for a branch rule other than the scaled one).
    fn split(
        &self,
        x: &[f64],
        state: &MasingState,
        piece: usize,
        emit: &mut dyn FnMut(usize, MasingState) -> bool,
    ) -> Result<Walked, CoreError>;
    /// One piece ([`force_piece`]).
    fn piece(&self, x: &[f64], out: &mut [f64], state: &mut MasingState)
        -> Result<bool, CoreError>;
    /// The whole channel, serially (`masing_force_rule`).
    fn whole(&self, x: &[f64], out: &mut [f64], state: &mut MasingState) -> Result<(), CoreError>;
}

/// A curve and a branch rule: a [`Channel`].
pub struct Model<'a, C> {
    pub curve: &'a C,
    pub rule: BranchRule,
}

impl<C: Backbone + Sync> Channel for Model<'_, C> {
    fn split(
        &self,
        x: &[f64],
        state: &MasingState,
        piece: usize,
        emit: &mut dyn FnMut(usize, MasingState) -> bool,
    ) -> Result<Walked, CoreError> {
        match self.rule {
            BranchRule::Scaled(l) => split_each(self.curve, l, x, state, piece, emit),
            BranchRule::Anchored(_) => Ok(Walked::Whole),
        }
    }
    fn piece(
        &self,
        x: &[f64],
        out: &mut [f64],
        state: &mut MasingState,
    ) -> Result<bool, CoreError> {
        match self.rule {
            BranchRule::Scaled(l) => force_piece(self.curve, l, x, out, state),
            BranchRule::Anchored(_) => Err(CoreError::InvalidState {
                reason: "anchored branches are not split",
            }),
        }
    }
    fn whole(&self, x: &[f64], out: &mut [f64], state: &mut MasingState) -> Result<(), CoreError> {
        super::masing_force_rule(self.curve, self.rule, x, out, state)
    }
}

/// A unit of work of [`force_channels`].
enum Work<'a> {
    /// Run the pre-pass of a channel, queueing its pieces as their boundaries are found.
    Split { x: &'a [f64], out: &'a mut [f64] },
    /// A piece of a split channel, from its start state; the last one's run gives the
    /// channel's end state.
    Piece {
        x: &'a [f64],
        out: &'a mut [f64],
        state: MasingState,
        last: bool,
    },
    /// A whole channel, serially.
    Whole { x: &'a [f64], out: &'a mut [f64] },
}

/// A queued unit: popped by (`rank`, samples) largest first, then in order of queueing.
struct Job<'a> {
    channel: usize,
    rank: u8,
    size: usize,
    seq: usize,
    work: Work<'a>,
}

impl Job<'_> {
    fn key(&self) -> (u8, usize, std::cmp::Reverse<usize>) {
        (self.rank, self.size, std::cmp::Reverse(self.seq))
    }
}
impl PartialEq for Job<'_> {
    fn eq(&self, o: &Self) -> bool {
        self.key() == o.key()
    }
}
impl Eq for Job<'_> {}
impl PartialOrd for Job<'_> {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Job<'_> {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.key().cmp(&o.key())
    }
}

/// The shared queue: jobs, and pre-passes not finished (more pieces may come).
struct Queue<'a> {
    jobs: std::collections::BinaryHeap<Job<'a>>,
    pending: usize,
    seq: usize,
}

/// What one channel's run came to.
#[derive(Default)]
struct Outcome {
    error: Option<CoreError>,
    end: Option<MasingState>,
    nonfinite: bool,
}

/// Which channels to split (`threads > 1`): any longer than an even share of the total
/// (it would hold one thread up), then the shortest splittable ones until the split total
/// reaches the longest channel, so that the pieces can even out what whole channels leave
/// unequal (threads of unequal speed included) while as little as possible pays the
/// pre-pass.
fn to_split(lens: &[usize], threads: usize, piece: usize) -> Vec<bool> {
    let mut pick = vec![false; lens.len()];
    if threads < 2 {
        return pick;
    }
    let total: usize = lens.iter().fold(0, |a, &n| a.saturating_add(n));
    let longest = lens.iter().copied().max().unwrap_or(0);
    let share = total.checked_div(threads).unwrap_or(total);
    let min = piece.saturating_mul(2);
    let mut got = 0_usize;
    for (c, &n) in lens.iter().enumerate() {
        if n >= min && n > share {
            pick[c] = true;
            got = got.saturating_add(n);
        }
    }
    let mut order: Vec<usize> = (0..lens.len()).filter(|&c| lens[c] >= min).collect();
    order.sort_by_key(|&c| (lens[c], c));
    for c in order {
        if got >= longest {
            break;
        }
        if !pick[c] {
            pick[c] = true;
            got = got.saturating_add(lens[c]);
        }
    }
    pick
}

/// What the worker threads of one [`force_channels`] call share.
struct Shared<'a, 'm> {
    models: &'m [&'m dyn Channel],
    starts: &'m [MasingState],
    queue: Mutex<Queue<'a>>,
    ready: Condvar,
    /// Samples of each channel's pieces queued or running.
    outstanding: Vec<AtomicUsize>,
    failed: AtomicBool,
    outcomes: Vec<Mutex<Outcome>>,
    threads: usize,
    piece: usize,
    cpu_times: bool,
    t0: Instant,
}

impl<'a> Shared<'a, '_> {
    fn note(&self, c: usize, f: &mut dyn FnMut(&mut Outcome)) {
        if let Ok(mut o) = self.outcomes[c].lock() {
            f(&mut o);
        }
    }

    /// The next job, waiting while pre-passes may still queue pieces; `None`: no more work
    /// (or a failure).
    fn next_job(&self) -> Option<Job<'a>> {
        let mut q = self.queue.lock().ok()?;
        loop {
            if self.failed.load(Ordering::Relaxed) {
                return None;
            }
            if let Some(j) = q.jobs.pop() {
                return Some(j);
            }
            if q.pending == 0 {
                return None;
            }
            q = self.ready.wait(q).ok()?;
        }
    }

    /// Queue a piece of channel `c`.
    fn queue_piece(
        &self,
        c: usize,
        x: &'a [f64],
        out: &'a mut [f64],
        state: MasingState,
        last: bool,
    ) {
        let len = x.len();
        self.outstanding[c].fetch_add(len, Ordering::Relaxed);
        if let Ok(mut q) = self.queue.lock() {
            let seq = q.seq;
            q.seq = seq.saturating_add(1);
            q.jobs.push(Job {
                channel: c,
                rank: 0,
                size: len,
                seq,
                work: Work::Piece {
                    x,
                    out,
                    state,
                    last,
                },
            });
            self.ready.notify_one();
        }
    }

    /// The whole channel `c` serially, from its start state.
    fn run_whole(&self, c: usize, x: &[f64], out: &mut [f64], st: &mut ThreadStats) {
        st.jobs = st.jobs.saturating_add(1);
        st.samples = st.samples.saturating_add(x.len());
        let mut s = self.starts[c].clone();
        match self.models[c].whole(x, out, &mut s) {
            Ok(()) => self.note(c, &mut |o| o.end = Some(s.clone())),
            Err(e) => self.note(c, &mut |o| o.error = Some(e.clone())),
        }
    }

    /// One piece of channel `c` from its start state.
    fn run_piece(
        &self,
        c: usize,
        x: &[f64],
        out: &mut [f64],
        mut state: MasingState,
        last: bool,
        st: &mut ThreadStats,
    ) {
        st.jobs = st.jobs.saturating_add(1);
        st.samples = st.samples.saturating_add(x.len());
        match self.models[c].piece(x, out, &mut state) {
            Ok(true) => {}
            Ok(false) => self.note(c, &mut |o| o.nonfinite = true),
            Err(e) => self.note(c, &mut |o| o.error = Some(e.clone())),
        }
        if last {
            self.note(c, &mut |o| o.end = Some(state.clone()));
        }
        self.outstanding[c].fetch_sub(x.len(), Ordering::Relaxed);
    }

    /// The pre-pass of channel `c`, queueing its pieces as their boundaries are found (or the
    /// whole channel when it cannot be split). Returns its CPU seconds when measured.
    fn run_split(&self, c: usize, x: &'a [f64], out: &'a mut [f64], st: &mut ThreadStats) -> f64 {
        let (w0, c0) = (
            self.t0.elapsed().as_secs_f64(),
            self.cpu_times.then(schedstat).flatten(),
        );
        let mut rest_x = x;
        let mut rest_o: &'a mut [f64] = out;
        let mut prev: Option<(usize, MasingState)> = None;
        let mut cut = |upto: usize, next: Option<(usize, MasingState)>| {
            if let Some((off, state)) = prev.take() {
                let len = upto.saturating_sub(off).min(rest_x.len());
                let (px, tx) = rest_x.split_at(len);
                let (po, to) = std::mem::take(&mut rest_o).split_at_mut(len);
                (rest_x, rest_o) = (tx, to);
                self.queue_piece(c, px, po, state, next.is_none());
            }
            prev = next;
        };
        // Stop where the rest, run as one piece by this thread, takes no longer than the
        // other threads need for the pieces queued and not yet done.
        let others = self.threads.saturating_sub(1).max(1);
        let r = self.models[c].split(x, &self.starts[c], self.piece, &mut |off, s| {
            cut(off, Some((off, s)));
            let queued = self.outstanding[c].load(Ordering::Relaxed);
            off == 0 || x.len().saturating_sub(off).saturating_mul(others) > queued
        });
        match r {
            Ok(Walked::Ended(_) | Walked::Stopped) => cut(x.len(), None),
            // not splittable: run whole
            Ok(Walked::Whole) => self.run_whole(c, rest_x, rest_o, st),
            Err(e) => self.note(c, &mut |o| o.error = Some(e.clone())),
        }
        if let Ok(mut q) = self.queue.lock() {
            q.pending = q.pending.saturating_sub(1);
        }
        self.ready.notify_all();
        st.prepass += self.t0.elapsed().as_secs_f64() - w0;
        match (c0, c0.and_then(|_| schedstat())) {
            (Some(a), Some(b)) => b.0.saturating_sub(a.0) as f64 * 1e-9,
            _ => 0.0,
        }
    }

    /// One worker thread: jobs until none is left.
    fn worker(&self) -> ThreadStats {
        let before = if self.cpu_times { schedstat() } else { None };
        let mut st = ThreadStats {
            start: self.t0.elapsed().as_secs_f64(),
            ..ThreadStats::default()
        };
        let mut pre_cpu = 0.0_f64;
        while let Some(Job {
            channel: c, work, ..
        }) = self.next_job()
        {
            match work {
                Work::Split { x, out } => pre_cpu += self.run_split(c, x, out, &mut st),
                Work::Piece {
                    x,
                    out,
                    state,
                    last,
                } => self.run_piece(c, x, out, state, last, &mut st),
                Work::Whole { x, out } => self.run_whole(c, x, out, &mut st),
            }
        }
        st.end = self.t0.elapsed().as_secs_f64();
        if let (Some(a), Some(b)) = (before, before.and_then(|_| schedstat())) {
            st.cpu = Some(b.0.saturating_sub(a.0) as f64 * 1e-9);
            st.wait = Some(b.1.saturating_sub(a.1) as f64 * 1e-9);
            st.prepass_cpu = Some(pre_cpu);
        }
        st
    }
}

/// Forces of several channels on up to `threads` threads, each continuing from its state in
/// `states` (updated on success; all unchanged on error), bit for bit the serial kernel.
///
/// One queue holds three kinds of job: the pre-pass of the channels chosen for splitting
/// (first: their pieces are queued as the pass finds each boundary, so other threads start
/// on them at once), whole channels (longest first), then pieces (largest first). With one
/// thread nothing is split. The error is that of the lowest-numbered failing channel.
/// Per-thread statistics: jobs and samples of forces (pieces and whole channels), times
/// from the call's start, CPU and wait; `prepass` and `prepass_cpu` the pre-passes' share.
pub fn force_channels(
    models: &[&dyn Channel],
    xs: &[&[f64]],
    mut outs: Vec<&mut [f64]>,
    states: &mut [MasingState],
    threads: usize,
    piece: usize,
    cpu_times: bool,
) -> Result<Vec<ThreadStats>, CoreError> {
    let nch = models.len();
    if xs.len() != nch || outs.len() != nch || states.len() != nch {
        return Err(CoreError::InvalidState {
            reason: "models, signals, outputs and states must be as many",
        });
    }
    for (x, o) in xs.iter().zip(&outs) {
        crate::error::check_same_len("x", x.len(), "out", o.len())?;
    }
    let piece = piece.max(1);
    let t0 = Instant::now();
    let lens: Vec<usize> = xs.iter().map(|x| x.len()).collect();
    let pick = to_split(&lens, threads, piece);
    let mut heap = std::collections::BinaryHeap::with_capacity(nch);
    for (c, out) in outs.iter_mut().enumerate() {
        let out: &mut [f64] = out;
        let x = xs[c];
        let (rank, work) = if pick[c] {
            (2, Work::Split { x, out })
        } else {
            (1, Work::Whole { x, out })
        };
        heap.push(Job {
            channel: c,
            rank,
            size: x.len(),
            seq: c,
            work,
        });
    }
    let pending = pick.iter().filter(|&&p| p).count();
    // Pieces may come: every thread; else no more threads than channels.
    let workers = if pending > 0 {
        threads
    } else {
        threads.min(nch)
    }
    .max(1);
    let shared = Shared {
        models,
        starts: states,
        queue: Mutex::new(Queue {
            jobs: heap,
            pending,
            seq: nch,
        }),
        ready: Condvar::new(),
        outstanding: (0..nch).map(|_| AtomicUsize::new(0)).collect(),
        failed: AtomicBool::new(false),
        outcomes: (0..nch).map(|_| Mutex::new(Outcome::default())).collect(),
        threads,
        piece,
        cpu_times,
        t0,
    };
    let stats: Vec<ThreadStats> = if workers == 1 {
        vec![shared.worker()]
    } else {
        // the calling thread is one of the workers: it starts at once, and one thread
        // fewer waits to be woken on a core (on a VM a few milliseconds)
        std::thread::scope(|s| {
            let handles: Vec<_> = (1..workers).map(|_| s.spawn(|| shared.worker())).collect();
            let mine = shared.worker();
            std::iter::once(mine)
                .chain(
                    handles
                        .into_iter()
                        .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p))),
                )
                .collect()
        })
    };
    let outcomes = shared.outcomes;
    // The lowest-numbered failing channel's error; else every state advances.
    let mut ends = Vec::with_capacity(nch);
    for (c, cell) in outcomes.into_iter().enumerate() {
        let o = cell.into_inner().unwrap_or_default();
        if let Some(e) = o.error {
            return Err(e);
        }
        if o.nonfinite {
            crate::error::check_output("force", outs[c])?;
        }
        ends.push(o.end);
    }
    for (st, (end, out)) in states.iter_mut().zip(ends.into_iter().zip(&outs)) {
        if let Some(mut e) = end {
            // the last output, as the serial kernel keeps it
            if let Some(&h) = out.last() {
                e.h = h;
            }
            *st = e;
        }
    }
    Ok(stats)
}
