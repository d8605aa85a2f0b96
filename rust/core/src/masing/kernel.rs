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
//! ([`continuation_bits`], with the finiteness check folded in) marks the turning points, and
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
//! data-dependent branch and writes per sample only the curve argument, the anchor's sample
//! index and its force where known (no run table, whose bookkeeping cost as much as the rules
//! there); [`eval_dense`] evaluates the curve over the block, then each force as the anchor's
//! output (an earlier sample of the block, through one indexed buffer) or the known base, plus
//! `lam · f(u)`. Both paths give the stepper's forces bit for bit.

use super::{MasingState, Reversal};
use crate::curve::Backbone;
use crate::simd::{self, Kernel, Level};

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

/// Curve pass of one block, free of data-dependent branches however short the branches of
/// the signal are: `out[i] = f(u[i])` over the whole block (auto-vectorised for the
/// exponential curve); then each run's base is resolved in order (a deferred base is the
/// output of an earlier sample, itself `base + mul · f(u)` of an earlier run); then
/// `out[i] = base + mul · out[i]` with the run of sample `i` looked up in `rid`.
#[inline(always)]
fn eval_block_body<C: Backbone>(
    curve: &C,
    runs: &mut [Run],
    u: &[f64],
    rid: &[u16],
    out: &mut [f64],
    tab: &mut RunTab,
) -> bool {
    for (o, &v) in out.iter_mut().zip(u) {
        *o = curve.eval(v);
    }
    // The bases in order. A deferred base is the output of an earlier sample, mostly one of
    // the previous run (a reversal's force is the last output of the branch it ends): then
    // it is `prev + term` with `prev` the previous run's base, in a register. Otherwise it is
    // a value that needs nothing from the previous run (`other`: a known base, or a deferred
    // one from an older run, stored at least two runs back). Both as `prev · a + c`, with
    // `a = 1, c = term` or `a = 0, c = other`, `a` and `c` computed off the chain: the chain
    // from run to run is one multiply and one add in the floating-point registers — no branch
    // (known and deferred bases alternate at random on a random walk), no store-to-load
    // forwarding. The selects are products with 0.0 / 1.0 factors, exact for finite operands:
    // `x · 1 + y · 0` is `x` (up to the sign of a zero). Every operand is finite when the
    // call can succeed: a non-finite base (a non-finite earlier force) makes it an error
    // anyway, reported at its first non-finite sample. The placeholder base of a deferred run
    // is the force before the block: an earlier output, or the state's force, finite in every
    // state `MasingState::from_slice` accepts or this crate produces. `mul` is never written
    // here.
    let mut prev_ha = 0.0_f64;
    for k in 0..runs.len() {
        let r = runs[k];
        let deferred = r.src != KNOWN;
        // A known base reads (and then ignores) sample 0.
        let s = pick(deferred, u64::from(r.src), 0) as usize;
        let fid = usize::from(rid[s]);
        let term = runs[fid].mul * out[s];
        let older = runs[fid.min(k.saturating_sub(2))].ha;
        // Selects by multiplying with 0.0 / 1.0 (every operand finite), the factors computed
        // in floating point from the indices: LLVM turns integer selects between floats, and
        // floats converted from booleans, back into branches (coin tosses here).
        // d = 1 for a deferred base (src < KNOWN), 0 for a known one.
        let d = (f64::from(KNOWN) - f64::from(r.src)).min(1.0);
        // a = 1 for a base deferred to the previous run, else 0.
        let gap = (fid.wrapping_add(1) ^ k) as f64;
        let a = (d - gap.min(1.0)).max(0.0);
        let other = r.ha * (1.0 - d) + (older + term) * d;
        let ha = prev_ha * a + (term * a + other * (1.0 - a));
        runs[k].ha = ha;
        runs[k].src = KNOWN;
        prev_ha = ha;
    }
    // The bases and multipliers in two arrays indexed by a masked run number (`rid` < BLOCK
    // + 2 <= 1024: the mask changes nothing and spares the bounds check), so that the loop
    // over the samples vectorises with gathers; one run (a smooth block) needs no gather.
    // Whether every force is finite is found on the way (no pass of its own).
    let mut finite = true;
    if let [r] = runs {
        for o in out.iter_mut() {
            *o = r.ha + r.mul * *o;
            finite &= o.is_finite();
        }
        return finite;
    }
    if runs.len() <= SEGMENTS {
        // Few runs (a smooth block): `rid` is non-decreasing (runs are numbered in order), so
        // each run is a contiguous stretch, found by bisection, and done by a vectorised loop.
        let mut from = 0_usize;
        for (k, r) in runs.iter().enumerate() {
            let to = from.wrapping_add(rid[from..].partition_point(|&q| usize::from(q) <= k));
            for o in &mut out[from..to] {
                *o = r.ha + r.mul * *o;
                finite &= o.is_finite();
            }
            from = to;
        }
        return finite;
    }
    let (ha, mul) = (&mut tab.ha, &mut tab.mul);
    for ((h, m), r) in ha.iter_mut().zip(mul.iter_mut()).zip(runs.iter()) {
        (*h, *m) = (r.ha, r.mul);
    }
    for (o, &k) in out.iter_mut().zip(rid) {
        let k = usize::from(k) & (RUNS - 1);
        *o = ha[k] + mul[k] * *o;
        finite &= o.is_finite();
    }
    finite
}

/// The runs' bases and multipliers for the gathers of [`eval_block_body`] (allocated once
/// per call of the kernel, not per block).
pub(super) struct RunTab {
    ha: [f64; RUNS],
    mul: [f64; RUNS],
}

impl RunTab {
    pub(super) fn new() -> Box<Self> {
        Box::new(Self {
            ha: [0.0; RUNS],
            mul: [0.0; RUNS],
        })
    }
}

/// Up to this many runs in a block, [`eval_block_body`] applies the bases run by run.
const SEGMENTS: usize = 16;

/// Size of the gather tables of [`eval_block_body`]: a power of two above `BLOCK + 2`.
const RUNS: usize = 1024;

/// [`eval_block_body`] as a [`Kernel`] for [`simd::run`].
struct EvalBlock<'a, C> {
    curve: &'a C,
    runs: &'a mut [Run],
    u: &'a [f64],
    rid: &'a [u16],
    out: &'a mut [f64],
    tab: &'a mut RunTab,
}

impl<C: Backbone> Kernel for EvalBlock<'_, C> {
    type Output = bool;
    #[inline(always)]
    fn run_at(self) -> bool {
        eval_block_body(self.curve, self.runs, self.u, self.rid, self.out, self.tab)
    }
}

/// Curve pass of one block (see [`eval_block_body`]) compiled for SIMD level `level`: every
/// level runs the same IEEE operations in the same order, so the forces are the same bit for
/// bit (the curve's evaluation is the part that vectorises; no fused multiply-add is formed).
/// Returns whether every force of the block is finite.
#[inline(never)]
pub(super) fn eval_block<C: Backbone>(
    level: Level,
    curve: &C,
    runs: &mut [Run],
    u: &[f64],
    rid: &[u16],
    out: &mut [f64],
    tab: &mut RunTab,
) -> bool {
    simd::run(
        level,
        EvalBlock {
            curve,
            runs,
            u,
            rid,
            out,
            tab,
        },
    )
}

/// [`eval_dense_body`] as a [`Kernel`] for [`simd::run`].
struct EvalDense<'a, C> {
    curve: &'a C,
    d: &'a mut Dense,
    start: u64,
    out: &'a mut [f64],
}

impl<C: Backbone> Kernel for EvalDense<'_, C> {
    type Output = bool;
    #[inline(always)]
    fn run_at(self) -> bool {
        eval_dense_body(self.curve, self.d, self.start, self.out)
    }
}

/// Curve pass of a dense block (see [`eval_dense_body`]) compiled for SIMD level `level`
/// (bit for bit the same at every level). Returns whether every force is finite.
#[inline(never)]
fn eval_dense<C: Backbone>(
    level: Level,
    curve: &C,
    d: &mut Dense,
    start: u64,
    out: &mut [f64],
) -> bool {
    simd::run(
        level,
        EvalDense {
            curve,
            d,
            start,
            out,
        },
    )
}

/// Continuation bits of a block of input.
type Cont = [u64; BLOCK / 64];

/// Bit `p` (word `p / 64`) set when step `p` of `x` moves strictly in the direction of step
/// `p - 1`: `x[p] - x[p-1]` and `x[p-1] - x[p-2]` both positive or both negative. Bits 0 and
/// 1 (no earlier step in the block) and bits past `x.len()` are clear.
#[inline(always)]
fn continuation_bits(x: &[f64]) -> Cont {
    let mut flags = [0_u8; BLOCK];
    let m = x.len().min(BLOCK);
    if m >= 3 {
        let (a, b, c) = (&x[..m.wrapping_sub(2)], &x[1..m.wrapping_sub(1)], &x[2..m]);
        for (((f, &x0), &x1), &x2) in flags[2..m].iter_mut().zip(a).zip(b).zip(c) {
            let (d0, d1) = (x1 - x0, x2 - x1);
            *f = u8::from((d0 > 0.0 && d1 > 0.0) || (d0 < 0.0 && d1 < 0.0));
        }
    }
    let mut bits = [0_u64; BLOCK / 64];
    for (w, fl) in bits.iter_mut().zip(flags.chunks_exact(64)) {
        *w = fl
            .iter()
            .enumerate()
            .fold(0_u64, |acc, (j, &f)| acc | (u64::from(f) << j));
    }
    bits
}

/// The first position `>= p` whose bit in `bits` is clear (`BLOCK` if none).
#[inline(always)]
fn next_clear(bits: &Cont, p: usize) -> usize {
    let mut w = p / 64;
    if w >= bits.len() {
        return BLOCK;
    }
    let mut v = !bits[w] >> (p % 64);
    if v != 0 {
        return p.wrapping_add(v.trailing_zeros() as usize);
    }
    loop {
        w = w.wrapping_add(1);
        if w >= bits.len() {
            return BLOCK;
        }
        v = !bits[w];
        if v != 0 {
            return (w << 6).wrapping_add(v.trailing_zeros() as usize);
        }
    }
}

/// First pass over one block ([`Pass::block_body`]) compiled for SIMD level `level`.
#[inline(never)]
fn block_pass(
    level: Level,
    pass: &mut Pass,
    stk: &mut [Reversal],
    xc: &[f64],
    u: &mut [f64],
    rid: &mut [u16],
    runs: &mut [Run; BLOCK + 2],
    cont: &Cont,
) -> usize {
    simd::run(
        level,
        BlockPass {
            pass,
            stk,
            xc,
            u,
            rid,
            runs,
            cont,
        },
    )
}

/// [`Pass::block_body`] as a [`Kernel`] for [`simd::run`].
struct BlockPass<'a> {
    pass: &'a mut Pass,
    stk: &'a mut [Reversal],
    xc: &'a [f64],
    u: &'a mut [f64],
    rid: &'a mut [u16],
    runs: &'a mut [Run; BLOCK + 2],
    cont: &'a Cont,
}

impl Kernel for BlockPass<'_> {
    type Output = usize;
    #[inline(always)]
    fn run_at(self) -> usize {
        self.pass
            .block_body(self.stk, self.xc, self.u, self.rid, self.runs, self.cont)
    }
}

/// The input scan of a block, as a [`Kernel`]: whether every value is finite and, when so,
/// the continuation bits (the first pass's turning points).
/// (The bits only when the second field says so; else all clear.)
struct Scan<'a>(&'a [f64], bool);

impl Kernel for Scan<'_> {
    type Output = Option<Cont>;
    #[inline(always)]
    fn run_at(self) -> Option<Cont> {
        let (x, bits) = (self.0, self.1);
        all_finite(x).then(|| {
            if bits {
                continuation_bits(x)
            } else {
                [0; BLOCK / 64]
            }
        })
    }
}

/// Anchor index of a sample on the virgin curve (its base is 0, its multiplier 1).
const VIRGIN: u64 = u64::MAX;

/// Per-sample records of a dense block ([`Pass::dense_block`]).
pub(super) struct Dense {
    u: [f64; BLOCK],
    /// Padding: arrays 4 KiB apart alias in the store-to-load check (the stores of one
    /// sample would all share their low 12 address bits).
    _pad0: [f64; 40],
    idx: [u64; BLOCK],
    _pad1: [f64; 40],
    /// `kh[p]`: the known base of sample `p` (an anchor before the block, or 0 on the virgin
    /// curve); `kh[BLOCK + p]`: the output of sample `p` once computed, the base of the
    /// samples anchored at it.
    kh: [f64; 2 * BLOCK],
    _pad2: [f64; 40],
    mm: [f64; BLOCK],
}

impl Dense {
    pub(super) fn new() -> Box<Self> {
        Box::new(Self {
            u: [0.0; BLOCK],
            _pad0: [0.0; 40],
            idx: [0; BLOCK],
            _pad1: [0.0; 40],
            kh: [0.0; 2 * BLOCK],
            _pad2: [0.0; 40],
            mm: [0.0; BLOCK],
        })
    }
}

/// Curve pass of a dense block: `out[p] = f(u[p])` over the block (vectorised), then in
/// order `out[p] = base + mm[p] · out[p]` with `base` the output of the in-block anchor
/// sample (`idx[p] - start < BLOCK`) or the known `kh[p]`, picked by an index into one
/// buffer (no data-dependent branch).
#[inline(always)]
fn eval_dense_body<C: Backbone>(curve: &C, d: &mut Dense, start: u64, out: &mut [f64]) -> bool {
    let m = out.len().min(BLOCK);
    let out = &mut out[..m];
    for (o, &v) in out.iter_mut().zip(&d.u[..m]) {
        *o = curve.eval(v);
    }
    for (p, o) in out.iter_mut().enumerate() {
        let rel = d.idx[p].wrapping_sub(start);
        // the anchor's output (BLOCK + rel) when it is in this block, else the known base
        let j = pick(
            rel < BLOCK as u64,
            (BLOCK as u64).wrapping_add(rel),
            p as u64,
        ) as usize;
        let v = d.kh[j & (2 * BLOCK - 1)] + d.mm[p] * *o;
        d.kh[BLOCK.wrapping_add(p) & (2 * BLOCK - 1)] = v;
        *o = v;
    }
    out.iter().fold(true, |ok, o| ok & o.is_finite())
}

/// Written above the stack top (never read as a reversal).
const SPARE: Reversal = Reversal {
    x: 0.0,
    h: 0.0,
    index: 0,
};

/// First-pass state. The stack is the caller's `Vec`, kept longer than its logical length
/// `n` so that a candidate reversal can be written above the top without a test; the passes
/// take it as a slice (its pointer and length stay in registers).
#[derive(Clone, Copy)]
struct Pass {
    n: usize,
    lam: f64,
    inv_lam: f64,
    xp: f64,
    /// +1, -1, or 0 before the first move.
    dir: f64,
    /// Current branch, `h = ha + mul · f((x - xa) · inv)`, closing where the input reaches
    /// `target`; `xa` is the stack top's input, `ha` its force or, while that is deferred,
    /// the in-block sample `src` whose output it is (kept in registers).
    xa: f64,
    ha: f64,
    src: u32,
    inv: f64,
    target: f64,
    /// Global index of the block's first sample; reversals at or after it are deferred.
    start: u64,
    /// Output of the sample before the block.
    h_before: f64,
}

/// `a` if `c` else `b`, by a mask: no branch whatever the compiler thinks of `c`.
#[inline(always)]
fn pick(c: bool, a: u64, b: u64) -> u64 {
    let m = 0_u64.wrapping_sub(u64::from(c));
    b ^ ((a ^ b) & m)
}

/// Sign bit of an f64.
const SIGN: u64 = 1 << 63;

/// Where the branch from the top of a stack of `n >= 1` reversals closes: the reversal below
/// the top, or for `n == 1` the mirror `-x` of the first reversal. Integer selects only: on
/// x86-64 a select between two f64 on an integer condition becomes a branch, and this one
/// is a coin toss on a random walk.
#[inline(always)]
fn target_of(stk: &[Reversal], n: usize) -> f64 {
    let k = pick(n >= 2, n.wrapping_sub(2) as u64, 0) as usize;
    let neg = pick(n == 1, SIGN, 0);
    f64::from_bits(stk[k].x.to_bits() ^ neg)
}

/// `a` or `b` by an integer select: on x86-64 a select between two f64 on a non-float
/// condition becomes a branch, and these conditions are coin tosses on a random walk.
#[inline(always)]
fn pickf(c: bool, a: f64, b: f64) -> f64 {
    f64::from_bits(pick(c, a.to_bits(), b.to_bits()))
}

impl Pass {
    /// Load the current branch from the stack (at a block's start and after closures).
    #[inline(always)]
    fn load_branch(&mut self, stk: &[Reversal]) {
        let n = self.n;
        if n == 0 {
            (self.xa, self.ha, self.src, self.inv) = (0.0, 0.0, KNOWN, 1.0);
            self.target = if self.dir >= 0.0 {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            };
        } else {
            let top = stk[n.saturating_sub(1)];
            // Deferred: found in this block (after its first sample).
            let src = match top.index.checked_sub(self.start) {
                Some(k) if k < BLOCK as u64 => k as u32,
                _ => KNOWN,
            };
            (self.xa, self.ha, self.src, self.inv) = (top.x, top.h, src, self.inv_lam);
            self.target = target_of(stk, n);
        }
    }

    /// Run record of the current branch.
    #[inline(always)]
    fn record(&self) -> Run {
        let virgin = self.n == 0;
        Run {
            ha: if virgin { 0.0 } else { self.ha },
            src: self.src,
            mul: if virgin { 1.0 } else { self.lam },
        }
    }

    /// The memory rules for input `xi`, block position `p`: a reversal at the previous sample
    /// and/or closures. Updates the stack, the branch, `dir` and `xp`; returns whether the
    /// branch changed.
    ///
    /// A reversal is handled without a branch: the candidate (the previous sample) is always
    /// written above the stack top, the top raised by 0 or 1, and the branch registers
    /// selected. A closure (a quarter of the samples of a random walk, rare otherwise) is a
    /// branch that reloads the branch from the stack.
    #[inline(always)]
    // `&` on booleans on purpose: no branch per condition.
    #[allow(clippy::needless_bitwise_bool)]
    fn rules(&mut self, stk: &mut [Reversal], xi: f64, p: usize) -> bool {
        let dx = xi - self.xp;
        let moved = dx != 0.0;
        let s = 1.0_f64.copysign(dx);
        let rev = moved & (s != self.dir) & (self.dir != 0.0);
        // The first move sets the direction of the virgin branch (and where it never closes).
        let first = moved & (self.dir == 0.0);
        // The reversal is the previous sample, global index start + p - 1 (the caller sees
        // to it that there is one when p = 0). Its force is `h_before` for p = 0 and is
        // deferred to in-block sample p - 1 otherwise (`h` is then a placeholder until the
        // block ends).
        stk[self.n] = Reversal {
            x: self.xp,
            h: self.h_before,
            index: self.start.wrapping_add(p as u64).wrapping_sub(1),
        };
        self.ha = pickf(rev, self.h_before, self.ha);
        // After a reversal the branch starts at it and heads for the previous top (off the
        // virgin curve: for the mirror point of the reversal, set below).
        let from_virgin = rev & (self.n == 0);
        self.target = pickf(rev, self.xa, self.target);
        self.xa = pickf(rev, self.xp, self.xa);
        // p - 1, and KNOWN (u32::MAX) for p = 0
        self.src = pick(
            rev,
            u64::from((p as u32).wrapping_sub(1)),
            u64::from(self.src),
        ) as u32;
        self.n = self.n.saturating_add(usize::from(rev)); // < stk.len()
        if from_virgin {
            self.target = -self.xp;
            self.inv = self.inv_lam;
        }
        if moved {
            self.dir = s;
            self.xp = xi;
        }
        // Off the virgin curve `target` is finite; on it, ±inf in the direction of travel
        // (never reached) except right at the first move, which rebuilds the branch anyway.
        let closes = moved & ((xi - self.target) * s >= 0.0);
        if closes | first {
            // Wipe out every loop this step closes (several only after a large jump).
            while self.n > 0 && (xi - target_of(stk, self.n)) * s >= 0.0 {
                self.n = self.n.saturating_sub(self.n.min(2));
            }
            self.load_branch(stk);
        }
        rev | closes | first
    }

    /// [`Pass::rules`] with the common cases free of data-dependent branches: a step that
    /// moves, off the first reversal's branch (a stack of two or more), with a reversal or
    /// not, closing one loop or none, raises the top by 0 or 1 and lowers it by 0 or 2 by
    /// arithmetic on the comparisons and reloads the branch from the stack (the same values
    /// [`Pass::rules`] selects); a closure that leaves fewer than two reversals, a zero-length
    /// step and the first move go through [`Pass::rules`], further closures in one step
    /// through [`Pass::more_closures`]. Returns whether the branch changed.
    #[inline(always)]
    // `&` on booleans on purpose: no branch per condition.
    #[allow(clippy::needless_bitwise_bool)]
    fn step_rules(&mut self, stk: &mut [Reversal], xi: f64, p: usize) -> bool {
        let dx = xi - self.xp;
        if (dx == 0.0) | (self.dir == 0.0) | (self.n < 2) {
            return self.rules(stk, xi, p);
        }
        let s = 1.0_f64.copysign(dx);
        let rev = s != self.dir;
        // Candidate reversal: the previous sample (see `rules`).
        stk[self.n] = Reversal {
            x: self.xp,
            h: self.h_before,
            index: self.start.wrapping_add(p as u64).wrapping_sub(1),
        };
        let n1 = self.n.wrapping_add(usize::from(rev)); // in 2..stk.len()
                                                        // The branch from the top of n1 reversals heads for the one below it.
        let closes = (xi - stk[n1.wrapping_sub(2)].x) * s >= 0.0;
        if closes & (n1 < 4) {
            // Down to the first reversal's branch or the virgin curve.
            return self.rules(stk, xi, p);
        }
        self.n = n1.wrapping_sub(usize::from(closes) << 1); // >= 2
        self.dir = s;
        self.xp = xi;
        if closes & ((xi - stk[self.n.wrapping_sub(2)].x) * s >= 0.0) {
            self.more_closures(stk, xi, s); // reloads the branch
        } else {
            self.load_branch(stk);
        }
        rev | closes
    }

    /// First pass over one block (`xc`, global start `self.start`): curve arguments into `u`,
    /// the runs into `runs` and each sample's run into `rid`. Returns the number of runs.
    ///
    /// The input's turning points are found first, for the whole block in one vectorised
    /// loop: bit `p` of `cont` says that step `p` moves strictly in the direction of step
    /// `p - 1` (`x[p] - x[p-1]` and `x[p-1] - x[p-2]` both positive or both negative). The
    /// memory rules then run once per sample where the bit is clear (a reversal, a
    /// zero-length step, the block's first sample) and the samples of the monotone stretch
    /// that follows are filled in bulk — `u = (x - x_a) · inv` on the current branch — when
    /// up to the first sample that reaches the branch's closure point (the stretch being
    /// monotone, the samples short of it are a prefix, counted without a branch for a short
    /// stretch; `(x - target) · dir` is monotone in `x` after rounding too); that sample goes
    /// through the rules ([`Pass::step_rules`]). The arguments and runs are the same bit for
    /// bit as the sample-by-sample pass's.
    #[inline(always)]
    // `&` on booleans on purpose: no branch per condition.
    #[allow(clippy::needless_bitwise_bool)]
    fn block_body(
        &mut self,
        stk: &mut [Reversal],
        xc: &[f64],
        u: &mut [f64],
        rid: &mut [u16],
        runs: &mut [Run; BLOCK + 2],
        cont: &Cont,
    ) -> usize {
        const W: usize = 8;
        // Work on a copy in registers (the struct behind `self` would live in memory).
        let mut st = *self;
        st.load_branch(stk); // the top's force may have been resolved since
        runs[0] = st.record();
        let mut nr = 1_usize;
        let m = xc.len().min(BLOCK).min(u.len()).min(rid.len());
        let (xc, u, rid) = (&xc[..m], &mut u[..m], &mut rid[..m]);
        let mut p = 0_usize;
        while p < m {
            // One sample through the rules (or the fast path).
            let xi = xc[p];
            let dx = xi - st.xp;
            // Moving on along the branch without reaching its closure point.
            if dx * st.dir > 0.0 && (xi - st.target) * st.dir < 0.0 {
                st.xp = xi;
            } else if st.step_rules(stk, xi, p) {
                runs[nr] = st.record();
                nr = nr.wrapping_add(1); // <= BLOCK + 1
            }
            u[p] = (st.xp - st.xa) * st.inv;
            let r = nr.wrapping_sub(1) as u16; // nr in 1..=BLOCK + 1
            rid[p] = r;
            p = p.wrapping_add(1);
            // The monotone stretch p..q that continues the direction of the last step.
            let q = next_clear(cont, p).min(m);
            let (t, d) = (st.target, st.dir);
            let (xa, inv) = (st.xa, st.inv);
            let len = q.wrapping_sub(p); // q >= p
            let e = p.wrapping_add(W);
            if (len <= W) & (e <= m) {
                // A short stretch, without a data-dependent branch: the samples short of the
                // closure point are a prefix p..c of it (the stretch being monotone, and
                // `(x - target) · dir` non-decreasing along it after rounding too); W lanes
                // are written from p, those from c on are rewritten by the samples after.
                let mut k = 0_usize;
                for j in 0..W {
                    let x = xc[p.wrapping_add(j)];
                    k = k.wrapping_add(usize::from(((x - t) * d < 0.0) & (j < len)));
                }
                for j in p..e {
                    u[j] = (xc[j] - xa) * inv;
                    rid[j] = r;
                }
                p = p.wrapping_add(k);
                st.xp = xc[p.wrapping_sub(1)]; // the last input so far (p >= 1)
            } else if q > p {
                // The same for a long stretch (or one at the block's end).
                let c = if (xc[q.wrapping_sub(1)] - t) * d < 0.0 {
                    q
                } else {
                    let short = xc[p..q].iter().map(|&x| usize::from((x - t) * d < 0.0));
                    p.wrapping_add(short.sum::<usize>())
                };
                if c > p {
                    let mut i = p;
                    while i < c {
                        let e = i.wrapping_add(W);
                        if e <= m {
                            for j in i..e {
                                u[j] = (xc[j] - xa) * inv;
                                rid[j] = r;
                            }
                        } else {
                            for j in i..m {
                                u[j] = (xc[j] - xa) * inv;
                                rid[j] = r;
                            }
                        }
                        i = i.wrapping_add(W);
                    }
                    st.xp = xc[c.wrapping_sub(1)];
                    p = c;
                }
            }
        }
        *self = st;
        nr
    }

    /// The record of the current sample for [`eval_dense`]: the anchor's global sample
    /// index ([`VIRGIN`] on the virgin curve), its force as far as it is known (a deferred
    /// one is resolved by the index), and the branch's multiplier.
    #[inline(always)]
    fn anchor(&self, stk: &[Reversal]) -> (u64, f64, f64) {
        if self.n == 0 {
            (VIRGIN, 0.0, 1.0)
        } else {
            let top = stk[self.n.saturating_sub(1)];
            (top.index, top.h, self.lam)
        }
    }

    /// First pass for a block where the input reverses often (a random walk reverses every
    /// ~2 samples; there the predicted test of [`Pass::block_body`] is a coin toss). It writes, per
    /// sample, the curve argument `u`, the anchor's sample index `idx`, its force `kh` where
    /// known (before the block) and the branch multiplier `mm`; [`eval_dense`] resolves the
    /// rest. No run table: a branch change costs nothing more than a step on. Returns the
    /// number of branch changes.
    ///
    /// Only the stack depth `n`, the last input and the direction live in registers: the
    /// current branch's target is always `stk[n - 2].x` and its anchor `stk[n - 1]` (the
    /// candidate reversal, always written above the top, is the anchor once the top is raised
    /// over it), so a reversal raises `n` by one and a closure lowers it by two, by
    /// arithmetic on the comparison results, without a data-dependent branch.
    ///
    /// Left to branches (rare on such a signal): a stack of fewer than two reversals (the
    /// virgin curve, or the first reversal's branch whose target is a mirror point) and a
    /// closure down to it, both through [`Pass::rules`]; a step that closes two or more
    /// loops at once; a zero-length step. Needs `dir != 0` (the first move goes through
    /// [`Pass::block_body`]).
    #[inline(never)]
    // `&` on booleans on purpose: no branch per condition.
    #[allow(clippy::needless_bitwise_bool)]
    fn dense_block(&mut self, stk: &mut [Reversal], xc: &[f64], d: &mut Dense) -> usize {
        self.load_branch(stk); // the top's force may have been resolved since
        let (start, lam, inv_lam, h_before) = (self.start, self.lam, self.inv_lam, self.h_before);
        // Global index of the sample before block position 0.
        let before = start.wrapping_sub(1);
        let (mut n, mut xp, mut up) = (self.n, self.xp, self.dir > 0.0);
        let mut changes = 0_usize;
        // Record of the last sample (a zero-length step repeats it).
        let mut ul = (xp - self.xa) * self.inv;
        let (mut li, mut lk, mut lm) = self.anchor(stk);
        // The inputs of the top reversal and the one below it, kept in registers while the
        // stack holds two or more (reloaded after the rare paths): the closure test of the
        // common step then needs no load that waits for the previous step's depth.
        let reload = |n: usize, stk: &[Reversal]| {
            if n >= 2 {
                (stk[n.wrapping_sub(1)].x, stk[n.wrapping_sub(2)].x)
            } else {
                (0.0, 0.0)
            }
        };
        let (mut ta, mut tb) = reload(self.n, stk);
        let m = xc.len().min(BLOCK);
        let (u, idx, kh, mm) = (
            &mut d.u[..m],
            &mut d.idx[..m],
            &mut d.kh[..m],
            &mut d.mm[..m],
        );
        for (p, &xi) in xc[..m].iter().enumerate() {
            if xi == xp {
                // A zero-length step changes nothing (a predicted branch: rare where the
                // input reverses often).
                (u[p], idx[p], kh[p], mm[p]) = (ul, li, lk, lm);
                continue;
            }
            let rising = xi > xp;
            if n < 2 {
                // The virgin curve or the first reversal's branch (whose target is a mirror
                // point): the general rules.
                let mut q = Pass {
                    n,
                    xp,
                    dir: if up { 1.0 } else { -1.0 },
                    ..*self
                };
                q.load_branch(stk);
                changes = changes.wrapping_add(usize::from(q.rules(stk, xi, p)));
                (n, xp, up) = (q.n, q.xp, q.dir > 0.0);
                ul = (q.xp - q.xa) * q.inv;
                (li, lk, lm) = q.anchor(stk);
                (ta, tb) = reload(n, stk);
                (u[p], idx[p], kh[p], mm[p]) = (ul, li, lk, lm);
                continue;
            }
            let rev = rising != up;
            // Candidate reversal: the previous sample (its force deferred for p > 0).
            stk[n] = Reversal {
                x: xp,
                h: h_before,
                index: before.wrapping_add(p as u64),
            };
            // in 2..stk.len()
            let n1 = n.wrapping_add(usize::from(rev));
            // The target stk[n1 - 2].x: the top's input after a reversal, else the one below.
            let t = pickf(rev, ta, tb);
            // (x - target) · s >= 0 with s the direction of the step
            let closes = (rising & (xi >= t)) | (!rising & (xi <= t));
            if closes {
                if n1 < 4 {
                    // A closure down to the first reversal's branch or onto the virgin
                    // curve: the general rules.
                    let mut q = Pass {
                        n,
                        xp,
                        dir: if up { 1.0 } else { -1.0 },
                        ..*self
                    };
                    q.load_branch(stk);
                    changes = changes.wrapping_add(usize::from(q.rules(stk, xi, p)));
                    (n, xp, up) = (q.n, q.xp, q.dir > 0.0);
                    ul = (q.xp - q.xa) * q.inv;
                    (li, lk, lm) = q.anchor(stk);
                    (ta, tb) = reload(n, stk);
                    (u[p], idx[p], kh[p], mm[p]) = (ul, li, lk, lm);
                    continue;
                }
                n = n1.wrapping_sub(2); // >= 2
                up = rising;
                xp = xi;
                changes = changes.wrapping_add(1); // <= BLOCK
                let below = stk[n.wrapping_sub(2)].x;
                if (rising & (xi >= below)) | (!rising & (xi <= below)) {
                    // The step closes further loops (a large jump).
                    let mut q = Pass {
                        n,
                        xp,
                        dir: if up { 1.0 } else { -1.0 },
                        ..*self
                    };
                    q.more_closures(stk, xi, q.dir);
                    n = q.n;
                    ul = (xp - q.xa) * q.inv;
                    (li, lk, lm) = q.anchor(stk);
                    (ta, tb) = reload(n, stk);
                    (u[p], idx[p], kh[p], mm[p]) = (ul, li, lk, lm);
                    continue;
                }
                let top = stk[n.wrapping_sub(1)];
                (ta, tb) = (top.x, below);
                ul = (xp - top.x) * inv_lam;
                (li, lk, lm) = (top.index, top.h, lam);
                (u[p], idx[p], kh[p], mm[p]) = (ul, li, lk, lm);
                continue;
            }
            // No closure: after a reversal the candidate (the previous sample) is the top.
            n = n1;
            changes = changes.wrapping_add(usize::from(rev)); // <= BLOCK
            tb = pickf(rev, ta, tb);
            ta = pickf(rev, xp, ta);
            li = pick(rev, before.wrapping_add(p as u64), li);
            lk = pickf(rev, h_before, lk);
            lm = lam;
            up = rising;
            xp = xi;
            ul = (xp - ta) * inv_lam;
            (u[p], idx[p], kh[p], mm[p]) = (ul, li, lk, lm);
        }
        (self.n, self.xp, self.dir) = (n, xp, if up { 1.0 } else { -1.0 });
        self.load_branch(stk);
        changes
    }

    /// After a first closure by input `xi` (direction `s`, already the state's direction and
    /// input), wipe out the further loops the step closes.
    #[cold]
    #[inline(never)]
    fn more_closures(&mut self, stk: &[Reversal], xi: f64, s: f64) {
        while self.n > 0 && (xi - target_of(stk, self.n)) * s >= 0.0 {
            self.n = self.n.saturating_sub(self.n.min(2));
        }
        self.load_branch(stk);
    }

    /// The block's forces are `out`: resolve the deferred reversal forces.
    #[inline(always)]
    fn end_block(&mut self, stk: &mut [Reversal], out: &[f64]) {
        for r in stk[..self.n].iter_mut().rev() {
            if r.index < self.start {
                break; // deferred entries are the newest ones
            }
            let k = usize::try_from(r.index.wrapping_sub(self.start)).unwrap_or(usize::MAX);
            if let Some(&h) = out.get(k) {
                r.h = h;
            }
        }
        if let Some(&h) = out.last() {
            self.h_before = h;
        }
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
/// (the input before its block is run: no separate pass over `x`).
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
        // block path will need them.
        let dense_path = dense && pass.dir != 0.0;
        let Some(cont) = simd::run(level, Scan(xc, !dense_path)) else {
            return Forces::BadInput;
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
            let c = pass.dense_block(stk, xc, d);
            finite &= eval_dense(level, curve, d, pass.start, oc);
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

#[cfg(test)]
mod level_tests {
    //! Every SIMD level the CPU has gives the generic path's forces bit for bit, and all of
    //! them the plain loop's (the anchor's rules with libm `exp`) to 1e-12 of h0.
    use super::*;
    use crate::curve::Exponential;

    fn uniform(seed: u64, n: usize) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                2.0 * ((s >> 11) as f64 / 9_007_199_254_740_992.0) - 1.0
            })
            .collect()
    }

    /// Sine (long runs), band-limited noise (runs of ~6), random walk (runs of ~2), and a
    /// mix with zero-length steps, held values, jumps that close several loops, and a drift.
    fn signals(n: usize) -> Vec<Vec<f64>> {
        let sine: Vec<f64> = (0..n)
            .map(|i| 0.8 * (std::f64::consts::TAU * (i % 700) as f64 / 700.0).sin())
            .collect();
        let e = uniform(1, n);
        let mut band = vec![0.0; n];
        let a1 = 2.0 * 0.95 * (std::f64::consts::TAU / 40.0).cos();
        for i in 2..n {
            band[i] = a1 * band[i - 1] - 0.9025 * band[i - 2] + 0.06 * e[i];
        }
        let e = uniform(2, n);
        let mut walk = vec![0.0; n];
        for i in 1..n {
            walk[i] = 0.999 * walk[i - 1] + 0.05 * e[i];
        }
        let e = uniform(3, n);
        let mixed: Vec<f64> = (0..n)
            .map(|i| {
                let held = (i / 3) as f64; // every value thrice: zero-length steps
                let jump = if i % 997 == 0 { 3.0 * e[i] } else { 0.0 };
                0.4 * (held * 0.05).sin() + 0.1 * e[i].round() + jump + 1e-5 * i as f64
            })
            .collect();
        vec![sine, band, walk, mixed]
    }

    /// The anchor's scalar loop (`masing_anchor.rs`, `masing`) for branch scale `lam`.
    fn plain(h0: f64, ac: f64, lam: f64, x: &[f64]) -> Vec<f64> {
        let (mut xr, mut hr): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
        let (mut xp, mut hp, mut d) = (0.0_f64, 0.0_f64, 0.0_f64);
        let f = |u: f64| (h0 * -(-ac * u.abs()).exp_m1()).copysign(u);
        x.iter()
            .map(|&xi| {
                if xi != xp {
                    let s = if xi > xp { 1.0 } else { -1.0 };
                    if s != d {
                        if d != 0.0 {
                            xr.push(xp);
                            hr.push(hp);
                        }
                        d = s;
                    }
                    while let Some(&top) = xr.last() {
                        let k = xr.len();
                        let t = if k >= 2 { xr[k - 2] } else { -top };
                        if s * (xi - t) < 0.0 {
                            break;
                        }
                        let nk = k.saturating_sub(2);
                        xr.truncate(nk);
                        hr.truncate(nk);
                    }
                    hp = match (xr.last(), hr.last()) {
                        (Some(&a), Some(&b)) => b + lam * f((xi - a) / lam),
                        _ => f(xi),
                    };
                    xp = xi;
                }
                hp
            })
            .collect()
    }

    #[test]
    fn every_level_gives_the_generic_forces_bit_for_bit() {
        let (h0, ac) = (1.0, 3.0);
        let c = Exponential::new(h0, ac).unwrap_or_else(|_| unreachable!());
        for (k, x) in signals(20_000).iter().enumerate() {
            for lam in [2.0, 1.7] {
                let run_at = |level: Level, cut: usize| {
                    let mut out = vec![0.0; x.len()];
                    let mut st = MasingState::default();
                    let (a, b) = x.split_at(cut);
                    let (oa, ob) = out.split_at_mut(cut);
                    assert_eq!(scaled_force(level, &c, lam, a, oa, &mut st), Forces::Finite);
                    assert_eq!(scaled_force(level, &c, lam, b, ob, &mut st), Forces::Finite);
                    (out, st)
                };
                let (want, want_st) = run_at(Level::Generic, x.len());
                let reference = plain(h0, ac, lam, x);
                let worst = want
                    .iter()
                    .zip(&reference)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= 1e-12 * h0,
                    "signal {k}, lam {lam}: {worst:e} from the loop"
                );
                for level in Level::ALL.into_iter().filter(|l| l.supported()) {
                    for cut in [x.len(), 777, 5_000] {
                        let (got, st) = run_at(level, cut);
                        let same = got
                            .iter()
                            .zip(&want)
                            .all(|(a, b)| a.to_bits() == b.to_bits());
                        assert!(same, "signal {k}, level {}, cut {cut}", level.name());
                        assert_eq!(st, want_st);
                    }
                }
            }
        }
    }

    #[test]
    fn a_non_finite_input_stops_the_kernel_at_every_level() {
        let c = Exponential::new(1.0, 3.0).unwrap_or_else(|_| unreachable!());
        for level in Level::ALL.into_iter().filter(|l| l.supported()) {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut x: Vec<f64> = (0..3000).map(|i| (i as f64 * 0.01).sin()).collect();
                x[2100] = bad;
                let mut out = vec![0.0; x.len()];
                let mut st = MasingState::default();
                let r = scaled_force(level, &c, 2.0, &x, &mut out, &mut st);
                assert_eq!(r, Forces::BadInput, "level {}", level.name());
            }
        }
    }
}
