//! The window's detrending: [`detrend_pair`] and [`detrend_pair_into`] remove the linear
//! drifts of `F` and `x`; [`detrend_pair_scan_into`] does so and, in the same pass, finds the
//! fold's checks and scales ([`WindowScan`]) and the order statistics of the detrended `x`.

use super::force_centre;
use crate::error::{check_same_len, CoreError};
use crate::select::{TailGather, GATHER_BLOCK, STRIDE};

/// Samples a block of [`detrend_pair_scan_into`]'s pass (a multiple of [`GATHER_BLOCK`]).
const SCAN_BLOCK: usize = 16 * GATHER_BLOCK;

/// `F - s_F·(t - tm)` and `x - s_x·(t - tm)` (the window's linear drifts removed), one
/// vectorised pass a channel, with numpy's operations in numpy's order (`v + (t - tm)·(-s)`,
/// bit for bit that of the expression `v - s·(t - tm)`).
pub fn detrend_pair(
    t: &[f64],
    tm: f64,
    (f, s_f): (&[f64], f64),
    (x, s_x): (&[f64], f64),
) -> Result<(Vec<f64>, Vec<f64>), CoreError> {
    let mut out_f = vec![0.0; f.len()];
    let mut out_x = vec![0.0; x.len()];
    detrend_pair_into(t, tm, (f, s_f), (x, s_x), (&mut out_f, &mut out_x))?;
    Ok((out_f, out_x))
}

/// [`detrend_pair`] into the caller's buffers (the Python binding's numpy arrays: a fresh
/// `Vec` of a window's length cost a page fault every 4 KiB, 5 ms of system time a window,
/// where numpy's allocator asks for huge pages).
pub fn detrend_pair_into(
    t: &[f64],
    tm: f64,
    (f, s_f): (&[f64], f64),
    (x, s_x): (&[f64], f64),
    (out_f, out_x): (&mut [f64], &mut [f64]),
) -> Result<(), CoreError> {
    check_same_len("t", t.len(), "F", f.len())?;
    check_same_len("t", t.len(), "x", x.len())?;
    check_same_len("t", t.len(), "out_F", out_f.len())?;
    check_same_len("t", t.len(), "out_x", out_x.len())?;
    for (out, v, neg) in [(out_f, f, -s_f), (out_x, x, -s_x)] {
        for ((o, &ti), &vi) in out.iter_mut().zip(t).zip(v) {
            *o = vi + (ti - tm) * neg;
        }
    }
    Ok(())
}

/// What [`detrend_pair_scan_into`] found of the samples it made: whether `t` is finite and
/// strictly increasing and the detrended `x` and `F` finite (`clean`), the largest `|x|` and
/// `|F|`, the centre of the scaled force (the numbers [`fold_window`](super::fold_window)'s check pass finds:
/// the same lanes and order of additions), and the order statistics of the detrended `x` at
/// the ranks asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowScan {
    pub n: usize,
    pub clean: bool,
    pub max_abs_x: f64,
    pub max_abs_f: f64,
    pub force_centre: f64,
    pub order_stats: Vec<f64>,
}

/// [`detrend_pair_into`] and, in the same pass over the samples, what the window's next two
/// passes over the detrended samples would read them for: the order statistics of `x` at
/// `ranks` ([`crate::select::order_stats`]'s: the subsample's detrended values computed
/// first, the tails gathered from each block as it is written; the robust amplitude of the
/// reversal search) and the fold's checks and scales ([`WindowScan`], for
/// [`fold_window_scanned`](super::fold_window_scanned)). The detrended samples are bit for bit [`detrend_pair_into`]'s,
/// the order statistics those of [`crate::select::order_stats`] of them (exact), the scan's
/// numbers those of [`fold_window`](super::fold_window)'s check. An empty `ranks` gathers nothing.
///
/// # Errors
/// As [`detrend_pair_into`]; a rank not below the samples' number as
/// [`crate::select::order_stats`].
// Index arithmetic: a + k < b <= n inside the blocks; k < 4.
#[allow(clippy::arithmetic_side_effects, clippy::needless_bitwise_bool)]
pub fn detrend_pair_scan_into(
    t: &[f64],
    tm: f64,
    (f, s_f): (&[f64], f64),
    (x, s_x): (&[f64], f64),
    (out_f, out_x): (&mut [f64], &mut [f64]),
    ranks: &[usize],
) -> Result<WindowScan, CoreError> {
    detrend_pair_scan_at(
        crate::simd::level(),
        t,
        tm,
        (f, s_f),
        (x, s_x),
        (out_f, out_x),
        ranks,
    )
}

/// [`detrend_pair_scan_into`] with its pass compiled for `level` ([`crate::simd`]): the
/// same numbers at every level (the tests compare them).
#[doc(hidden)]
#[allow(clippy::arithmetic_side_effects)]
pub fn detrend_pair_scan_at(
    level: crate::simd::Level,
    t: &[f64],
    tm: f64,
    (f, s_f): (&[f64], f64),
    (x, s_x): (&[f64], f64),
    (out_f, out_x): (&mut [f64], &mut [f64]),
    ranks: &[usize],
) -> Result<WindowScan, CoreError> {
    check_same_len("t", t.len(), "F", f.len())?;
    scan_with(
        level,
        Axis::Samples(t),
        tm,
        (f, s_f),
        (x, s_x),
        (out_f, out_x),
        ranks,
    )
}

/// [`detrend_pair_scan_into`] of a window whose time axis is sampled every `dt` from `t0`:
/// sample `i` at `t0 + dt · (offset + i)`, [`crate::stream::fill_time`]'s axis bit for bit,
/// made as the pass goes instead of read (a streamed recording's windows: 8 of the 40 bytes a
/// sample the pass moves). The same numbers as [`detrend_pair_scan_into`] of that axis, and
/// the same checks of it (an axis that overflows or stops increasing is not clean).
///
/// # Errors
/// As [`detrend_pair_scan_into`]; [`CoreError::TooLong`] when `offset` plus the samples
/// pass 2^53 (as [`crate::stream::fill_time`]).
pub fn detrend_pair_scan_uniform_into(
    (t0, dt, offset): (f64, f64, u64),
    tm: f64,
    (f, s_f): (&[f64], f64),
    (x, s_x): (&[f64], f64),
    (out_f, out_x): (&mut [f64], &mut [f64]),
    ranks: &[usize],
) -> Result<WindowScan, CoreError> {
    detrend_pair_scan_uniform_at(
        crate::simd::level(),
        (t0, dt, offset),
        tm,
        (f, s_f),
        (x, s_x),
        (out_f, out_x),
        ranks,
    )
}

/// [`detrend_pair_scan_uniform_into`] with its pass compiled for `level`.
#[doc(hidden)]
pub fn detrend_pair_scan_uniform_at(
    level: crate::simd::Level,
    (t0, dt, offset): (f64, f64, u64),
    tm: f64,
    (f, s_f): (&[f64], f64),
    (x, s_x): (&[f64], f64),
    (out_f, out_x): (&mut [f64], &mut [f64]),
    ranks: &[usize],
) -> Result<WindowScan, CoreError> {
    if !crate::stream::indices_exact(offset, f.len()) {
        return Err(CoreError::TooLong { len: f.len() });
    }
    scan_with(
        level,
        Axis::Uniform(t0, dt, offset),
        tm,
        (f, s_f),
        (x, s_x),
        (out_f, out_x),
        ranks,
    )
}

/// The time axis of [`ScanPass`]: the samples, or `t0 + dt · (offset + i)` (indices exact,
/// checked by the caller), made block by block as [`crate::stream::fill_time`] makes it.
#[derive(Clone, Copy)]
enum Axis<'a> {
    Samples(&'a [f64]),
    Uniform(f64, f64, u64),
}

impl Axis<'_> {
    #[inline(always)]
    fn at(&self, i: usize) -> f64 {
        match *self {
            Axis::Samples(t) => t[i],
            Axis::Uniform(t0, dt, offset) => crate::stream::time_at(t0, dt, offset, i),
        }
    }
}

/// [`detrend_pair_scan_at`] on either axis (`f`'s length is the samples').
#[allow(clippy::arithmetic_side_effects)]
fn scan_with(
    level: crate::simd::Level,
    t: Axis<'_>,
    tm: f64,
    (f, s_f): (&[f64], f64),
    (x, s_x): (&[f64], f64),
    (out_f, out_x): (&mut [f64], &mut [f64]),
    ranks: &[usize],
) -> Result<WindowScan, CoreError> {
    check_same_len("t", f.len(), "x", x.len())?;
    check_same_len("t", f.len(), "out_F", out_f.len())?;
    check_same_len("t", f.len(), "out_x", out_x.len())?;
    let n = f.len();
    let (nf, nx) = (-s_f, -s_x);
    let mut gather = if ranks.is_empty() || n == 0 {
        None
    } else {
        // a sparser subsample than order_stats' (its samples are cache misses here, where
        // order_stats' were just written): thresholds a little less sharp, values the same
        Some(TailGather::new(n, ranks, 4 * STRIDE, |i| {
            x[i] + (t.at(i) - tm) * nx
        })?)
    };
    let (mx, mf, sum_f, z, zt, dmin) = crate::simd::run(
        level,
        ScanPass {
            t,
            tm,
            inputs: (f, nf, x, nx),
            outputs: (out_f, out_x),
            gather: gather.as_mut(),
        },
    );
    // t: finite (its first sample too) and strictly increasing (a NaN step fails `> 0`)
    let t_ok = n >= 2
        && t.at(0).is_finite()
        && zt.iter().all(|&v| v == 0.0)
        && dmin.iter().all(|&d| d > 0.0);
    let ok = [z.iter().all(|&v| v == 0.0); 1];
    let big = |m: [f64; W]| m.iter().fold(0.0_f64, |a, &b| if b > a { b } else { a });
    let (sx, sf) = (big(mx), big(mf));
    let sum = (sum_f[0] + sum_f[1]) + (sum_f[2] + sum_f[3]);
    let clean = t_ok && ok[0];
    let order_stats = match gather {
        Some(g) => g.finish(out_x),
        None => Vec::new(),
    };
    Ok(WindowScan {
        n,
        clean,
        max_abs_x: sx,
        max_abs_f: sf,
        force_centre: force_centre(out_f, sum, sf),
        order_stats,
    })
}

/// The lanes [`ScanPass`] hands back: the largest `|x|`, `|F|`, the sum of F, `Σ (x, F)·0`,
/// `Σ t·0`, the smallest step of t.
type ScanLanes = ([f64; W], [f64; W], [f64; 4], [f64; W], [f64; W], [f64; W]);

/// Lanes of [`ScanPass`]'s order-free scans (maxima, minimum, zero tests).
const W: usize = 8;

/// [`detrend_pair_scan_at`]'s pass over the samples as a [`crate::simd::Kernel`] (compiled
/// for each level: in the baseline build the detrending and the scans ran two lanes wide,
/// 1.6 ns a sample in cache).
struct ScanPass<'a> {
    t: Axis<'a>,
    tm: f64,
    inputs: (&'a [f64], f64, &'a [f64], f64),
    outputs: (&'a mut [f64], &'a mut [f64]),
    gather: Option<&'a mut TailGather>,
}

impl crate::simd::Kernel for ScanPass<'_> {
    type Output = ScanLanes;

    // Index arithmetic: a + k < b <= n inside the blocks; l < 8.
    #[allow(clippy::arithmetic_side_effects)]
    #[inline(always)]
    fn run_at(self) -> ScanLanes {
        let ScanPass {
            t,
            tm,
            inputs: (f, nf, x, nx),
            outputs: (out_f, out_x),
            mut gather,
        } = self;
        let n = f.len();
        // a sampled axis's block (and the sample before it), made here: in L2, not read
        let mut made = match t {
            Axis::Samples(_) => Vec::new(),
            Axis::Uniform(..) => vec![0.0_f64; SCAN_BLOCK.min(n) + 1],
        };
        let (mut mx, mut mf, mut sum_f) = ([0.0_f64; W], [0.0_f64; W], [0.0_f64; 4]);
        // Σ v·0 of x, F and t: ±0 while every value is finite, NaN from an inf or a NaN on (a
        // vectorised finiteness check, where a lane of booleans was not); the smallest step of t
        let (mut z, mut zt, mut dmin) = ([0.0_f64; W], [0.0_f64; W], [f64::INFINITY; W]);
        let mut a = 0_usize;
        while a < n {
            // blocks that stay in L2 for the passes over what was just written, long enough for
            // the prefetchers' streams (blocks of GATHER_BLOCK were 2.5x slower)
            let b = (a + SCAN_BLOCK).min(n);
            // t from the sample before the block (none before the first) to its end
            let lo = a.saturating_sub(1);
            let tp: &[f64] = match t {
                Axis::Samples(t) => &t[lo..b],
                Axis::Uniform(t0, dt, offset) => {
                    let buf = &mut made[..b - lo];
                    crate::stream::fill_time_in(buf, t0, dt, offset + lo as u64);
                    buf
                }
            };
            let tb = &tp[a - lo..];
            let (fb, xb) = (&f[a..b], &x[a..b]);
            let (ofb, oxb) = (&mut out_f[a..b], &mut out_x[a..b]);
            // the detrended samples and, as they are made (in registers, not read back),
            // finite_max_abs's numbers: the maxima and the zero test in eight lanes (order
            // free), the sum of F in its four lanes (sample i in lane i mod 4, in order:
            // blocks start at multiples of 8). Each sample is `v + (t - tm)·(-s)`, as
            // detrend_pair_into makes it.
            {
                let mut qf_it = ofb.chunks_exact_mut(W);
                let mut qx_it = oxb.chunks_exact_mut(W);
                let mut tt_it = tb.chunks_exact(W);
                let mut ff_it = fb.chunks_exact(W);
                let mut xx_it = xb.chunks_exact(W);
                for ((((qf, qx), tt), ff), xx) in (&mut qf_it)
                    .zip(&mut qx_it)
                    .zip(&mut tt_it)
                    .zip(&mut ff_it)
                    .zip(&mut xx_it)
                {
                    let (mut vf, mut vx) = ([0.0_f64; W], [0.0_f64; W]);
                    for l in 0..W {
                        let d = tt[l] - tm;
                        vf[l] = ff[l] + d * nf;
                        vx[l] = xx[l] + d * nx;
                    }
                    qf.copy_from_slice(&vf);
                    qx.copy_from_slice(&vx);
                    for l in 0..W {
                        let (ax, af) = (vx[l].abs(), vf[l].abs());
                        mx[l] = if ax > mx[l] { ax } else { mx[l] };
                        mf[l] = if af > mf[l] { af } else { mf[l] };
                        z[l] += vx[l] * 0.0 + vf[l] * 0.0;
                    }
                    for l in 0..4 {
                        sum_f[l] += vf[l];
                    }
                    for l in 0..4 {
                        sum_f[l] += vf[l + 4];
                    }
                }
                let rest = qf_it
                    .into_remainder()
                    .iter_mut()
                    .zip(qx_it.into_remainder())
                    .zip(tt_it.remainder())
                    .zip(ff_it.remainder())
                    .zip(xx_it.remainder());
                for (l, ((((of, ox), &ti), &fi), &xi)) in rest.enumerate() {
                    let d = ti - tm;
                    let (vf, vx) = (fi + d * nf, xi + d * nx);
                    *of = vf;
                    *ox = vx;
                    let (ax, af) = (vx.abs(), vf.abs());
                    mx[l] = if ax > mx[l] { ax } else { mx[l] };
                    mf[l] = if af > mf[l] { af } else { mf[l] };
                    sum_f[l % 4] += vf;
                    z[l] += vx * 0.0 + vf * 0.0;
                }
            }
            // the steps of t from the sample before the block (none before the first); eight
            // lanes: a minimum and a zero test do not depend on the order
            let (t0, t1) = (&tp[..tp.len() - 1], &tp[1..]);
            let mut c0 = t0.chunks_exact(W);
            let mut c1 = t1.chunks_exact(W);
            for (p, q) in (&mut c0).zip(&mut c1) {
                for l in 0..W {
                    let d = q[l] - p[l];
                    dmin[l] = if d < dmin[l] { d } else { dmin[l] };
                    zt[l] += q[l] * 0.0;
                }
            }
            for (l, (&p, &q)) in c0.remainder().iter().zip(c1.remainder()).enumerate() {
                let d = q - p;
                dmin[l] = if d < dmin[l] { d } else { dmin[l] };
                zt[l] += q * 0.0;
            }
            if let Some(g) = gather.as_mut() {
                for blk in oxb.chunks(GATHER_BLOCK) {
                    g.block(blk);
                }
            }
            a = b;
        }
        (mx, mf, sum_f, z, zt, dmin)
    }
}
