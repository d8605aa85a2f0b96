//! Order statistics (the k-th smallest values) of a long sample near its ends, without
//! partitioning all of it: the robust amplitude of a displacement (its 0.5 and 99.5
//! percentiles, `contactlab.tangential.preprocess.tail_percentiles`) needs four values of a
//! window of a million samples.
//!
//! A strided subsample's order statistics give two thresholds; one pass gathers the samples
//! at or below the low one and at or above the high one (about 2 % of them each), and the
//! ranks are selected in those tails. The values are those a sort of the whole sample gives
//! (exact: an order statistic is one of the samples); where a tail turns out too short for a
//! rank (a subsample that misjudges the distribution), the whole sample is selected from.

use crate::error::CoreError;

/// Below this many samples the whole sample is selected from (no subsample).
const SUBSAMPLE_ABOVE: usize = 1 << 15;
/// Every this many samples one goes into the subsample.
pub const STRIDE: usize = 32;
/// Samples a block of the tails' gathering.
const GATHER: usize = 2048;
/// Samples a run of the gathering's prefilter (skipped when none is in a tail).
const PREFILTER: usize = 16;

/// The `rank`-th smallest value of `v` for each of `ranks` (ascending), selected in place.
fn select_into(v: &mut [f64], ranks: &[usize], offset: usize, out: &mut [f64]) {
    for (&r, o) in ranks.iter().zip(out.iter_mut()) {
        let k = r.saturating_sub(offset);
        if k < v.len() {
            let (_, m, _) = v.select_nth_unstable_by(k, f64::total_cmp);
            *o = *m;
        }
    }
}

/// The values of rank `ranks` (0-based: rank 0 is the smallest) of `x`, exactly those of a
/// sort of `x` (by value: `-0.0` and `0.0` are one value, the one returned either). `x`
/// finite (the caller's check; a NaN only makes the numbers meaningless).
///
/// # Errors
/// [`CoreError::Empty`] for an empty `x`, [`CoreError::InvalidParameter`] for a rank not
/// below `x.len()`.
pub fn order_stats(x: &[f64], ranks: &[usize]) -> Result<Vec<f64>, CoreError> {
    let mut g = TailGather::new(x.len(), ranks, STRIDE, |i| x[i])?;
    if g.gathering() {
        // the gathering pass compiled for the CPU's SIMD level (the same tails on every one)
        crate::simd::run(crate::simd::level(), GatherPass { x, gather: &mut g });
    }
    Ok(g.finish(x))
}

/// The gathering pass of [`order_stats`] as a [`crate::simd::Kernel`] (compiled for the
/// CPU's SIMD level: the same tails on every one).
struct GatherPass<'a> {
    x: &'a [f64],
    gather: &'a mut TailGather,
}

impl crate::simd::Kernel for GatherPass<'_> {
    type Output = ();

    #[inline(always)]
    fn run_at(self) {
        for block in self.x.chunks(GATHER) {
            self.gather.block(block);
        }
    }
}

/// [`order_stats`] split into its steps, so that another kernel's pass over the samples can
/// gather the tails as it makes them (the detrended displacement of an analysis window:
/// [`crate::window::detrend_pair_scan_into`]): [`TailGather::new`] takes the subsample's
/// thresholds, [`TailGather::block`] gathers the tails of consecutive blocks of at most
/// [`GATHER`] samples, [`TailGather::finish`] selects the ranks (from the whole sample where
/// a tail is too short or the sample too short for a subsample). The values are those of
/// [`order_stats`]: exact order statistics, whichever way they are found.
pub struct TailGather {
    n: usize,
    /// positions of the ranks in ascending order, and the ranks so sorted
    order: Vec<usize>,
    sorted: Vec<usize>,
    /// the sorted ranks below `n / 2`
    n_low: usize,
    /// None: no subsample (select from the whole sample)
    thresholds: Option<(f64, f64)>,
    lv: Vec<f64>,
    hv: Vec<f64>,
    nl: usize,
    nh: usize,
}

/// Samples a block of [`TailGather::block`] at most.
pub const GATHER_BLOCK: usize = GATHER;

impl TailGather {
    /// The gathering of `ranks` of `n` samples, `sample(i)` the `i`-th (read at the
    /// subsample's positions only: every `stride`-th sample, [`STRIDE`] in [`order_stats`]).
    /// The stride sets only how well the thresholds are guessed, not the values: a tail
    /// found too short is selected from the whole sample.
    ///
    /// # Errors
    /// As [`order_stats`].
    // Index arithmetic: ranks < n (checked), sub ranks < sub.len(), counts <= n.
    #[allow(clippy::arithmetic_side_effects)]
    pub fn new(
        n: usize,
        ranks: &[usize],
        stride: usize,
        sample: impl Fn(usize) -> f64,
    ) -> Result<Self, CoreError> {
        if n == 0 {
            return Err(CoreError::Empty { name: "x" });
        }
        if let Some(&r) = ranks.iter().find(|&&r| r >= n) {
            return Err(CoreError::InvalidParameter {
                name: "rank",
                value: r as f64,
                reason: "must be below the number of samples",
            });
        }
        let mut order: Vec<usize> = (0..ranks.len()).collect();
        order.sort_by_key(|&i| ranks[i]);
        let sorted: Vec<usize> = order.iter().map(|&i| ranks[i]).collect();
        let half = n / 2;
        let n_low = sorted.iter().filter(|&&r| r < half).count();
        let thresholds = if n > SUBSAMPLE_ABOVE {
            let (low, high) = sorted.split_at(n_low);
            let mut sub: Vec<f64> = (0..n).step_by(stride.max(1)).map(sample).collect();
            let m = sub.len();
            // a subsample rank whose value has about twice the samples the rank needs below
            // it (and 16 subsample values more): a tail short of the rank is rare, and then
            // only slower
            let sub_rank = |r: usize| (2 * (r + 2) * m / n + 16).min(m - 1);
            let t_lo = low.last().map(|&r| {
                let k = sub_rank(r);
                *sub.select_nth_unstable_by(k, f64::total_cmp).1
            });
            let t_hi = high.first().map(|&r| {
                let k = m - 1 - sub_rank(n - 1 - r);
                *sub.select_nth_unstable_by(k, f64::total_cmp).1
            });
            Some((
                t_lo.unwrap_or(f64::NEG_INFINITY),
                t_hi.unwrap_or(f64::INFINITY),
            ))
        } else {
            None
        };
        Ok(TailGather {
            n,
            order,
            sorted,
            n_low,
            thresholds,
            lv: Vec::new(),
            hv: Vec::new(),
            nl: 0,
            nh: 0,
        })
    }

    /// Whether the samples' blocks are to be gathered (false: the whole sample is selected
    /// from at [`TailGather::finish`]).
    pub fn gathering(&self) -> bool {
        self.thresholds.is_some()
    }

    /// The next block of at most [`GATHER_BLOCK`] samples (in order).
    // Index arithmetic: the buffers grow a block ahead; il, ih < GATHER after the mask.
    // Bitwise ors: no early exit, so the prefilter's test vectorises.
    // Inlined whole into its callers' passes, which are compiled for the CPU's SIMD level.
    #[allow(clippy::arithmetic_side_effects, clippy::needless_bitwise_bool)]
    #[inline(always)]
    pub fn block(&mut self, block: &[f64]) {
        let Some((lo, hi)) = self.thresholds else {
            return;
        };
        // the tails by value (every sample at or below lo: the smallest samples of x, ±0
        // together, so a rank of x is the same rank of the low tail; the high tail's ranks
        // are x's less the samples below it). Branch-free: each sample is written at the
        // tail's end, which moves on only when the sample belongs to the tail
        let (nl, nh) = (self.nl, self.nh);
        self.lv.resize(nl + GATHER, 0.0);
        self.hv.resize(nh + GATHER, 0.0);
        let (lb, hb) = (&mut self.lv[nl..nl + GATHER], &mut self.hv[nh..nh + GATHER]);
        let (mut il, mut ih) = (0_usize, 0_usize);
        let blk = &block[..block.len().min(GATHER)];
        // runs of PREFILTER samples none of which is in a tail (most: the tails hold about
        // 2 % of the samples, in runs around the extremes) are skipped after a vectorised
        // test; the others are gathered sample by sample as before (the same tails, in the
        // same order: a skipped sample was never kept). The gather's chain of dependent
        // stores and counts was 2.5 of the 3.6 ns a sample of the detrending pass.
        let mut runs = blk.chunks_exact(PREFILTER);
        for run in &mut runs {
            let hit = run.iter().fold(false, |a, &v| a | (v <= lo) | (v >= hi));
            if hit {
                for &v in run {
                    lb[il & (GATHER - 1)] = v;
                    hb[ih & (GATHER - 1)] = v;
                    il += usize::from(v <= lo);
                    ih += usize::from(v >= hi);
                }
            }
        }
        for &v in runs.remainder() {
            lb[il & (GATHER - 1)] = v;
            hb[ih & (GATHER - 1)] = v;
            il += usize::from(v <= lo);
            ih += usize::from(v >= hi);
        }
        self.nl += il;
        self.nh += ih;
    }

    /// The values of the ranks, in the order given; `x` the whole sample (selected from when
    /// there were no tails, or a tail too short for a rank).
    // Index arithmetic: counts <= n.
    #[allow(clippy::arithmetic_side_effects)]
    pub fn finish(mut self, x: &[f64]) -> Vec<f64> {
        let mut vals = vec![0.0_f64; self.sorted.len()];
        let (low, high) = self.sorted.split_at(self.n_low);
        let mut done = false;
        if self.thresholds.is_some() {
            self.lv.truncate(self.nl);
            self.hv.truncate(self.nh);
            let below_hi = self.n - self.hv.len();
            let short = low.last().is_some_and(|&r| r >= self.lv.len())
                || high.first().is_some_and(|&r| r < below_hi);
            if !short {
                let (v_lo, v_hi) = vals.split_at_mut(low.len());
                select_into(&mut self.lv, low, 0, v_lo);
                select_into(&mut self.hv, high, below_hi, v_hi);
                done = true;
            }
        }
        if !done {
            let mut all = x.to_vec();
            select_into(&mut all, &self.sorted, 0, &mut vals);
        }
        let mut out = vec![0.0_f64; vals.len()];
        for (&i, &v) in self.order.iter().zip(&vals) {
            out[i] = v;
        }
        out
    }
}

/// [`order_stats`] of the ranks `low` (below `n/2`) and `high` (the rest), both ascending,
/// from the tails of `x`, into `vals` (low's then high's); false when a tail is too short.
#[cfg(test)]
fn tails(x: &[f64], low: &[usize], high: &[usize], vals: &mut [f64]) -> bool {
    let ranks: Vec<usize> = low.iter().chain(high).copied().collect();
    let Ok(mut g) = TailGather::new(x.len(), &ranks, STRIDE, |i| x[i]) else {
        return false;
    };
    if g.n_low != low.len() || !g.gathering() {
        return false;
    }
    for block in x.chunks(GATHER) {
        g.block(block);
    }
    g.lv.truncate(g.nl);
    g.hv.truncate(g.nh);
    let below_hi = x.len() - g.hv.len();
    if low.last().is_some_and(|&r| r >= g.lv.len()) || high.first().is_some_and(|&r| r < below_hi) {
        return false;
    }
    let v = g.finish(x);
    vals.copy_from_slice(&v);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sorted(x: &[f64]) -> Vec<f64> {
        let mut s = x.to_vec();
        s.sort_by(f64::total_cmp);
        s
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// The values a sort gives, for ranks near both ends and in the middle, on noisy
        /// sines, heavy tails (a few huge outliers), quantised samples (ties, ±0) and short
        /// samples (no subsample).
        #[test]
        fn equals_a_sort(
            seed in 0u64..100_000, n in prop::sample::select(vec![5usize, 1000, 40_000, 300_000]),
            kind in 0usize..4, fr in prop::collection::vec(0.0f64..1.0, 1..6),
        ) {
            let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(3);
            let mut rnd = move || {
                s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            };
            let x: Vec<f64> = (0..n)
                .map(|i| {
                    let base = (i as f64 * 0.0063).sin() + 0.05 * rnd();
                    match kind {
                        0 => base,
                        1 => if rnd() > 0.499 { 1e6 * rnd() } else { base },
                        2 => (2.0 * base).round(),
                        _ => if i % 7 == 0 { -0.0 } else { (3.0 * rnd()).round() },
                    }
                })
                .collect();
            let srt = sorted(&x);
            // the tails' ranks (0.5 %, 99.5 % and their neighbours) and arbitrary ones
            let mut ranks = vec![0, n / 200, n / 200 + 1, n - 1 - n / 200, n - 1];
            ranks.extend(fr.iter().map(|f| ((n - 1) as f64 * f) as usize));
            let got = order_stats(&x, &ranks).unwrap();
            for (r, g) in ranks.iter().zip(&got) {
                // by value (±0 are one value)
                prop_assert!(*g == srt[*r], "rank {} of {}: {} vs {}", r, n, g, srt[*r]);
            }
        }
    }

    fn xs(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                if i % STRIDE == 0 {
                    i as f64 * 1e-3
                } else {
                    1e3 + i as f64
                }
            })
            .collect()
    }

    #[test]
    fn a_subsample_that_misjudges_falls_back() {
        // the stride's samples all small, the others large: the low threshold is far too
        // low a value for the rank (a tail too short), so the whole sample is selected from
        let n = 100_000;
        assert!(!tails(&xs(n), &[500], &[], &mut [0.0]));
        let x = xs(n);
        let srt = sorted(&x);
        let ranks = [n / 2 - 1, 500, 99_000, 10];
        let got = order_stats(&x, &ranks).unwrap();
        for (r, g) in ranks.iter().zip(&got) {
            assert_eq!(*g, srt[*r]);
        }
        let y: Vec<f64> = x.iter().map(|v| -v).collect();
        assert!(!tails(&y, &[], &[n - 501], &mut [0.0]));
        let got = order_stats(&y, &[3, n - 501]).unwrap();
        assert_eq!(got, vec![-srt[n - 4], -srt[500]]);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(order_stats(&[], &[0]).is_err());
        assert!(order_stats(&[1.0, 2.0], &[2]).is_err());
        assert_eq!(order_stats(&[2.0, 1.0], &[]).unwrap(), Vec::<f64>::new());
        assert_eq!(
            order_stats(&[2.0, 1.0, 3.0], &[1, 0, 2]).unwrap(),
            vec![2.0, 1.0, 3.0]
        );
    }
}
