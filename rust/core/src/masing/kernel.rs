//! The force kernel of Masing's scaled branch rule (PHYSICS.md §1) with no closure observer:
//! what `Masing.force`, `MasingOperator.push` and `force_many` run.
//!
//! Two passes per block of [`BLOCK`] samples. The first applies the memory rules sample by
//! sample and records each sample's curve argument `u` and the run of samples on one branch
//! it belongs to (a run is `h = base + mul · f(u)`). The second ([`eval_block`]) evaluates the
//! curve over the whole block in one vectorised loop, then the runs' bases, then the forces.
//!
//! A new reversal's force is the output of the previous sample, which the second pass computes
//! anyway; it is not evaluated when the reversal is found (it is *deferred*): the reversal
//! refers to its sample until the block ends. Deferred entries are the stack's newest ones, the
//! reversals found in the current block, so their global sample index says which they are and
//! where their force is.
//!
//! The first pass keeps the current branch (anchor, target, deferred source) in registers
//! and skips the rules, by a predicted test, on samples that move on along their branch.
//! Elsewhere a reversal is applied without data-dependent branches (the candidate is always
//! written above the stack top, the top raised by 0 or 1, the branch registers selected by
//! integer selects); only a closure takes a branch and reloads the branch from the stack.
//!
//! The first pass does not visit every sample: one vectorised scan of the block's input
//! ([`scan::continuation_bits`], with the finiteness check folded in) marks the turning points, and
//! the monotone stretches between them are filled in bulk up to where they reach the
//! branch's closure point ([`Pass::block_body`]).
//!
//! Every vectorised part (the input scan, the first pass, both curve passes with the
//! output's finiteness check) is compiled for the baseline, AVX2 and AVX-512 and chosen at
//! run time ([`simd::run`]); the same IEEE operations in the same order at every level, so
//! the forces are the same bit for bit (tests: `level_tests` below, `simd` tests for the
//! exponential against libm).
//!
//! A block after one that changed branch more than once every [`DENSE`] samples (a random
//! walk) takes the dense path instead: [`Pass::dense_block`] applies the rules with no
//! data-dependent branch but the closure's and writes per sample only the curve argument and
//! the slot of its base in one buffer (no run table, whose bookkeeping cost as much as the
//! rules there); [`eval_dense`] evaluates the curve over the block, then each force as the
//! base in its slot (the anchor's output, an earlier sample of the block, or a base known
//! before the block) plus `lam · f(u)`. Both paths give the stepper's forces bit for bit.
//!
//! Files: `kernel/scan.rs` the input scan, `kernel/pass.rs` the first pass (memory rules),
//! `kernel/eval.rs` the curve passes, `kernel/level_tests.rs` the SIMD level tests; this file the
//! shared records ([`Run`], [`Dense`]) and the driver [`scaled_force`].

use super::MasingState;
use crate::curve::Backbone;
use crate::simd::{self, Level};
use eval::eval_dense;
pub(super) use eval::{eval_block, RunTab};
use pass::{block_pass, dense_pass, Pass, SPARE};
use scan::Scan;

/// No pending sample: the value is known.
pub(super) const KNOWN: u32 = u32::MAX;

/// Samples per block: the curve arguments of one block and its run table stay in L1 between
/// the passes.
pub(super) const BLOCK: usize = 512;

/// A block is run by [`Pass::dense_block`] when the previous one changed branch more often
/// than once every `DENSE` samples.
const DENSE: usize = 8;

/// A stretch of a block on one branch: its samples have `h = base + mul · f(u)`, `base` being
/// `ha`, or the output of in-block sample `src` while that force is deferred.
#[derive(Clone, Copy)]
pub(super) struct Run {
    pub(super) ha: f64,
    pub(super) src: u32,
    pub(super) mul: f64,
}

/// `a` if `c` else `b`, by a mask: no branch whatever the compiler thinks of `c`.
#[inline(always)]
fn pick(c: bool, a: u64, b: u64) -> u64 {
    let m = 0_u64.wrapping_sub(u64::from(c));
    b ^ ((a ^ b) & m)
}

/// Per-sample records of a dense block ([`Pass::dense_block`]).
pub(super) struct Dense {
    u: [f64; BLOCK],
    /// Padding: arrays 4 KiB apart alias in the store-to-load check (the stores of one
    /// sample would all share their low 12 address bits).
    _pad0: [f64; 40],
    /// `slot[p]`: where in `kh` the base of sample `p` is.
    slot: [u32; BLOCK],
    _pad1: [f64; 40],
    /// The bases, by slot: `kh[p]` for `p < BLOCK` a known base written at sample `p` (an
    /// anchor before the block); `kh[BLOCK]` the output of the sample before the block;
    /// `kh[BLOCK + 1 + q]` the output of in-block sample `q` once computed; `kh[VIRGIN_SLOT]`
    /// 0, the base of the virgin curve (whose multiplier is 1, not `lam`).
    kh: [f64; KH],
}

/// The slot of the virgin curve's base in [`Dense::kh`].
pub(super) const VIRGIN_SLOT: u32 = 2 * BLOCK as u32 + 1;

/// Length of [`Dense::kh`]: a power of two above [`VIRGIN_SLOT`] (a masked index needs no
/// bounds check).
pub(super) const KH: usize = 4 * BLOCK;

impl Dense {
    pub(super) fn new() -> Box<Self> {
        Box::new(Self {
            u: [0.0; BLOCK],
            _pad0: [0.0; 40],
            slot: [0; BLOCK],
            _pad1: [0.0; 40],
            kh: [0.0; KH],
        })
    }
}

/// Whether every value is finite: one vectorised pass without an early exit (the
/// `position`-based checks of `crate::error` run a compare and branch per value; they are
/// called only to name the first bad value once this says there is one).
#[inline(always)]
pub(super) fn all_finite(v: &[f64]) -> bool {
    v.chunks(256)
        .all(|c| c.iter().fold(true, |ok, a| ok & a.is_finite()))
}

/// Whether [`scaled_force`] can continue from `state`: its reversals precede its sample count
/// (always so for states this crate produced), and, at count 0, it has not moved yet (a
/// reversal at the first sample would be sample -1).
pub(super) fn takes(state: &MasingState) -> bool {
    (state.count > 0 || state.dir == 0) && state.stack.iter().all(|r| r.index < state.count)
}

/// What [`scaled_force`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Forces {
    /// Every input and every force is finite.
    Finite,
    /// Every input is finite, some force is not.
    NotFinite,
    /// Some input is not finite: the run stopped at its block (`state` and `out` are then
    /// partly advanced; the caller restores or discards them).
    BadInput,
}

/// Masing forces of `x` under the scaled branch rule `h = h_r + lam f((x - x_r) / lam)` into
/// `out` (same length), continuing from `state` and updating it, with the vectorised parts
/// compiled for SIMD level `level` (every level gives the same forces bit for bit). The caller
/// has checked that `state.count + x.len()` fits in 63 bits and that [`takes`] `state`. The
/// input's and the forces' finiteness are checked block by block while the block is in cache
/// (no separate pass over `x`): the input before its block is run on the block path (the same
/// scan finds its turning points), after its first pass on the dense path (from L1).
pub(super) fn scaled_force<C: Backbone>(
    level: Level,
    curve: &C,
    lam: f64,
    x: &[f64],
    out: &mut [f64],
    state: &mut MasingState,
) -> Forces {
    let stack = &mut state.stack;
    let mut pass = Pass {
        n: stack.len(),
        lam,
        inv_lam: 1.0 / lam,
        xp: state.x,
        dir: f64::from(state.dir),
        xa: 0.0,
        ha: 0.0,
        src: KNOWN,
        inv: 1.0,
        target: f64::INFINITY,
        start: state.count,
        h_before: state.h,
    };
    pass.load_branch(stack);
    let mut runs = [Run {
        ha: 0.0,
        src: KNOWN,
        mul: 1.0,
    }; BLOCK + 2];
    let mut ub = [0.0_f64; BLOCK];
    let mut rid = [0_u16; BLOCK];
    // The dense path's records, allocated at its first block.
    let mut dense_rec: Option<Box<Dense>> = None;
    let mut dense = false;
    let mut tab = RunTab::new();
    let mut finite = true;
    for (xc, oc) in x.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
        // The input's check, while the block is read for its turning points when the
        // block path will need them. The dense path needs no turning points: its block is
        // checked after its first pass, from L1 (the pass's own loads then meet the block's
        // cache misses, overlapped with its work, instead of a streaming pass of its own).
        // A non-finite input there makes only meaningless values within the block (every
        // stack index stays within the room made below, every loop ends), and the call is
        // then an error whose partial results the caller discards.
        let dense_path = dense && pass.dir != 0.0;
        let cont = if dense_path {
            [0; BLOCK / 64]
        } else {
            let Some(cont) = simd::run(level, Scan(xc, true)) else {
                return Forces::BadInput;
            };
            cont
        };
        let m = xc.len();
        // Room for one candidate above the top per sample.
        let need = pass.n.saturating_add(m).saturating_add(1);
        if stack.len() < need {
            stack.resize(need, SPARE);
        }
        let stk = stack.as_mut_slice();
        // The path for this block from the branch changes of the last one.
        let changes = if dense_path {
            let d = dense_rec.get_or_insert_with(Dense::new);
            let c = dense_pass(level, &mut pass, stk, xc, d);
            if simd::run(level, Scan(xc, false)).is_none() {
                return Forces::BadInput;
            }
            finite &= eval_dense(level, curve, d, lam, oc);
            c
        } else {
            let (u, r) = (&mut ub[..m], &mut rid[..m]);
            let nr = block_pass(level, &mut pass, stk, xc, u, r, &mut runs, &cont);
            finite &= eval_block(level, curve, &mut runs[..nr], u, r, oc, &mut tab);
            nr.saturating_sub(1)
        };
        pass.end_block(stk, oc);
        dense = changes.saturating_mul(DENSE) > m;
        pass.start = pass.start.saturating_add(m as u64);
    }
    stack.truncate(pass.n);
    let (xp, dir, h, end) = (pass.xp, pass.dir, pass.h_before, pass.start);
    state.x = xp;
    state.h = h;
    state.dir = dir as i8;
    state.count = end;
    if finite {
        Forces::Finite
    } else {
        Forces::NotFinite
    }
}

mod eval;
mod pass;
mod scan;

#[cfg(test)]
mod level_tests;
