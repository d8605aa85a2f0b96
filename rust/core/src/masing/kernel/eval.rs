//! The curve passes of the kernel: [`eval_block`] (a block of runs) and [`eval_dense`] (a
//! dense block), each compiled for every SIMD level, and the gather tables they use.

use super::{pick, Dense, Run, BLOCK, KH, KNOWN, VIRGIN_SLOT};
use crate::curve::Backbone;
use crate::simd::{self, Kernel, Level};

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
pub(in crate::masing) struct RunTab {
    ha: [f64; RUNS],
    mul: [f64; RUNS],
}

impl RunTab {
    pub(in crate::masing) fn new() -> Box<Self> {
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
pub(in crate::masing) fn eval_block<C: Backbone>(
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
    lam: f64,
    out: &'a mut [f64],
}

impl<C: Backbone> Kernel for EvalDense<'_, C> {
    type Output = bool;
    #[inline(always)]
    fn run_at(self) -> bool {
        eval_dense_body(self.curve, self.d, self.lam, self.out)
    }
}

/// Curve pass of a dense block (see [`eval_dense_body`]) compiled for SIMD level `level`
/// (bit for bit the same at every level). Returns whether every force is finite.
#[inline(never)]
pub(super) fn eval_dense<C: Backbone>(
    level: Level,
    curve: &C,
    d: &mut Dense,
    lam: f64,
    out: &mut [f64],
) -> bool {
    simd::run(level, EvalDense { curve, d, lam, out })
}

/// Curve pass of a dense block: `out[p] = f(u[p])` over the block (vectorised), then in
/// order `out[p] = kh[slot[p]] + mul · out[p]`, writing the result to `kh[BLOCK + 1 + p]`
/// (the base of the samples anchored at sample `p`), with `mul` 1 on the virgin curve and
/// `lam` elsewhere (no data-dependent branch; a block with no sample on the virgin curve
/// takes a loop with `mul = lam`).
#[inline(always)]
fn eval_dense_body<C: Backbone>(curve: &C, d: &mut Dense, lam: f64, out: &mut [f64]) -> bool {
    let m = out.len().min(BLOCK);
    let out = &mut out[..m];
    for (o, &v) in out.iter_mut().zip(&d.u[..m]) {
        *o = curve.eval(v);
    }
    let slot = &d.slot[..m];
    let virgin = VIRGIN_SLOT as usize;
    // Whether a sample is on the virgin curve (rare: before the first reversal or after a
    // rejoin): one vectorised test, which spares the common loop the select of the multiplier.
    if slot
        .iter()
        .fold(0_u32, |any, &j| any | u32::from(j == VIRGIN_SLOT))
        != 0
    {
        for (p, (o, &j)) in out.iter_mut().zip(slot).enumerate() {
            let j = j as usize;
            let mul = f64::from_bits(pick(j == virgin, 1.0_f64.to_bits(), lam.to_bits()));
            let v = d.kh[j & (KH - 1)] + mul * *o;
            d.kh[BLOCK.wrapping_add(1).wrapping_add(p) & (KH - 1)] = v;
            *o = v;
        }
    } else {
        for (p, (o, &j)) in out.iter_mut().zip(slot).enumerate() {
            let v = d.kh[j as usize & (KH - 1)] + lam * *o;
            d.kh[BLOCK.wrapping_add(1).wrapping_add(p) & (KH - 1)] = v;
            *o = v;
        }
    }
    out.iter().fold(true, |ok, o| ok & o.is_finite())
}
