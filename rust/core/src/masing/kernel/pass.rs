//! The first pass of the kernel: the memory rules applied sample by sample ([`Pass`]), on a
//! block with runs ([`Pass::block_body`], run by [`block_pass`] at the SIMD level) or on a
//! dense block ([`Pass::dense_block`]), and the branch-free selects they use.

use super::scan::{next_clear, Cont};
use super::{pick, Dense, Run, BLOCK, KH, KNOWN, VIRGIN_SLOT};
use crate::masing::Reversal;
use crate::simd::{self, Kernel, Level};

/// First pass over one block ([`Pass::block_body`]) compiled for SIMD level `level`.
#[inline(never)]
pub(super) fn block_pass(
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

/// First pass over one dense block ([`Pass::dense_block`]) compiled for SIMD level `level`
/// (scalar code; the wider levels bring three-operand instructions and twice the registers,
/// the same IEEE operations in the same order). The branch target is selected in registers
/// at AVX-512 (a masked move) and loaded from the stack below it: there the compiler turns
/// the select into a branch, a coin toss on a random walk (measured on the anchor's random
/// walk with `CONTACTLAB_SIMD=avx2`: 1.3x the anchor with the select, 1.8x with the load; at
/// AVX-512 the select is 5 to 10 % faster than the load).
#[inline(never)]
pub(super) fn dense_pass(
    level: Level,
    pass: &mut Pass,
    stk: &mut [Reversal],
    xc: &[f64],
    d: &mut Dense,
) -> usize {
    if level == Level::Avx512 {
        simd::run(level, DensePass::<true> { pass, stk, xc, d })
    } else {
        simd::run(level, DensePass::<false> { pass, stk, xc, d })
    }
}

/// [`Pass::dense_block`] as a [`Kernel`] for [`simd::run`] (`SELECT`: see [`dense_pass`]).
struct DensePass<'a, const SELECT: bool> {
    pass: &'a mut Pass,
    stk: &'a mut [Reversal],
    xc: &'a [f64],
    d: &'a mut Dense,
}

impl<const SELECT: bool> Kernel for DensePass<'_, SELECT> {
    type Output = usize;
    #[inline(always)]
    fn run_at(self) -> usize {
        self.pass.dense_block::<SELECT>(self.stk, self.xc, self.d)
    }
}

/// The inputs of the top two reversals of a stack of `n` (0 for fewer than two).
#[inline(always)]
fn top_two(n: usize, stk: &[Reversal]) -> (f64, f64) {
    if n >= 2 {
        (stk[n.wrapping_sub(1)].x, stk[n.wrapping_sub(2)].x)
    } else {
        (0.0, 0.0)
    }
}

/// The base slot ([`Dense::kh`]) of block position `p` whose branch starts at reversal
/// `top` (off the virgin curve), the sample before the block being `before`: that of the
/// output of an in-block sample or of the sample before the block, else slot `p`, where the
/// known force is written (always written, harmless when unused: slot `p` is read only by
/// samples whose slot this call made `p`). Integer selects only (in-block and older anchors
/// alternate at random after closures).
#[inline(always)]
fn known_slot(top: Reversal, before: u64, p: usize, kh: &mut [f64; KH]) -> u32 {
    // 0 for the sample before the block, q + 1 for in-block sample q
    let rel = top.index.wrapping_sub(before);
    kh[p & (BLOCK - 1)] = top.h;
    pick(
        rel <= BLOCK as u64,
        (BLOCK as u64).wrapping_add(rel),
        p as u64,
    ) as u32
}

/// Written above the stack top (never read as a reversal).
pub(super) const SPARE: Reversal = Reversal {
    x: 0.0,
    h: 0.0,
    index: 0,
};

/// First-pass state. The stack is the caller's `Vec`, kept longer than its logical length
/// `n` so that a candidate reversal can be written above the top without a test; the passes
/// take it as a slice (its pointer and length stay in registers).
#[derive(Clone, Copy)]
pub(super) struct Pass {
    pub(super) n: usize,
    pub(super) lam: f64,
    pub(super) inv_lam: f64,
    pub(super) xp: f64,
    /// +1, -1, or 0 before the first move.
    pub(super) dir: f64,
    /// Current branch, `h = ha + mul · f((x - xa) · inv)`, closing where the input reaches
    /// `target`; `xa` is the stack top's input, `ha` its force or, while that is deferred,
    /// the in-block sample `src` whose output it is (kept in registers).
    pub(super) xa: f64,
    pub(super) ha: f64,
    pub(super) src: u32,
    pub(super) inv: f64,
    pub(super) target: f64,
    /// Global index of the block's first sample; reversals at or after it are deferred.
    pub(super) start: u64,
    /// Output of the sample before the block.
    pub(super) h_before: f64,
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
    pub(super) fn load_branch(&mut self, stk: &[Reversal]) {
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

    /// The base slot ([`Dense::kh`]) of block position `p` for [`eval_dense`] on the current
    /// branch: [`VIRGIN_SLOT`] on the virgin curve, else that of the anchor, the stack top
    /// (see [`known_slot`]).
    #[inline(always)]
    fn slot(&self, stk: &[Reversal], p: usize, kh: &mut [f64; KH]) -> u32 {
        if self.n == 0 {
            VIRGIN_SLOT
        } else {
            let top = stk[self.n.saturating_sub(1)];
            known_slot(top, self.start.wrapping_sub(1), p, kh)
        }
    }

    /// First pass for a block where the input reverses often (a random walk reverses every
    /// ~2 samples; there the predicted test of [`Pass::block_body`] is a coin toss). It writes, per
    /// sample, the curve argument `u` and the slot of its base in [`Dense::kh`] (writing there
    /// the bases known before the block); [`eval_dense`] resolves the rest. No run table: a
    /// branch change costs nothing more than a step on. Returns the number of branch changes.
    ///
    /// Only the stack depth `n`, the last input and the direction live in registers (and the
    /// inputs of the top two reversals, so that the closure test of a step needs no load that
    /// waits for the previous step's depth): the current branch's target is always
    /// `stk[n - 2].x` and its anchor `stk[n - 1]` (the candidate reversal, always written above
    /// the top, is the anchor once the top is raised over it), so a reversal raises `n` by one
    /// and a closure lowers it by two, by arithmetic on the comparison results, without a
    /// data-dependent branch. Per common step four stores: the candidate's input and index,
    /// the argument and the slot (after a reversal the anchor's slot is that of the previous
    /// sample's output, `BLOCK + p`).
    ///
    /// The common steps (a move on a stack of two or more, with a reversal or not, closing
    /// one loop or none; the closure a predicted branch, taken on about a tenth of the
    /// samples of a band-limited signal and a fifth of a random walk's) run in an inner loop
    /// of their own; it leaves, to apply [`Pass::rules`], for the rare others: a zero-length
    /// step, a stack of fewer than two reversals (the virgin curve, or the first reversal's
    /// branch whose target is a mirror point), a closure down to it, and a step that closes
    /// two loops or more. With those in the same loop body, the compiler kept a branch
    /// register on the stack, stored and reloaded at every step. Needs `dir != 0` (the first
    /// move goes through [`Pass::block_body`]).
    #[inline(always)]
    // `&` on booleans on purpose: no branch per condition.
    #[allow(clippy::needless_bitwise_bool)]
    pub(super) fn dense_block<const SELECT: bool>(
        &mut self,
        stk: &mut [Reversal],
        xc: &[f64],
        d: &mut Dense,
    ) -> usize {
        self.load_branch(stk); // the top's force may have been resolved since
        let (start, inv_lam, h_before) = (self.start, self.inv_lam, self.h_before);
        // Global index of the sample before block position 0.
        let before = start.wrapping_sub(1);
        let kh = &mut d.kh;
        kh[BLOCK] = h_before;
        kh[VIRGIN_SLOT as usize] = 0.0;
        let (mut n, mut xp, mut up) = (self.n, self.xp, self.dir > 0.0);
        let (mut ta, mut tb) = top_two(n, stk);
        // The last sample's record (a zero-length step repeats it).
        let mut ul = (self.xp - self.xa) * self.inv;
        let mut j = self.slot(stk, 0, kh);
        // The force of the first sample's candidate (the sample before the block).
        stk[self.n].h = h_before;
        let m = xc.len().min(BLOCK);
        let (xc, u, sl) = (&xc[..m], &mut d.u[..m], &mut d.slot[..m]);
        let mut p = 0_usize;
        // The common steps run in an inner loop that leaves for any other: its registers are
        // then not shared with the general rules'.
        while p < m {
            while p < m {
                let xi = xc[p];
                let dx = xi - xp;
                if (dx == 0.0) | (n < 2) {
                    break;
                }
                let rising = dx > 0.0;
                let rev = rising != up;
                // Candidate reversal: the previous sample. Its force is deferred for p > 0
                // (the placeholder is never read: the index names the in-block sample, and
                // `end_block` writes the force), so only the input and the index are
                // written; for p = 0 the force `h_before` was written at the block's start.
                let cand = &mut stk[n];
                (cand.x, cand.index) = (xp, before.wrapping_add(p as u64));
                // in 2..stk.len()
                let n1 = n.wrapping_add(usize::from(rev));
                // The target stk[n1 - 2].x: the top's input after a reversal, else the one
                // below (selected from the registers, or loaded: see `dense_pass`).
                let t = if SELECT {
                    pickf(rev, ta, tb)
                } else {
                    stk[n1.wrapping_sub(2)].x
                };
                // (x - target) · s >= 0 with s the direction of the step (exact: s = ±1)
                let s = 1.0_f64.copysign(dx);
                if (xi - t) * s >= 0.0 {
                    if n1 < 4 {
                        break;
                    }
                    let n2 = n1.wrapping_sub(2); // >= 2
                    let below = stk[n2.wrapping_sub(2)].x;
                    if (xi - below) * s >= 0.0 {
                        break;
                    }
                    let top = stk[n2.wrapping_sub(1)];
                    (n, up, xp) = (n2, rising, xi);
                    (ta, tb) = (top.x, below);
                    ul = (xi - top.x) * inv_lam;
                    j = known_slot(top, before, p, kh);
                    (u[p], sl[p]) = (ul, j);
                    p = p.wrapping_add(1);
                    continue;
                }
                // No closure: after a reversal the candidate (the previous sample, whose
                // output is slot BLOCK + p) is the top, and the old top's input the target.
                n = n1;
                tb = t;
                ta = pickf(rev, xp, ta);
                j = pick(rev, BLOCK.wrapping_add(p) as u64, u64::from(j)) as u32;
                up = rising;
                xp = xi;
                ul = (xi - ta) * inv_lam;
                (u[p], sl[p]) = (ul, j);
                p = p.wrapping_add(1);
            }
            if p >= m {
                break;
            }
            // A step the inner loop left: a zero-length step (changes nothing), a stack of
            // fewer than two reversals (the virgin curve, or the first reversal's branch whose
            // target is a mirror point) or a closure down to it (the general rules), or a
            // step that closes two loops or more (a large jump). All rare where the input
            // reverses often.
            let xi = xc[p];
            if xi != xp {
                let mut q = Pass {
                    n,
                    xp,
                    dir: if up { 1.0 } else { -1.0 },
                    ..*self
                };
                q.load_branch(stk);
                q.rules(stk, xi, p);
                (n, xp, up) = (q.n, q.xp, q.dir > 0.0);
                ul = (q.xp - q.xa) * q.inv;
                j = q.slot(stk, p, kh);
                (ta, tb) = top_two(n, stk);
            }
            (u[p], sl[p]) = (ul, j);
            p = p.wrapping_add(1);
        }
        (self.n, self.xp, self.dir) = (n, xp, if up { 1.0 } else { -1.0 });
        self.load_branch(stk);
        // The branch changes: where the slot changes (a reversal or a closure always gives a
        // new one), counted after the loop (a counter in it is one register too many).
        sl.windows(2)
            .fold(0_usize, |c, w| c.wrapping_add(usize::from(w[0] != w[1])))
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
    pub(super) fn end_block(&mut self, stk: &mut [Reversal], out: &[f64]) {
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
