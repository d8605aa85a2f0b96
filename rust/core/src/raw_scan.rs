//! One pass over an analysis window's raw samples for two of its kernels: the order
//! statistics of the displacement ([`crate::select::order_stats`], its robust amplitude)
//! and the cumulative trapezoid integrals of F and x that the period means between the
//! peaks read ([`crate::fold::period_means_pair`]), kept at every [`CHECKPOINT`]-th sample.
//!
//! The peaks (the period edges) are found from the order statistics, so the period means
//! used to make a pass of their own afterwards: one chain of dependent additions a sample
//! (3 ns a sample of a streamed window, issue 33). The chain does not depend on the edges
//! (it is paused at each edge and resumed with the same numbers), so it runs in the order
//! statistics' pass, whose vectorised tail test leaves the processor room for it, and
//! [`period_means_pair_resumed`] resumes it from the checkpoint below each edge: at most
//! [`CHECKPOINT`] steps an edge. The numbers are those of the two kernels, bit for bit.

use crate::error::{check_same_len, CoreError};
use crate::fold::{period_means_pair, trapezoids_until};
use crate::select::{TailGather, STRIDE};

/// Samples between two checkpoints of the trapezoid integrals.
pub const CHECKPOINT: usize = 64;

/// Pairs of samples a run of the pass's trapezoid terms.
const TERMS: usize = 16;

/// What [`order_stats_trapezoids`] found of `(x, t, F)`.
#[derive(Debug, Clone, PartialEq)]
pub struct RawScan {
    /// The order statistics of x at the ranks asked for (in their order).
    pub order_stats: Vec<f64>,
    /// The samples scanned.
    pub n: usize,
    /// `t` finite and strictly increasing (else no checkpoint is read:
    /// [`period_means_pair_resumed`] runs [`period_means_pair`], which names the fault).
    pub t_ok: bool,
    /// The cumulative trapezoid integrals of F and of x from sample 0 to sample
    /// `k · CHECKPOINT` (k = 0, 1, ... while below `n`).
    pub cf: Vec<f64>,
    pub cx: Vec<f64>,
    /// The time of each checkpoint's sample.
    pub ct: Vec<f64>,
    /// The first and last time of the samples (a check that the resumed walk reads the same
    /// axis).
    pub t_ends: (f64, f64),
}

/// [`order_stats`](crate::select::order_stats) of `x` at `ranks` and, in the same pass, the
/// checkpoints of the period means' trapezoid integrals over `(t, F, x)` (see the module
/// docs). `x` finite (the caller's check, as `order_stats`); `t` is checked as the pass
/// reads it (`t_ok`).
///
/// # Errors
/// As `order_stats`; [`CoreError::LengthMismatch`] for channels of different lengths.
// Index arithmetic: j + 1 < n inside the chain; piece bounds below n.
#[allow(clippy::arithmetic_side_effects, clippy::needless_bitwise_bool)]
pub fn order_stats_trapezoids(
    x: &[f64],
    t: &[f64],
    f: &[f64],
    ranks: &[usize],
) -> Result<RawScan, CoreError> {
    check_same_len("t", t.len(), "x", x.len())?;
    check_same_len("t", t.len(), "F", f.len())?;
    let mut g = TailGather::new(x.len(), ranks, STRIDE, |i| x[i])?;
    let n = x.len();
    let n_cp = (n - 1) / CHECKPOINT + 1;
    let mut cps = Checkpoints {
        t: Vec::with_capacity(n_cp),
        f: Vec::with_capacity(n_cp),
        x: Vec::with_capacity(n_cp),
    };
    let ok = crate::simd::run(
        crate::simd::level(),
        FusedPass {
            txf: (t, x, f),
            gather: &mut g,
            cps: &mut cps,
        },
    );
    Ok(RawScan {
        order_stats: g.finish(x),
        n,
        t_ok: ok,
        cf: cps.f,
        cx: cps.x,
        ct: cps.t,
        t_ends: (t[0], t[n - 1]),
    })
}

/// The checkpoints as the pass makes them: the sample's time and the two integrals.
struct Checkpoints {
    t: Vec<f64>,
    f: Vec<f64>,
    x: Vec<f64>,
}

/// [`order_stats_trapezoids`]' pass as a [`crate::simd::Kernel`] (the gathering's test
/// vectorised for the CPU's SIMD level; the chain is scalar at every level, the same sums).
struct FusedPass<'a> {
    txf: (&'a [f64], &'a [f64], &'a [f64]),
    gather: &'a mut TailGather,
    cps: &'a mut Checkpoints,
}

impl crate::simd::Kernel for FusedPass<'_> {
    /// `t` finite and strictly increasing
    type Output = bool;

    // Index arithmetic: s < e <= n; the pairs (j, j + 1) with j < stop <= n - 1; m <= TERMS.
    #[allow(clippy::arithmetic_side_effects, clippy::needless_bitwise_bool)]
    #[inline(always)]
    fn run_at(self) -> bool {
        let FusedPass {
            txf: (t, x, f),
            gather,
            cps,
        } = self;
        let n = x.len().min(t.len()).min(f.len());
        let mut ok = t[0].is_finite();
        let (mut cf, mut cx) = (0.0_f64, 0.0_f64);
        // a piece's trapezoid terms, made in a loop that vectorises (no chain) before the
        // chain adds them: the chain is then two additions a sample, which the processor
        // runs next to the gathering and the next piece's terms
        let (mut tf, mut tx) = ([0.0_f64; TERMS], [0.0_f64; TERMS]);
        let mut s = 0_usize;
        while s < n {
            let e = (s + CHECKPOINT).min(n);
            gather.block(&x[s..e]);
            cps.t.push(t[s]);
            cps.f.push(cf);
            cps.x.push(cx);
            // the pairs (j, j + 1), j in [s, e) below n - 1, in runs of TERMS: a run's terms,
            // then its chain (a loop body small enough for the processor to run the next
            // runs' terms and gathering while the chain waits on its additions)
            let stop = e.min(n - 1);
            let mut r = s;
            while r < stop {
                let r1 = (r + TERMS).min(stop);
                let m = r1 - r;
                let pairs = t[r..r1]
                    .iter()
                    .zip(&t[r + 1..=r1])
                    .zip(f[r..r1].iter().zip(&f[r + 1..=r1]))
                    .zip(x[r..r1].iter().zip(&x[r + 1..=r1]));
                let mut good = true;
                for ((of, ox), (((&t0, &t1), (&f0, &f1)), (&x0, &x1))) in
                    tf[..m].iter_mut().zip(tx[..m].iter_mut()).zip(pairs)
                {
                    good &= (t1 > t0) & t1.is_finite();
                    let dt = t1 - t0;
                    // period_means_pair's terms, bit for bit: 0.5·(v[j+1] + v[j])·dt
                    *of = 0.5 * (f1 + f0) * dt;
                    *ox = 0.5 * (x1 + x0) * dt;
                }
                ok &= good;
                for (&a, &b) in tf[..m].iter().zip(&tx[..m]) {
                    cf += a;
                    cx += b;
                }
                r = r1;
            }
            s = e;
        }
        ok
    }
}

/// [`period_means_pair`] of `(t, F, x)` between `edges`, the trapezoid integrals resumed
/// from `scan`'s checkpoints (`scan`: [`order_stats_trapezoids`] of these very samples):
/// the same numbers, bit for bit. Where the scan found `t` not finite and increasing, or
/// does not match the samples, or the edges are not finite and non-decreasing, this is
/// [`period_means_pair`] itself (its errors name the fault).
///
/// # Errors
/// As [`period_means_pair`].
// Index arithmetic: k below the checkpoints' length, k · CHECKPOINT < n; j + 1 < n where
// read.
#[allow(clippy::arithmetic_side_effects)]
pub fn period_means_pair_resumed(
    t: &[f64],
    f: &[f64],
    x: &[f64],
    edges: &[f64],
    scan: &RawScan,
) -> Result<(Vec<f64>, Vec<f64>), CoreError> {
    let n = t.len();
    let fits = scan.t_ok
        && n >= 2
        && f.len() == n
        && x.len() == n
        && scan.n == n
        && scan.cf.len() == (n - 1) / CHECKPOINT + 1
        && scan.cx.len() == scan.cf.len()
        && scan.ct.len() == scan.cf.len()
        && scan.t_ends == (t[0], t[n - 1])
        && edges.iter().all(|e| e.is_finite())
        && edges.windows(2).all(|w| w[1] >= w[0]);
    if !fits {
        return period_means_pair(t, f, x, edges);
    }
    let mut ce_f = Vec::with_capacity(edges.len());
    let mut ce_x = Vec::with_capacity(edges.len());
    // the walk's state (sample j and the integrals to it), as period_means_pair's, and the
    // last checkpoint at or before the edge (found in the checkpoints' own times: a read
    // of the axis at every edge missed the cache)
    let (mut j, mut cf, mut cx) = (0_usize, 0.0_f64, 0.0_f64);
    let mut k = 0_usize;
    let ct = &scan.ct;
    for &e in edges {
        if e <= t[0] {
            ce_f.push(0.0);
            ce_x.push(0.0);
            continue;
        }
        while k + 1 < ct.len() && ct[k + 1] <= e {
            k += 1;
        }
        if k * CHECKPOINT > j {
            (j, cf, cx) = (k * CHECKPOINT, scan.cf[k], scan.cx[k]);
        }
        (j, cf, cx) = trapezoids_until(t, (f, x), j, e, (cf, cx));
        if j + 1 >= n || e == t[j] {
            ce_f.push(cf);
            ce_x.push(cx);
        } else {
            let dt = t[j + 1] - t[j];
            let c1f = cf + 0.5 * (f[j + 1] + f[j]) * dt;
            let c1x = cx + 0.5 * (x[j + 1] + x[j]) * dt;
            ce_f.push((c1f - cf) / dt * (e - t[j]) + cf);
            ce_x.push((c1x - cx) / dt * (e - t[j]) + cx);
        }
    }
    let means = |ce: &[f64]| -> Vec<f64> {
        ce.windows(2)
            .zip(edges.windows(2))
            .map(|(c, e)| (c[1] - c[0]) / (e[1] - e[0]))
            .collect()
    };
    Ok((means(&ce_f), means(&ce_x)))
}

#[cfg(test)]
mod tests;
