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
//! The pieces are then independent: [`force_channels`](super::channels::force_channels) hands them out from one queue,
//! largest first, so two threads of unequal speed finish together, and one long channel
//! uses every thread.
//!
//! The pre-pass is not free (0.1-0.3 of the kernel's CPU on smooth input, where reading the
//! input from memory is most of it, about 0.6 on a random walk, where the rules are), so
//! [`force_channels`](super::channels::force_channels) splits only the channels that balancing needs, and stops a channel's
//! pre-pass where the rest, run as one last piece by the pre-pass's own thread, takes no
//! longer than the other threads need for the pieces already queued: for one channel on two
//! threads at `1 / (2 - p)` of it with `p` the pre-pass's cost relative to the kernel, so
//! the wall time is `1 / (2 - p)` of one thread's instead of `(1 + p) / 2`.
//!
//! A boundary is skipped where the stack is deeper than a quarter of the piece length plus 64 (its
//! copy would cost a noticeable share of the piece's work): a signal of ever-shrinking
//! nested loops then runs in fewer, longer pieces.

use super::{kernel, MasingState, Reversal};
use crate::curve::Backbone;
use crate::error::CoreError;

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
    let walked = split_each(curve, scale, x, state, piece, |off, st| {
        pieces.push((off, st));
        true
    })?;
    Ok(match walked {
        Walked::Ended(end) => Some(Split { pieces, end }),
        Walked::Whole | Walked::Stopped => None,
    })
}

/// How a pre-pass ([`split_each`]) ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Walked {
    /// Nothing emitted: a state the kernel does not continue from (or a rule that is not
    /// split); run the channel whole.
    Whole,
    /// Through the whole input; the end state (the serial kernel's).
    Ended(MasingState),
    /// `emit` said stop at its last boundary: the last piece runs to the end of the input
    /// (its run gives the end state).
    Stopped,
}

/// [`split`] handing each boundary `(offset, start state)` to `emit` as soon as it is found
/// (the first is `(0, state)`). `emit` returns whether to go on: `false` ends the pre-pass
/// there, the piece from that boundary then runs to the end of `x` ([`Walked::Stopped`]).
pub fn split_each<C: Backbone>(
    curve: &C,
    scale: f64,
    x: &[f64],
    state: &MasingState,
    piece: usize,
    mut emit: impl FnMut(usize, MasingState) -> bool,
) -> Result<Walked, CoreError> {
    crate::error::check_positive("scale", scale)?;
    if !kernel::all_finite(x) {
        crate::error::check_finite("x", x)?;
    }
    let end = super::checked_end(state, x.len())?;
    if !kernel::takes(state) {
        return Ok(Walked::Whole);
    }
    let piece = piece.max(1);
    let (lam, inv) = (scale, 1.0 / scale);
    let start = state.count;
    let mut stk: Vec<Entry> = state
        .stack
        .iter()
        .map(|&r| Entry { r, known: true })
        .collect();
    // `stk[..n]` is the stack; above it, room for a candidate per sample of a block.
    let mut n = stk.len();
    let mut w = Walk {
        xp: state.x,
        dir: f64::from(state.dir),
        h0: state.h,
        start,
    };
    if !emit(0, state.clone()) {
        return Ok(Walked::Stopped);
    }
    let mut offset = 0_usize;
    let mut dense = false;
    let mut calm = false;
    for xc in x.chunks(piece) {
        if offset > 0 && n <= (piece / 4).saturating_add(64) {
            let h = resolve(curve, lam, inv, &mut stk[..n], w.xp);
            let go_on = emit(
                offset,
                MasingState {
                    x: w.xp,
                    h,
                    dir: w.dir as i8,
                    count: start.saturating_add(offset as u64), // <= end, checked
                    stack: stk[..n].iter().map(|e| e.r).collect(),
                },
            );
            if !go_on {
                return Ok(Walked::Stopped);
            }
        }
        let mut at = offset;
        for xb in xc.chunks(BLK) {
            let need = n.saturating_add(xb.len()).saturating_add(1);
            if stk.len() < need {
                stk.resize(need, SPARE);
            }
            let changes = if dense && w.dir != 0.0 && at > 0 {
                w.dense(&mut stk, &mut n, xb, at)
            } else {
                w.smooth(&mut stk, &mut n, xb, at, calm)
            };
            dense = changes.saturating_mul(8) > xb.len();
            // fewer than one change per 64 samples
            calm = changes.saturating_mul(64) < xb.len();
            at = at.saturating_add(xb.len());
        }
        offset = offset.saturating_add(xc.len());
    }
    let h = if x.is_empty() {
        state.h
    } else {
        resolve(curve, lam, inv, &mut stk[..n], w.xp)
    };
    Ok(Walked::Ended(MasingState {
        x: w.xp,
        h,
        dir: w.dir as i8,
        count: end,
        stack: stk[..n].iter().map(|e| e.r).collect(),
    }))
}

/// Samples per block of the pre-pass (the path for a block follows the branch changes of
/// the one before, as in the kernel).
const BLK: usize = 512;

/// Written above the stack top.
const SPARE: Entry = Entry {
    r: Reversal {
        x: 0.0,
        h: 0.0,
        index: 0,
    },
    known: false,
};

/// The pre-pass's walk through the memory rules: last input, direction, the state's force
/// (that of a reversal at the call's first sample) and the call's first global index.
struct Walk {
    xp: f64,
    dir: f64,
    h0: f64,
    start: u64,
}

impl Walk {
    /// The rules for input `xi` at call position `i` (the serial kernel's: a reversal at the
    /// previous sample, then every closure the step makes); `stk[..*n]` the stack with room
    /// above. Returns whether the branch changed.
    #[inline(always)]
    fn rules(&mut self, stk: &mut [Entry], n: &mut usize, xi: f64, i: usize) -> bool {
        let dx = xi - self.xp;
        if dx == 0.0 {
            return false; // a zero-length step changes nothing
        }
        let s = if dx > 0.0 { 1.0 } else { -1.0 };
        let rev = s != self.dir && self.dir != 0.0;
        if rev {
            // The reversal is the previous sample. At the call's first sample its force is
            // the state's (as the kernel takes it), otherwise evaluated when a boundary
            // needs it.
            stk[*n] = Entry {
                r: Reversal {
                    x: self.xp,
                    h: self.h0,
                    index: self.start.saturating_add(i as u64).saturating_sub(1),
                },
                known: i == 0,
            };
            *n = n.saturating_add(1);
        }
        self.dir = s;
        let before = *n;
        // Wipe out every loop this step closes.
        while *n > 0 && (xi - target(&stk[..*n], s)) * s >= 0.0 {
            *n = n.saturating_sub((*n).min(2));
        }
        self.xp = xi;
        rev || *n != before
    }

    /// A block where the input mostly moves on along its branch: a predicted test per
    /// sample, the rules where needed; with `groups` (where the branch rarely changes:
    /// elsewhere the group test mostly fails and costs) by [`Walk::grouped`]. Returns the
    /// number of branch changes.
    #[inline(never)]
    fn smooth(
        &mut self,
        stk: &mut [Entry],
        n: &mut usize,
        xb: &[f64],
        at: usize,
        groups: bool,
    ) -> usize {
        if groups {
            return self.grouped(stk, n, xb, at);
        }
        let mut tgt = target(&stk[..*n], self.dir);
        let mut changes = 0_usize;
        for (p, &xi) in xb.iter().enumerate() {
            let dx = xi - self.xp;
            // Moving on along the branch without reaching its closure point.
            if dx * self.dir > 0.0 && (xi - tgt) * self.dir < 0.0 {
                self.xp = xi;
                continue;
            }
            if self.rules(stk, n, xi, at.saturating_add(p)) {
                changes = changes.saturating_add(1);
            }
            tgt = target(&stk[..*n], self.dir);
        }
        changes
    }

    /// [`Walk::smooth`] by groups of eight samples: those that all move on along the branch
    /// without reaching its closure point only move the last input (one branch-free test
    /// per group); a group that does not pass goes sample by sample.
    #[inline(never)]
    // `&` on booleans on purpose: one branch-free test per group.
    #[allow(clippy::needless_bitwise_bool)]
    fn grouped(&mut self, stk: &mut [Entry], n: &mut usize, xb: &[f64], at: usize) -> usize {
        let mut tgt = target(&stk[..*n], self.dir);
        let mut changes = 0_usize;
        for (g, xg) in xb.chunks(8).enumerate() {
            let d = self.dir;
            let mut on = xg.len() == 8;
            let mut prev = self.xp;
            for &v in xg {
                on &= ((v - prev) * d > 0.0) & ((v - tgt) * d < 0.0);
                prev = v;
            }
            if on {
                self.xp = prev;
                continue;
            }
            for (q, &xi) in xg.iter().enumerate() {
                let dx = xi - self.xp;
                if dx * self.dir > 0.0 && (xi - tgt) * self.dir < 0.0 {
                    self.xp = xi;
                    continue;
                }
                let i = at.saturating_add(g.saturating_mul(8)).saturating_add(q);
                if self.rules(stk, n, xi, i) {
                    changes = changes.saturating_add(1);
                }
                tgt = target(&stk[..*n], self.dir);
            }
        }
        changes
    }

    /// A block where the input reverses every sample or two (a random walk, broadband
    /// noise): the candidate reversal is always written above the top and the top raised
    /// by 0 or 1 and lowered by 0 or 2 by arithmetic on the comparisons, with no
    /// data-dependent branch (the kernel's dense path, without the forces). Left to
    /// [`Walk::rules`]: a stack of fewer than two reversals or a closure down to one, a
    /// step closing two loops or more, a zero-length step. Needs `dir != 0` and `at > 0`.
    #[inline(never)]
    // `&` on booleans on purpose: no branch per condition.
    #[allow(clippy::needless_bitwise_bool)]
    fn dense(&mut self, stk: &mut [Entry], n: &mut usize, xb: &[f64], at: usize) -> usize {
        let mut changes = 0_usize;
        let (mut k, mut xp, mut up) = (*n, self.xp, self.dir > 0.0);
        let before = self.start.saturating_add(at as u64).saturating_sub(1);
        for (p, &xi) in xb.iter().enumerate() {
            if xi == xp {
                continue;
            }
            let rising = xi > xp;
            if k < 2 {
                (self.xp, self.dir) = (xp, if up { 1.0 } else { -1.0 });
                let c = self.rules(stk, &mut k, xi, at.saturating_add(p));
                changes = changes.saturating_add(usize::from(c));
                (xp, up) = (self.xp, self.dir > 0.0);
                continue;
            }
            let rev = rising != up;
            stk[k] = Entry {
                r: Reversal {
                    x: xp,
                    h: 0.0,
                    index: before.wrapping_add(p as u64),
                },
                known: false,
            };
            let k1 = k.wrapping_add(usize::from(rev)); // >= 2
            let t = stk[k1.wrapping_sub(2)].r.x;
            let closes = (rising & (xi >= t)) | (!rising & (xi <= t));
            if closes & (k1 < 4) {
                (self.xp, self.dir) = (xp, if up { 1.0 } else { -1.0 });
                let c = self.rules(stk, &mut k, xi, at.saturating_add(p));
                changes = changes.saturating_add(usize::from(c));
                (xp, up) = (self.xp, self.dir > 0.0);
                continue;
            }
            k = k1.wrapping_sub(usize::from(closes) << 1); // >= 2
            up = rising;
            xp = xi;
            changes = changes.wrapping_add(usize::from(rev | closes));
            let below = stk[k.wrapping_sub(2)].r.x;
            if closes & ((rising & (xi >= below)) | (!rising & (xi <= below))) {
                // the step closes further loops (a large jump)
                let s = if rising { 1.0 } else { -1.0 };
                while k > 0 && (xi - target(&stk[..k], s)) * s >= 0.0 {
                    k = k.saturating_sub(k.min(2));
                }
            }
        }
        (*n, self.xp, self.dir) = (k, xp, if up { 1.0 } else { -1.0 });
        changes
    }
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
    match kernel::scaled_force(crate::simd::level(), curve, scale, x, out, state) {
        kernel::Forces::Finite => Ok(true),
        kernel::Forces::NotFinite => Ok(false),
        kernel::Forces::BadInput => {
            crate::error::check_finite("x", x)?;
            Ok(false) // not reached: the input has a non-finite value
        }
    }
}
