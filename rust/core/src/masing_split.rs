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
use crate::parallel::{run_jobs, ThreadStats};
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
    let mut pieces = vec![(0_usize, state.clone())];
    let mut offset = 0_usize;
    for xc in x.chunks(piece) {
        if offset > 0 && stk.len() <= (piece / 4).saturating_add(64) {
            let h = resolve(curve, lam, inv, &mut stk, xp);
            pieces.push((
                offset,
                MasingState {
                    x: xp,
                    h,
                    dir: dir as i8,
                    count: start.saturating_add(offset as u64), // <= end, checked
                    stack: stk.iter().map(|e| e.r).collect(),
                },
            ));
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
    let end = MasingState {
        x: xp,
        h,
        dir: dir as i8,
        count: end,
        stack: stk.iter().map(|e| e.r).collect(),
    };
    Ok(Some(Split { pieces, end }))
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
    /// The pieces of `x` from `state` ([`split`]), or `None` to run it whole (a branch
    /// rule other than the scaled one, or a state the kernel does not continue from).
    fn split(
        &self,
        x: &[f64],
        state: &MasingState,
        piece: usize,
    ) -> Result<Option<Split>, CoreError>;
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
    ) -> Result<Option<Split>, CoreError> {
        match self.rule {
            BranchRule::Scaled(l) => split(self.curve, l, x, state, piece),
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

/// A unit of the second phase of [`force_channels`].
struct Job<'a> {
    channel: usize,
    x: &'a [f64],
    out: &'a mut [f64],
    state: MasingState,
    /// A piece of a split channel (else the whole channel).
    piece: bool,
}

/// What one channel's run came to.
#[derive(Default)]
struct Outcome {
    split: Option<Result<Option<Split>, CoreError>>,
    error: Option<CoreError>,
    end: Option<MasingState>,
}

/// Forces of several channels on up to `threads` threads, each continuing from its state in
/// `states` (updated on success; all unchanged on error). Channels of at least two pieces
/// are [`split`] (first phase, one channel per job) and their pieces run as jobs of their own
/// (second phase, pieces and whole channels from one queue, longest first); with one thread
/// nothing is split. Outputs are those of the serial kernel bit for bit. The error is that of
/// the lowest-numbered failing channel. Per-thread statistics cover both phases; `prepass`
/// and `prepass_cpu` are the first phase's share.
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
    let outcomes: Vec<Mutex<Outcome>> = (0..nch).map(|_| Mutex::new(Outcome::default())).collect();
    let put = |c: usize, f: &dyn Fn(&mut Outcome)| {
        if let Ok(mut o) = outcomes[c].lock() {
            f(&mut o);
        }
    };
    // Phase 1: split the channels worth splitting.
    let wide = threads > 1;
    let to_split: Vec<usize> = (0..nch)
        .filter(|&c| wide && xs[c].len() >= piece.saturating_mul(2))
        .collect();
    let first = if to_split.is_empty() {
        Vec::new()
    } else {
        run_jobs(
            to_split,
            threads,
            cpu_times,
            |&c| xs[c].len(),
            |_, c| {
                let r = models[c].split(xs[c], &states[c], piece);
                put(c, &|o| o.split = Some(r.clone()));
                Ok(())
            },
        )?
    };
    let t1 = t0.elapsed().as_secs_f64();
    // Phase 2: pieces and whole channels.
    let mut jobs: Vec<Job<'_>> = Vec::new();
    for (c, out) in outs.iter_mut().enumerate() {
        let x = xs[c];
        let sp = outcomes[c].lock().ok().and_then(|mut o| o.split.take());
        match sp {
            Some(Err(e)) => put(c, &|o| o.error = Some(e.clone())),
            Some(Ok(Some(s))) => {
                let offs: Vec<usize> = s.pieces.iter().map(|p| p.0).skip(1).collect();
                let mut rest_x = x;
                let mut rest_o: &mut [f64] = out;
                let mut at = 0_usize;
                for (k, (_, st)) in s.pieces.into_iter().enumerate() {
                    let next = offs.get(k).copied().unwrap_or(x.len());
                    let len = next.saturating_sub(at).min(rest_x.len());
                    let (px, tx) = rest_x.split_at(len);
                    let (po, to) = std::mem::take(&mut rest_o).split_at_mut(len);
                    (rest_x, rest_o) = (tx, to);
                    at = next;
                    jobs.push(Job {
                        channel: c,
                        x: px,
                        out: po,
                        state: st,
                        piece: true,
                    });
                }
                put(c, &|o| o.end = Some(s.end.clone()));
            }
            Some(Ok(None)) | None => jobs.push(Job {
                channel: c,
                x,
                out,
                state: states[c].clone(),
                piece: false,
            }),
        }
    }
    let bad: Vec<AtomicBool> = (0..nch).map(|_| AtomicBool::new(false)).collect();
    let second = run_jobs(
        jobs,
        threads,
        cpu_times,
        |j| j.x.len(),
        |_, j| {
            let Job {
                channel: c,
                x,
                out,
                mut state,
                piece,
            } = j;
            if piece {
                match models[c].piece(x, out, &mut state) {
                    Ok(true) => {}
                    Ok(false) => bad[c].store(true, Ordering::Relaxed),
                    Err(e) => put(c, &|o| o.error = Some(e.clone())),
                }
            } else {
                match models[c].whole(x, out, &mut state) {
                    Ok(()) => put(c, &|o| o.end = Some(state.clone())),
                    Err(e) => put(c, &|o| o.error = Some(e.clone())),
                }
            }
            Ok(())
        },
    )?;
    // The lowest-numbered failing channel's error; else every state advances.
    let mut ends = Vec::with_capacity(nch);
    for (c, cell) in outcomes.into_iter().enumerate() {
        let o = cell.into_inner().unwrap_or_default();
        if let Some(e) = o.error {
            return Err(e);
        }
        if bad[c].load(Ordering::Relaxed) {
            crate::error::check_output("force", outs[c])?;
        }
        ends.push(o.end);
    }
    for ((st, end), out) in states.iter_mut().zip(ends).zip(&outs) {
        if let Some(mut e) = end {
            // the last output, as the serial kernel keeps it
            if let Some(&h) = out.last() {
                e.h = h;
            }
            *st = e;
        }
    }
    Ok(merge(&first, &second, t1))
}

/// Per-thread statistics of both phases: the second's jobs and samples, times from the
/// call's start, CPU and wait summed; `prepass` (wall) and `prepass_cpu` from the first.
fn merge(first: &[ThreadStats], second: &[ThreadStats], t1: f64) -> Vec<ThreadStats> {
    let n = first.len().max(second.len());
    (0..n)
        .map(|k| {
            let a = first.get(k);
            let b = second.get(k);
            let add = |u: Option<f64>, v: Option<f64>| match (u, v) {
                (Some(u), Some(v)) => Some(u + v),
                (u, None) => u,
                (None, v) => v,
            };
            ThreadStats {
                jobs: b.map_or(0, |b| b.jobs),
                samples: b.map_or(0, |b| b.samples),
                start: a.map_or_else(|| b.map_or(t1, |b| t1 + b.start), |a| a.start),
                end: b.map_or_else(|| a.map_or(t1, |a| a.end), |b| t1 + b.end),
                cpu: add(a.and_then(|a| a.cpu), b.and_then(|b| b.cpu)),
                wait: add(a.and_then(|a| a.wait), b.and_then(|b| b.wait)),
                prepass: a.map_or(0.0, |a| a.end - a.start),
                prepass_cpu: a.and_then(|a| a.cpu),
            }
        })
        .collect()
}
