//! One channel in many pieces, on several threads, bit for bit the serial kernel.
//!
//! Under Masing's scaled rule the force of a sample is `h_a + λ f((x - x_a) / λ)` with
//! `(x_a, h_a)` the top of the reversal stack, and a reversal's force is that of its own
//! sample, on the branch from the entry below it (the stack only grows and shrinks at its
//! top). So the state at any sample follows from the reversal stack alone, which the memory
//! rules build with comparisons only. [`split`] runs the rules once over the channel (no
//! curve evaluation per sample) and records the state at piece boundaries; the forces of the
//! reversals still on the stack there (each evaluated once, oldest first, with the kernel's
//! own expression) and of the sample before the boundary are the only curve evaluations.
//! The pieces are then independent: [`force_channels`] hands them out from one queue
//! (`crate::parallel::run_jobs`, longest first), so two threads of unequal speed finish
//! together, and one long channel uses every thread.
//!
//! A boundary is skipped where the stack is deeper than a quarter of the piece length plus 64 (its
//! copy would cost a noticeable share of the piece's work): a signal of ever-shrinking
//! nested loops then runs in fewer, longer pieces.

use super::{kernel, BranchRule, MasingState, Reversal};
use crate::curve::Backbone;
use crate::error::CoreError;
use crate::parallel::{schedstat, ThreadStats};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Default piece length (samples): long enough that a piece's set-up (a state copy, the
/// kernel's block buffers) is negligible, short enough that 8 channels of 4e6 samples make
/// about 500 pieces.
pub const PIECE: usize = 1 << 16;

/// Where the pieces of a channel start.
#[derive(Debug, Clone, PartialEq)]
pub struct Split {
    /// `(offset, state)`: the piece from sample `offset` up to the next offset (or the end)
    /// starts in `state`. The first is `(0, the given state)`.
    pub pieces: Vec<(usize, MasingState)>,
    /// The state after the last sample (as the serial kernel leaves it).
    pub end: MasingState,
}

/// A stack entry of the pre-pass: its force is evaluated only when a boundary needs it.
#[derive(Clone, Copy)]
struct Entry {
    r: Reversal,
    known: bool,
}

/// Where the branch from a stack of `n` entries closes, moving in direction `dir`.
fn target(stk: &[Entry], dir: f64) -> f64 {
    match stk.len() {
        0 if dir >= 0.0 => f64::INFINITY,
        0 => f64::NEG_INFINITY,
        1 => -stk[0].r.x,
        n => stk[n.saturating_sub(2)].r.x,
    }
}

/// Evaluate the forces of the stack's new entries (the top run of unknown ones, oldest
/// first) and return the force of input `xp` on the branch from the top. The expressions
/// are the kernel's: `base + mul · f((x - x_a) · inv)`, `(0, 1, 1)` on the virgin curve.
fn resolve<C: Backbone>(curve: &C, lam: f64, inv: f64, stk: &mut [Entry], xp: f64) -> f64 {
    let first = stk
        .iter()
        .rposition(|e| e.known)
        .map_or(0, |k| k.saturating_add(1));
    for j in first..stk.len() {
        let (ha, xa, mul, iv) = match j.checked_sub(1).and_then(|k| stk.get(k)) {
            Some(b) => (b.r.h, b.r.x, lam, inv),
            None => (0.0, 0.0, 1.0, 1.0),
        };
        let e = &mut stk[j];
        e.r.h = ha + mul * curve.eval((e.r.x - xa) * iv);
        e.known = true;
    }
    match stk.last() {
        Some(t) => t.r.h + lam * curve.eval((xp - t.r.x) * inv),
        None => 0.0 + 1.0 * curve.eval((xp - 0.0) * 1.0),
    }
}

/// The start states of the pieces of `x` (about `piece` samples each) under Masing's scaled
/// rule of scale `scale`, continuing from `state`. `None` when `state` is one the kernel does
/// not continue from (a hand-made state whose reversals do not precede its sample count, or
/// that moved at count 0): run such a channel whole. Validates like the serial kernel (scale,
/// non-finite input, sample counter).
pub fn split<C: Backbone>(
    curve: &C,
    scale: f64,
    x: &[f64],
    state: &MasingState,
    piece: usize,
) -> Result<Option<Split>, CoreError> {
    let mut pieces = Vec::new();
    let end = split_each(curve, scale, x, state, piece, |off, st| {
        pieces.push((off, st));
    })?;
    Ok(end.map(|end| Split { pieces, end }))
}

/// [`split`] handing each boundary `(offset, start state)` to `emit` as soon as it is found
/// (the first is `(0, state)`); returns the end state (`None`, with nothing emitted, for a
/// state the kernel does not continue from).
pub fn split_each<C: Backbone>(
    curve: &C,
    scale: f64,
    x: &[f64],
    state: &MasingState,
    piece: usize,
    mut emit: impl FnMut(usize, MasingState),
) -> Result<Option<MasingState>, CoreError> {
    crate::error::check_positive("scale", scale)?;
    if !kernel::all_finite(x) {
        crate::error::check_finite("x", x)?;
    }
    let end = super::checked_end(state, x.len())?;
    if !kernel::takes(state) {
        return Ok(None);
    }
    let piece = piece.max(1);
    let (lam, inv) = (scale, 1.0 / scale);
    let start = state.count;
    let mut stk: Vec<Entry> = state
        .stack
        .iter()
        .map(|&r| Entry { r, known: true })
        .collect();
    let (mut xp, mut dir) = (state.x, f64::from(state.dir));
    let mut tgt = target(&stk, dir);
    emit(0, state.clone());
    let mut offset = 0_usize;
    for xc in x.chunks(piece) {
        if offset > 0 && stk.len() <= (piece / 4).saturating_add(64) {
            let h = resolve(curve, lam, inv, &mut stk, xp);
            emit(
                offset,
                MasingState {
                    x: xp,
                    h,
                    dir: dir as i8,
                    count: start.saturating_add(offset as u64), // <= end, checked
                    stack: stk.iter().map(|e| e.r).collect(),
                },
            );
        }
        for (p, &xi) in xc.iter().enumerate() {
            let dx = xi - xp;
            // Moving on along the branch without reaching its closure point.
            if dx * dir > 0.0 && (xi - tgt) * dir < 0.0 {
                xp = xi;
                continue;
            }
            if dx == 0.0 {
                continue; // a zero-length step changes nothing
            }
            let s = if dx > 0.0 { 1.0 } else { -1.0 };
            if s != dir {
                if dir != 0.0 {
                    // The reversal is the previous sample. At the call's first sample its
                    // force is the state's (as the kernel takes it), otherwise evaluated
                    // when a boundary needs it.
                    let i = offset.saturating_add(p);
                    stk.push(Entry {
                        r: Reversal {
                            x: xp,
                            h: state.h,
                            index: start.saturating_add(i as u64).saturating_sub(1),
                        },
                        known: i == 0,
                    });
                }
                dir = s;
            }
            // Wipe out every loop this step closes.
            while !stk.is_empty() && (xi - target(&stk, s)) * s >= 0.0 {
                let n = stk.len();
                stk.truncate(n.saturating_sub(n.min(2)));
            }
            tgt = target(&stk, dir);
            xp = xi;
        }
        offset = offset.saturating_add(xc.len());
    }
    let h = if x.is_empty() {
        state.h
    } else {
        resolve(curve, lam, inv, &mut stk, xp)
    };
    Ok(Some(MasingState {
        x: xp,
        h,
        dir: dir as i8,
        count: end,
        stack: stk.iter().map(|e| e.r).collect(),
    }))
}

/// Forces of one piece of a [`split`] channel into `out` (same length), from its start
/// state (updated). Returns whether every force is finite; the caller names the first
/// non-finite one over the whole channel.
pub fn force_piece<C: Backbone>(
    curve: &C,
    scale: f64,
    x: &[f64],
    out: &mut [f64],
    state: &mut MasingState,
) -> Result<bool, CoreError> {
    crate::error::check_same_len("x", x.len(), "out", out.len())?;
    if !kernel::takes(state) {
        return Err(CoreError::InvalidState {
            reason: "a piece must start from a state the split produced",
        });
    }
    Ok(kernel::scaled_force(curve, scale, x, out, state))
}

/// A channel's model, as [`force_channels`] sees it.
pub trait Channel: Sync {
    /// The pieces of `x` from `state`, each boundary to `emit` as found ([`split_each`]);
    /// the end state, or `None` (nothing emitted) to run it whole (a branch rule other than
    /// the scaled one, or a state the kernel does not continue from).
    fn split(
        &self,
        x: &[f64],
        state: &MasingState,
        piece: usize,
        emit: &mut dyn FnMut(usize, MasingState),
    ) -> Result<Option<MasingState>, CoreError>;
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
        emit: &mut dyn FnMut(usize, MasingState),
    ) -> Result<Option<MasingState>, CoreError> {
        match self.rule {
            BranchRule::Scaled(l) => split_each(self.curve, l, x, state, piece, emit),
            BranchRule::Anchored(_) => Ok(None),
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
    /// A piece of a split channel, from its start state.
    Piece {
        x: &'a [f64],
        out: &'a mut [f64],
        state: MasingState,
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
    let outcomes: Vec<Mutex<Outcome>> = (0..nch).map(|_| Mutex::new(Outcome::default())).collect();
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
    let queue = Mutex::new(Queue {
        jobs: heap,
        pending,
        seq: nch,
    });
    let ready = std::sync::Condvar::new();
    let failed = AtomicBool::new(false);
    // Pieces may come: every thread; else no more threads than channels.
    let workers = if pending > 0 {
        threads
    } else {
        threads.min(nch)
    }
    .max(1);
    let starts: &[MasingState] = states;
    let note = |c: usize, f: &mut dyn FnMut(&mut Outcome)| {
        if let Ok(mut o) = outcomes[c].lock() {
            f(&mut o);
        }
    };
    let worker = || -> ThreadStats {
        let before = if cpu_times { schedstat() } else { None };
        let mut st = ThreadStats {
            start: t0.elapsed().as_secs_f64(),
            ..ThreadStats::default()
        };
        let mut pre_cpu = 0.0_f64;
        loop {
            let job = {
                let Ok(mut q) = queue.lock() else { break };
                loop {
                    if failed.load(Ordering::Relaxed) {
                        break None;
                    }
                    if let Some(j) = q.jobs.pop() {
                        break Some(j);
                    }
                    if q.pending == 0 {
                        break None;
                    }
                    match ready.wait(q) {
                        Ok(g) => q = g,
                        Err(_) => return st,
                    }
                }
            };
            let Some(Job {
                channel: c, work, ..
            }) = job
            else {
                break;
            };
            match work {
                Work::Split { x, out } => {
                    let (w0, c0) = (
                        t0.elapsed().as_secs_f64(),
                        cpu_times.then(schedstat).flatten(),
                    );
                    let mut rest_x = x;
                    let mut rest_o: &mut [f64] = out;
                    let mut prev: Option<(usize, MasingState)> = None;
                    let mut cut = |upto: usize, next: Option<(usize, MasingState)>| {
                        if let Some((off, state)) = prev.take() {
                            let len = upto.saturating_sub(off).min(rest_x.len());
                            let (px, tx) = rest_x.split_at(len);
                            let (po, to) = std::mem::take(&mut rest_o).split_at_mut(len);
                            (rest_x, rest_o) = (tx, to);
                            if let Ok(mut q) = queue.lock() {
                                let seq = q.seq;
                                q.seq = seq.saturating_add(1);
                                q.jobs.push(Job {
                                    channel: c,
                                    rank: 0,
                                    size: len,
                                    seq,
                                    work: Work::Piece {
                                        x: px,
                                        out: po,
                                        state,
                                    },
                                });
                                ready.notify_one();
                            }
                        }
                        prev = next;
                    };
                    let r = models[c].split(x, &starts[c], piece, &mut |off, s| {
                        cut(off, Some((off, s)));
                    });
                    match r {
                        Ok(Some(end)) => {
                            cut(x.len(), None);
                            note(c, &mut |o| o.end = Some(end.clone()));
                        }
                        Ok(None) => {
                            // not splittable: run whole
                            st.jobs = st.jobs.saturating_add(1);
                            st.samples = st.samples.saturating_add(x.len());
                            let mut s = starts[c].clone();
                            match models[c].whole(rest_x, rest_o, &mut s) {
                                Ok(()) => note(c, &mut |o| o.end = Some(s.clone())),
                                Err(e) => note(c, &mut |o| o.error = Some(e.clone())),
                            }
                        }
                        Err(e) => {
                            note(c, &mut |o| o.error = Some(e.clone()));
                        }
                    }
                    if let Ok(mut q) = queue.lock() {
                        q.pending = q.pending.saturating_sub(1);
                    }
                    ready.notify_all();
                    st.prepass += t0.elapsed().as_secs_f64() - w0;
                    if let (Some(a), Some(b)) = (c0, c0.and_then(|_| schedstat())) {
                        pre_cpu += b.0.saturating_sub(a.0) as f64 * 1e-9;
                    }
                }
                Work::Piece { x, out, mut state } => {
                    st.jobs = st.jobs.saturating_add(1);
                    st.samples = st.samples.saturating_add(x.len());
                    match models[c].piece(x, out, &mut state) {
                        Ok(true) => {}
                        Ok(false) => note(c, &mut |o| o.nonfinite = true),
                        Err(e) => note(c, &mut |o| o.error = Some(e.clone())),
                    }
                }
                Work::Whole { x, out } => {
                    st.jobs = st.jobs.saturating_add(1);
                    st.samples = st.samples.saturating_add(x.len());
                    let mut s = starts[c].clone();
                    match models[c].whole(x, out, &mut s) {
                        Ok(()) => note(c, &mut |o| o.end = Some(s.clone())),
                        Err(e) => note(c, &mut |o| o.error = Some(e.clone())),
                    }
                }
            }
        }
        st.end = t0.elapsed().as_secs_f64();
        if let (Some(a), Some(b)) = (before, before.and_then(|_| schedstat())) {
            st.cpu = Some(b.0.saturating_sub(a.0) as f64 * 1e-9);
            st.wait = Some(b.1.saturating_sub(a.1) as f64 * 1e-9);
            st.prepass_cpu = Some(pre_cpu);
        }
        st
    };
    let stats: Vec<ThreadStats> = if workers == 1 {
        vec![worker()]
    } else {
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..workers).map(|_| s.spawn(worker)).collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
                .collect()
        })
    };
    drop(queue);
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
