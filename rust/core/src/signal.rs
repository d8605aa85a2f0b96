//! Reversal detection by a hysteresis (Schmitt) threshold, streaming.
//!
//! A signal counts as having turned only after it has crossed a band of half-width
//! `threshold` around `centre` (ASTM E1049-85 §5.4.4 calls this the "gate" of peak counting):
//! noise smaller than the band never creates a reversal. The detector reports *excursions*:
//! stretches from the sample where the signal leaves the band on one side to the sample where
//! it next leaves it on the other side. Each carries the index of its extreme, so callers
//! derive peaks, valleys and cycle boundaries without a per-sample loop of their own.
//!
//! The state carries over between chunks: pushing a recording in pieces gives the same
//! excursions as one pass.

use crate::error::{check_finite, check_same_len, CoreError};

/// One excursion beyond the band: `sign = +1` above `centre + threshold`, `-1` below
/// `centre - threshold`. Indices are global sample indices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Excursion {
    pub sign: i8,
    /// First sample beyond the level (where the excursion starts).
    pub start: u64,
    /// Sample of the extreme of the value signal in `[start, next start)` (first occurrence).
    pub extreme: u64,
    pub extreme_value: f64,
    /// Last sample of the excursion still beyond its level.
    pub last_beyond: u64,
    /// The trigger signal crossed the centre after the extreme (always true once the next
    /// excursion has started; for the open one it says whether the turn is confirmed).
    pub returned: bool,
}

/// Streaming hysteresis-threshold reversal detector.
#[derive(Debug, Clone, PartialEq)]
pub struct Schmitt {
    pub centre: f64,
    pub threshold: f64,
    /// Samples processed so far.
    pub count: u64,
    /// The excursion in progress (none before the signal first leaves the band).
    pub open: Option<Excursion>,
}

impl Schmitt {
    pub fn new(centre: f64, threshold: f64) -> Result<Self, CoreError> {
        if !centre.is_finite() {
            return Err(CoreError::InvalidParameter {
                name: "centre",
                value: centre,
                reason: "must be finite",
            });
        }
        crate::error::check_positive("threshold", threshold)?;
        Ok(Self {
            centre,
            threshold,
            count: 0,
            open: None,
        })
    }

    /// Feed `trigger` (the thresholded signal) and optionally `value` (whose extremes are
    /// located; default `trigger`); append every excursion completed in this chunk to `done`.
    /// On error nothing changes.
    pub fn push(
        &mut self,
        trigger: &[f64],
        value: Option<&[f64]>,
        done: &mut Vec<Excursion>,
    ) -> Result<(), CoreError> {
        check_finite("x", trigger)?;
        if let Some(v) = value {
            // (the trigger itself, checked above, when no separate value is given)
            check_same_len("x", trigger.len(), "value", v.len())?;
            check_finite("value", v)?;
        }
        let value = value.unwrap_or(trigger);
        let end = u64::try_from(trigger.len())
            .ok()
            .and_then(|n| self.count.checked_add(n))
            .ok_or(CoreError::TooLong { len: trigger.len() })?;
        let hi = self.centre + self.threshold;
        let lo = self.centre - self.threshold;
        let centre = self.centre;
        // the open excursion in locals (an `Option<Excursion>` matched every sample kept it
        // in memory: 7 ns a sample, against about 2 now); the same decisions as
        // `push_reference` in the tests, sample for sample
        let mut has = self.open.is_some();
        let mut e = self.open.unwrap_or(Excursion {
            sign: 1,
            start: 0,
            extreme: 0,
            extreme_value: 0.0,
            last_beyond: 0,
            returned: false,
        });
        let mut sign_f = f64::from(e.sign);
        let n = trigger.len().min(value.len());
        let mut i = 0_usize;
        let mut index = self.count;
        while i < n {
            let stop = i.saturating_add(BLOCK).min(n);
            let (ub, vb) = (&trigger[i..stop], &value[i..stop]);
            // a block of an open excursion that stays on its side of the band (the most
            // samples): its extreme, return and last beyond in a few vectorised passes
            if has && ub.len() == BLOCK {
                let stayed = if e.sign > 0 {
                    side_block::<true>(ub, vb, (lo, hi, centre), index, &mut e)
                } else {
                    side_block::<false>(ub, vb, (lo, hi, centre), index, &mut e)
                };
                if stayed {
                    i = stop;
                    index = index.saturating_add(BLOCK as u64);
                    continue;
                }
            }
            for (&u, &v) in ub.iter().zip(vb) {
                let s: i8 = if u > hi {
                    1
                } else if u < lo {
                    -1
                } else {
                    0
                };
                if has && (s == 0 || s == e.sign) {
                    // v beyond the extreme on the excursion's side (finite values: the sign
                    // of the difference is that of the comparison)
                    if (v - e.extreme_value) * sign_f > 0.0 {
                        e.extreme = index;
                        e.extreme_value = v;
                        e.returned = false;
                    } else if (u - centre) * sign_f < 0.0 {
                        e.returned = true;
                    }
                    if s != 0 {
                        e.last_beyond = index;
                    }
                } else if s != 0 {
                    if has {
                        e.returned = true;
                        done.push(e);
                    }
                    has = true;
                    e = Excursion {
                        sign: s,
                        start: index,
                        extreme: index,
                        extreme_value: v,
                        last_beyond: index,
                        returned: false,
                    };
                    sign_f = f64::from(s);
                }
                index = index.saturating_add(1);
            }
            i = stop;
        }
        let open = if has { Some(e) } else { None };
        self.open = open;
        self.count = end;
        Ok(())
    }
}

/// Samples a block of [`Schmitt::push`]'s fast path holds.
const BLOCK: usize = 32;

/// One block of samples `(u, v)` (trigger, value; finite, [`BLOCK`] long) of the open
/// excursion `e` (above the band when `UP`, else below), its first sample's index `base`:
/// false, and `e` untouched, when a sample leaves the band on the other side (a new
/// excursion starts in the block: the per-sample loop takes it); else `e` as the per-sample
/// loop leaves it. The extreme: the first sample of the block's largest value (smallest when
/// below) when that beats the excursion's (the per-sample loop's strict comparisons move the
/// extreme to exactly that sample); returned: a trigger sample beyond the centre after the
/// block's new extreme (or anywhere in the block, or before it, without one); last beyond:
/// the block's last sample beyond the band on the excursion's side.
// Index arithmetic: k < BLOCK, base + k is a sample index below the checked end.
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
fn side_block<const UP: bool>(
    u: &[f64],
    v: &[f64],
    (lo, hi, centre): (f64, f64, f64),
    base: u64,
    e: &mut Excursion,
) -> bool {
    let (Ok(u), Ok(v)) = (<&[f64; BLOCK]>::try_from(u), <&[f64; BLOCK]>::try_from(v)) else {
        return false;
    };
    let better = |a: f64, b: f64| if UP { a > b } else { a < b };
    // four independent running extremes (a chain of selects a sample was the loop's
    // latency); the block's extreme value is theirs whatever the order
    let mut best = [e.extreme_value; 4];
    let mut other = [false; 4];
    for j in 0..BLOCK / 4 {
        for k in 0..4 {
            let (uk, vk) = (u[4 * j + k], v[4 * j + k]);
            best[k] = if better(vk, best[k]) { vk } else { best[k] };
            other[k] |= if UP { uk < lo } else { uk > hi };
        }
    }
    if other.iter().any(|&o| o) {
        return false;
    }
    let mut top = best[0];
    for &b in &best[1..] {
        top = if better(b, top) { b } else { top };
    }
    // one bit a sample: the block's extreme value, beyond the centre, beyond the band
    let (mut at, mut back, mut beyond) = (0_u64, 0_u64, 0_u64);
    for k in 0..BLOCK {
        let x = u[k];
        at |= u64::from(v[k] == top) << k;
        back |= u64::from(if UP { x < centre } else { x > centre }) << k;
        beyond |= u64::from(if UP { x > hi } else { x < lo }) << k;
    }
    if better(top, e.extreme_value) {
        // the first sample of the block's extreme value (numerically equal: ±0 are one)
        let m = at.trailing_zeros() as usize % BLOCK;
        e.extreme = base + m as u64;
        e.extreme_value = v[m];
        // beyond the centre after it
        e.returned = (back >> m) >> 1 != 0;
    } else {
        e.returned |= back != 0;
    }
    if beyond != 0 {
        e.last_beyond = base + u64::from(beyond.ilog2());
    }
    true
}

/// Sums of a phase-bin fold (the cycle averaging of a periodic recording), accumulated over
/// any number of chunks: per bin (`n_bins`) and per cycle and bin (`n_cycles × n_bins`,
/// row-major by cycle). Means are sums over counts; the caller divides.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldSums {
    pub n_bins: usize,
    pub n_cycles: usize,
    /// Per bin: samples, Σx, ΣF, Σφ, Σφ², Σx², Σt (φ: phase within the cycle, in [0, 1)).
    pub count: Vec<f64>,
    pub sum_x: Vec<f64>,
    pub sum_f: Vec<f64>,
    pub sum_phase: Vec<f64>,
    pub sum_phase2: Vec<f64>,
    pub sum_xx: Vec<f64>,
    pub sum_t: Vec<f64>,
    /// Per cycle and bin: samples, Σx, ΣF, Σφ.
    pub cycle_count: Vec<f64>,
    pub cycle_x: Vec<f64>,
    pub cycle_f: Vec<f64>,
    pub cycle_phase: Vec<f64>,
    /// Global index of each cycle's first sample (-1: none yet).
    pub first: Vec<i64>,
}

impl FoldSums {
    /// The buffers hold what `n_bins` and `n_cycles` say: the fields are public, so a value
    /// built by hand (not by [`FoldSums::new`]) is checked before any index uses them.
    pub fn check_shape(&self) -> Result<(), CoreError> {
        let bad = |reason| Err(CoreError::InvalidState { reason });
        if self.n_bins == 0 {
            return bad("fold sums need at least one bin");
        }
        let Some(cells) = self.n_bins.checked_mul(self.n_cycles) else {
            return bad("fold sums: n_bins * n_cycles overflows");
        };
        let per_bin = [
            &self.count,
            &self.sum_x,
            &self.sum_f,
            &self.sum_phase,
            &self.sum_phase2,
            &self.sum_xx,
            &self.sum_t,
        ];
        let per_cell = [
            &self.cycle_count,
            &self.cycle_x,
            &self.cycle_f,
            &self.cycle_phase,
        ];
        if per_bin.iter().any(|v| v.len() != self.n_bins)
            || per_cell.iter().any(|v| v.len() != cells)
            || self.first.len() != self.n_cycles
        {
            return bad("fold sums: buffer lengths do not match n_bins and n_cycles");
        }
        Ok(())
    }

    pub fn new(n_bins: usize, n_cycles: usize) -> Result<Self, CoreError> {
        if n_bins == 0 {
            return Err(CoreError::InvalidParameter {
                name: "n_bins",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        let cells = n_bins
            .checked_mul(n_cycles)
            .filter(|&c| c <= (1 << 40))
            .ok_or(CoreError::InvalidParameter {
                name: "n_cycles",
                value: n_cycles as f64,
                reason: "n_cycles × n_bins is too large",
            })?;
        let z = |k| vec![0.0; k];
        Ok(Self {
            n_bins,
            n_cycles,
            count: z(n_bins),
            sum_x: z(n_bins),
            sum_f: z(n_bins),
            sum_phase: z(n_bins),
            sum_phase2: z(n_bins),
            sum_xx: z(n_bins),
            sum_t: z(n_bins),
            cycle_count: z(cells),
            cycle_x: z(cells),
            cycle_f: z(cells),
            cycle_phase: z(cells),
            first: vec![-1; n_cycles],
        })
    }
}

/// Fold the samples `(t, x, F)` (a chunk starting at global index `offset`) into phase bins.
///
/// The phase of a sample is the piecewise-linear interpolation of the knots `(kt, kp)` at its
/// time (as `numpy.interp`, so the bins are those numpy gives); samples outside
/// `[kt[0], kt[last])` are skipped. Cycle `k = floor(phase)`, bin `floor(frac · n_bins)`.
/// Knots must be strictly increasing in time and non-decreasing in phase, with phases below
/// `n_cycles`. Streaming: call per chunk with the same `sums` (knots covering the chunk).
// Index arithmetic: kt.len() >= 2 (checked), j + 1 <= the last knot because ti < t1, and
// k = c * n_bins + b < n_cycles * n_bins, the size `FoldSums::new` allocated (n_bins >= 1).
#[allow(clippy::arithmetic_side_effects)]
pub fn fold_phase(
    t: &[f64],
    x: &[f64],
    f: &[f64],
    offset: u64,
    kt: &[f64],
    kp: &[f64],
    sums: &mut FoldSums,
) -> Result<(), CoreError> {
    check_same_len("t", t.len(), "x", x.len())?;
    check_same_len("t", t.len(), "F", f.len())?;
    check_same_len("knot_t", kt.len(), "knot_phase", kp.len())?;
    sums.check_shape()?;
    check_finite("t", t)?;
    check_finite("knot_t", kt)?;
    check_finite("knot_phase", kp)?;
    if kt.len() < 2 {
        return Err(CoreError::Empty { name: "knot_t" });
    }
    for i in 1..kt.len() {
        if kt[i] <= kt[i - 1] {
            return Err(CoreError::NotIncreasing {
                name: "knot_t",
                index: i,
                value: kt[i],
                prev: kt[i - 1],
            });
        }
    }
    let top = kp[kp.len() - 1];
    if kp[0] < 0.0 || top > sums.n_cycles as f64 || kp.windows(2).any(|w| w[1] < w[0]) {
        return Err(CoreError::InvalidParameter {
            name: "knot_phase",
            value: top,
            reason: "knot phases must be non-decreasing, in [0, n_cycles]",
        });
    }
    let nb = sums.n_bins;
    let (t0, t1) = (kt[0], kt[kt.len() - 1]);
    let mut j = 0_usize;
    // the segment's slope, computed once per knot interval (the same value numpy.interp
    // computes per sample, so the phases are bit-identical)
    let seg_slope = |j: usize| (kp[j + 1] - kp[j]) / (kt[j + 1] - kt[j]);
    let mut slope = seg_slope(0);
    for (i, ((&ti, &xi), &fi)) in t.iter().zip(x).zip(f).enumerate() {
        if !(ti >= t0 && ti < t1) {
            continue;
        }
        if ti < kt[j] {
            j = 0; // time went back (a new chunk of another stretch): search from the start
            slope = seg_slope(0);
        }
        if kt[j + 1] <= ti {
            while kt[j + 1] <= ti {
                j += 1;
            }
            slope = seg_slope(j);
        }
        // numpy.interp's arithmetic: the knot's value on the knot, else slope·(t - t_j) + p_j.
        let ph = if ti == kt[j] {
            kp[j]
        } else {
            slope * (ti - kt[j]) + kp[j]
        };
        let cf = ph.floor();
        let frac = ph - cf;
        let c = cf as usize; // 0 <= ph < n_cycles checked through the knots
        if c >= sums.n_cycles {
            continue; // only ph == n_cycles exactly, which interp never gives below t1
        }
        let b = ((frac * nb as f64) as usize).min(nb - 1);
        sums.count[b] += 1.0;
        sums.sum_x[b] += xi;
        sums.sum_f[b] += fi;
        sums.sum_phase[b] += frac;
        sums.sum_phase2[b] += frac * frac;
        sums.sum_xx[b] += xi * xi;
        sums.sum_t[b] += ti;
        let k = c * nb + b;
        sums.cycle_count[k] += 1.0;
        sums.cycle_x[k] += xi;
        sums.cycle_f[k] += fi;
        sums.cycle_phase[k] += frac;
        if sums.first[c] < 0 {
            sums.first[c] = i64::try_from(offset.saturating_add(i as u64)).unwrap_or(i64::MAX);
        }
    }
    Ok(())
}

/// `∮ F dx` of each cycle `x[bounds[k]..bounds[k+1]]` (as [`crate::masing::loop_area`]; NaN
/// for a cycle of fewer than 3 samples).
pub fn loop_areas(x: &[f64], f: &[f64], bounds: &[usize]) -> Result<Vec<f64>, CoreError> {
    check_same_len("x", x.len(), "F", f.len())?;
    let mut out = Vec::with_capacity(bounds.len().saturating_sub(1));
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b > x.len() || a > b {
            return Err(CoreError::InvalidParameter {
                name: "bounds",
                value: b as f64,
                reason: "cycle bounds must be non-decreasing and within the signal",
            });
        }
        out.push(if b.saturating_sub(a) >= 3 {
            crate::masing::loop_area(&x[a..b], &f[a..b])?
        } else {
            f64::NAN
        });
    }
    Ok(out)
}

/// Cycle-to-cycle spread of a phase fold: per bin, the standard deviation over the cycles of
/// the per-cycle bin means of x and F, each corrected to first order for where that cycle's
/// samples sit inside the bin (`mean - slope · (φ̄_cycle - φ̄_bin)`, the slope along phase a
/// periodic central difference of the bin means); NaN below 2 cycles with samples in the
/// bin. Per cycle: half the range of its bin means of x (amplitude) and of F (NaN for a cycle
/// without samples). The arithmetic is numpy's of `contactlab.tangential.preprocess`.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldSpread {
    pub x_std: Vec<f64>,
    pub f_std: Vec<f64>,
    pub amplitude: Vec<f64>,
    pub force_range: Vec<f64>,
}

// Index arithmetic: b < nb and c < n_cycles, so c * nb + b < the cells `check_shape` checked;
// (b + 1) % nb and (b + nb - 1) % nb stay below nb (nb >= 1).
#[allow(clippy::arithmetic_side_effects)]
pub fn fold_spread(sums: &FoldSums) -> Result<FoldSpread, CoreError> {
    sums.check_shape()?;
    let (nb, nc) = (sums.n_bins, sums.n_cycles);
    let half_n = nb as f64 / 2.0;
    let mean_of =
        |v: &[f64]| -> Vec<f64> { v.iter().zip(&sums.count).map(|(s, n)| s / n).collect() };
    let (xm, fm, phim) = (
        mean_of(&sums.sum_x),
        mean_of(&sums.sum_f),
        mean_of(&sums.sum_phase),
    );
    let slope = |m: &[f64], b: usize| (m[(b + 1) % nb] - m[(b + nb - 1) % nb]) * half_n;
    let gx: Vec<f64> = (0..nb).map(|b| slope(&xm, b)).collect();
    let gf: Vec<f64> = (0..nb).map(|b| slope(&fm, b)).collect();
    // corrected per-cycle bin means, NaN where a cycle has no sample in the bin
    let cell = |c: usize, b: usize, v: &[f64], g: &[f64]| {
        let k = c * nb + b;
        let n = sums.cycle_count[k];
        let dphi = sums.cycle_phase[k] / n - phim[b];
        v[k] / n - g[b] * dphi
    };
    let spread = |v: &[f64], g: &[f64]| -> Vec<f64> {
        let mut sum = vec![0.0_f64; nb];
        let mut cnt = vec![0_usize; nb];
        for c in 0..nc {
            for b in 0..nb {
                let a = cell(c, b, v, g);
                if a.is_finite() {
                    sum[b] += a;
                    cnt[b] += 1;
                }
            }
        }
        let mean: Vec<f64> = sum.iter().zip(&cnt).map(|(s, &k)| s / k as f64).collect();
        let mut sq = vec![0.0_f64; nb];
        for c in 0..nc {
            for b in 0..nb {
                let a = cell(c, b, v, g);
                if a.is_finite() {
                    let d = a - mean[b];
                    sq[b] += d * d;
                }
            }
        }
        sq.iter()
            .zip(&cnt)
            .map(|(q, &k)| {
                if k >= 2 {
                    (q / (k - 1) as f64).sqrt()
                } else {
                    f64::NAN
                }
            })
            .collect()
    };
    let range = |v: &[f64]| -> Vec<f64> {
        (0..nc)
            .map(|c| {
                let (mut hi, mut lo) = (f64::NEG_INFINITY, f64::INFINITY);
                for b in 0..nb {
                    let k = c * nb + b;
                    let m = v[k] / sums.cycle_count[k];
                    if !m.is_nan() {
                        hi = hi.max(m);
                        lo = lo.min(m);
                    }
                }
                if hi >= lo {
                    0.5 * (hi - lo)
                } else {
                    f64::NAN
                }
            })
            .collect()
    };
    Ok(FoldSpread {
        x_std: spread(&sums.cycle_x, &gx),
        f_std: spread(&sums.cycle_f, &gf),
        amplitude: range(&sums.cycle_x),
        force_range: range(&sums.cycle_f),
    })
}

/// Time averages of `v` between consecutive `edges` (trapezoid rule on the samples, the
/// cumulative integral interpolated linearly at the edges), with numpy's arithmetic:
/// `c = [0, cumsum(0.5 (v[1:] + v[:-1]) diff(t))]`, `ce = interp(edges, t, c)`,
/// `diff(ce) / diff(edges)`. `t` strictly increasing (checked), `edges` non-decreasing.
// Index arithmetic: j + 1 < t.len() inside the search (t.len() >= 2 checked).
#[allow(clippy::arithmetic_side_effects)]
pub fn period_means(t: &[f64], v: &[f64], edges: &[f64]) -> Result<Vec<f64>, CoreError> {
    check_same_len("t", t.len(), "v", v.len())?;
    check_finite("t", t)?;
    check_finite("edges", edges)?;
    if t.len() < 2 {
        return Err(CoreError::Empty { name: "t" });
    }
    for i in 1..t.len() {
        if t[i] <= t[i - 1] {
            return Err(CoreError::NotIncreasing {
                name: "t",
                index: i,
                value: t[i],
                prev: t[i - 1],
            });
        }
    }
    for i in 1..edges.len() {
        if edges[i] < edges[i - 1] {
            return Err(CoreError::NotIncreasing {
                name: "edges",
                index: i,
                value: edges[i],
                prev: edges[i - 1],
            });
        }
    }
    let n = t.len();
    // cumulative integral at sample j, carried while the edges are visited in order
    let mut ce = Vec::with_capacity(edges.len());
    let (mut j, mut cj) = (0_usize, 0.0_f64);
    let step = |j: usize| 0.5 * (v[j + 1] + v[j]) * (t[j + 1] - t[j]);
    for &e in edges {
        if e <= t[0] {
            ce.push(0.0);
            continue;
        }
        while j + 1 < n && t[j + 1] <= e {
            cj += step(j);
            j += 1;
        }
        if j + 1 >= n {
            ce.push(cj); // at or beyond the last sample: its value
        } else if e == t[j] {
            ce.push(cj);
        } else {
            let c1 = cj + step(j);
            let slope = (c1 - cj) / (t[j + 1] - t[j]);
            ce.push(slope * (e - t[j]) + cj);
        }
    }
    Ok(ce
        .windows(2)
        .zip(edges.windows(2))
        .map(|(c, e)| (c[1] - c[0]) / (e[1] - e[0]))
        .collect())
}

/// [`period_means`] of two channels on one time axis in one pass (the checks of `t` and
/// `edges` once, `t` read once): `(means of f, means of x)`, each bit for bit what
/// [`period_means`] gives for it (the same steps, sums and interpolation).
// Index arithmetic: j + 1 < t.len() inside the search (t.len() >= 2 checked).
#[allow(clippy::arithmetic_side_effects)]
pub fn period_means_pair(
    t: &[f64],
    f: &[f64],
    x: &[f64],
    edges: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), CoreError> {
    check_same_len("t", t.len(), "v", f.len())?;
    check_same_len("t", t.len(), "v", x.len())?;
    if t.len() < 2 {
        check_finite("t", t)?;
        check_finite("edges", edges)?;
        return Err(CoreError::Empty { name: "t" });
    }
    // finite and strictly increasing in one pass (NaN fails the comparison); the separate
    // checks name the first failure
    let mut ok = t[0].is_finite();
    for w in t.windows(2) {
        ok &= w[1] > w[0] && w[1].is_finite();
    }
    if !ok {
        check_finite("t", t)?;
        for i in 1..t.len() {
            if t[i] <= t[i - 1] {
                return Err(CoreError::NotIncreasing {
                    name: "t",
                    index: i,
                    value: t[i],
                    prev: t[i - 1],
                });
            }
        }
    }
    check_finite("edges", edges)?;
    for i in 1..edges.len() {
        if edges[i] < edges[i - 1] {
            return Err(CoreError::NotIncreasing {
                name: "edges",
                index: i,
                value: edges[i],
                prev: edges[i - 1],
            });
        }
    }
    Ok(period_means_pair_checked(t, f, x, edges))
}

/// [`period_means_pair`] of checked samples: `t` finite, strictly increasing and at least
/// two samples, `f` and `x` as long, `edges` finite and non-decreasing (the callers' checks).
// Index arithmetic: j + 1 < n where j + 1 is taken (trapezoids_until stops there).
#[allow(clippy::arithmetic_side_effects)]
pub(crate) fn period_means_pair_checked(
    t: &[f64],
    f: &[f64],
    x: &[f64],
    edges: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let n = t.len();
    let mut ce_f = Vec::with_capacity(edges.len());
    let mut ce_x = Vec::with_capacity(edges.len());
    let (mut j, mut cf, mut cx) = (0_usize, 0.0_f64, 0.0_f64);
    for &e in edges {
        if e <= t[0] {
            ce_f.push(0.0);
            ce_x.push(0.0);
            continue;
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
    (means(&ce_f), means(&ce_x))
}

/// [`period_means_pair`]'s cumulative trapezoid integrals `(cf, cx)` of `F` and `x` carried
/// from sample `j` over the samples up to the last at or before `e`: returns the new `j` and
/// sums. Its own function: inlined into the loop over the edges, the two sums lived on the
/// stack (a store and a load in their chain every sample, 5 ns a sample against about 1).
// Index arithmetic: j + 1 < n, the shortest slice's length.
#[allow(clippy::arithmetic_side_effects)]
#[inline(never)]
fn trapezoids_until(
    t: &[f64],
    (f, x): (&[f64], &[f64]),
    mut j: usize,
    e: f64,
    (mut cf, mut cx): (f64, f64),
) -> (usize, f64, f64) {
    let n = t.len().min(f.len()).min(x.len());
    while j + 1 < n && t[j + 1] <= e {
        let dt = t[j + 1] - t[j];
        cf += 0.5 * (f[j + 1] + f[j]) * dt;
        cx += 0.5 * (x[j + 1] + x[j]) * dt;
        j += 1;
    }
    (j, cf, cx)
}

/// Noise sensitivity of each cycle's loop area `x[bounds[k]..bounds[k+1]]`: the shoelace
/// area is linear in every sample's `F` with coefficient `(x[i-1] - x[i+1]) / 2` and in its
/// `x` with `(F[i+1] - F[i-1]) / 2` (indices cyclic within the cycle). Returns per cycle
/// `(Σ coef_F², Σ coef_x²)`, so that independent sample noise `σF`, `σx` gives the area a
/// variance `σF² Σ coef_F² + σx² Σ coef_x²`.
// Index arithmetic: i < m = b - a with a <= b <= len checked, so a + (i ± 1) mod m < len.
#[allow(clippy::arithmetic_side_effects)]
pub fn loop_area_sensitivity(
    x: &[f64],
    f: &[f64],
    bounds: &[usize],
) -> Result<(Vec<f64>, Vec<f64>), CoreError> {
    check_same_len("x", x.len(), "F", f.len())?;
    let cycles = bounds.len().saturating_sub(1);
    let (mut out_f, mut out_x) = (Vec::with_capacity(cycles), Vec::with_capacity(cycles));
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b > x.len() || a > b {
            return Err(CoreError::InvalidParameter {
                name: "bounds",
                value: b as f64,
                reason: "cycle bounds must be non-decreasing and within the signal",
            });
        }
        let (xs, fs) = (&x[a..b], &f[a..b]);
        let m = xs.len();
        let (mut sf, mut sx) = (0.0_f64, 0.0_f64);
        for i in 0..m {
            let (p, n) = (
                if i == 0 { m - 1 } else { i - 1 },
                if i + 1 == m { 0 } else { i + 1 },
            );
            let cf = 0.5 * (xs[p] - xs[n]);
            let cx = 0.5 * (fs[n] - fs[p]);
            sf += cf * cf;
            sx += cx * cx;
        }
        out_f.push(sf);
        out_x.push(sx);
    }
    Ok((out_f, out_x))
}

/// State of [`cycle_block`] between blocks of a stream (see `contactlab.studies._cycles`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleState {
    /// Trigger level: +1 above the band, -1 below, 0 not yet known.
    pub level: i8,
    pub have_crossing: bool,
    pub x_cross: f64,
    pub f_cross: f64,
    pub t_cross: f64,
    /// `∮ F dx` since the last crossing, up to the previous sample.
    pub acc: f64,
    /// The previous block's last sample (NaN before the first).
    pub x_prev: f64,
    pub f_prev: f64,
    /// Extrema since the last crossing.
    pub x_max: f64,
    pub x_min: f64,
    pub f_max: f64,
    pub f_min: f64,
}

impl Default for CycleState {
    fn default() -> Self {
        Self {
            level: 0,
            have_crossing: false,
            x_cross: 0.0,
            f_cross: 0.0,
            t_cross: 0.0,
            acc: 0.0,
            x_prev: f64::NAN,
            f_prev: f64::NAN,
            x_max: f64::NEG_INFINITY,
            x_min: f64::INFINITY,
            f_max: f64::NEG_INFINITY,
            f_min: f64::INFINITY,
        }
    }
}

/// Cycles completed in one block by [`cycle_block`]: every upward crossing of the drive
/// (global index) and, per complete cycle, start and end time, `∮ F dx` (the polygon of the
/// cycle's samples, closed by the chord back to its first), amplitude (half the x range) and
/// offset (centre of the F range).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BlockCycles {
    pub crossings: Vec<u64>,
    pub start: Vec<f64>,
    pub end: Vec<f64>,
    pub energy: Vec<f64>,
    pub amplitude: Vec<f64>,
    pub offset: Vec<f64>,
}

/// The first upward crossing of `drive[from..]` through `[low, high]` (`low < high`) as a
/// Schmitt trigger with the carried `level`: the drive must have been `<= low` since the last
/// `>= high`; `drive.len()` when there is none. `level` follows the drive up to the crossing
/// (to the end without one), as one sample at a time would leave it.
// Index arithmetic: from <= k <= drive.len() throughout.
#[allow(clippy::arithmetic_side_effects)]
fn next_crossing(drive: &[f64], from: usize, low: f64, high: f64, level: &mut i8) -> usize {
    let n = drive.len();
    let mut k = from;
    if *level != -1 {
        let Some(p) = drive[k..].iter().position(|&d| d <= low) else {
            if drive[k..].iter().any(|&d| d >= high) {
                *level = 1;
            }
            return n;
        };
        *level = -1;
        k += p + 1;
    }
    match drive[k..].iter().position(|&d| d >= high) {
        Some(p) => {
            *level = 1;
            k + p
        }
        None => n,
    }
}

/// Upward crossings of `drive` through the band `[low, high]` (a Schmitt trigger: the drive
/// must have been `<= low` since the last `>= high` before a new `>= high` counts) and the
/// cycles they complete, in one pass over a block starting at global index `offset`; `state`
/// carries everything across blocks, so any chunking gives the same cycles. A band with
/// `high <= low` (a constant block) finds no crossing. On error `state` is unchanged.
#[allow(clippy::too_many_arguments)]
pub fn cycle_block(
    t: &[f64],
    x: &[f64],
    f: &[f64],
    drive: &[f64],
    offset: u64,
    low: f64,
    high: f64,
    state: &mut CycleState,
) -> Result<BlockCycles, CoreError> {
    check_same_len("t", t.len(), "x", x.len())?;
    check_same_len("x", x.len(), "F", f.len())?;
    check_same_len("x", x.len(), "drive", drive.len())?;
    check_finite("t", t)?;
    cycle_block_with(|c| t[c], x, f, drive, offset, (low, high), state)
}

/// [`cycle_block`] of a recording sampled every `dt` from `t0`, without a time array: block
/// sample `i` is at `t0 + dt * (offset + i)`, bit for bit [`crate::stream::fill_time`]'s
/// (and numpy's `t0 + dt * arange`). The same cycles as [`cycle_block`] given that time
/// axis.
#[allow(clippy::too_many_arguments)]
pub fn cycle_block_sampled(
    t0: f64,
    dt: f64,
    x: &[f64],
    f: &[f64],
    drive: &[f64],
    offset: u64,
    low: f64,
    high: f64,
    state: &mut CycleState,
) -> Result<BlockCycles, CoreError> {
    for (name, value) in [("t0", t0), ("dt", dt)] {
        if !value.is_finite() {
            return Err(CoreError::InvalidParameter {
                name,
                value,
                reason: "the time axis' start and step must be finite",
            });
        }
    }
    u64::try_from(x.len())
        .ok()
        .and_then(|k| offset.checked_add(k))
        .filter(|&end| end <= 1 << 53)
        .ok_or(CoreError::TooLong { len: x.len() })?;
    // exact: offset + c < 2^53
    #[allow(clippy::cast_precision_loss, clippy::arithmetic_side_effects)]
    let time = |c: usize| t0 + dt * ((offset + c as u64) as f64);
    cycle_block_with(time, x, f, drive, offset, (low, high), state)
}

/// The first of the checks of `x`, `F` and `drive` that fails, in that order (what a block
/// with a non-finite sample reports), else `other`.
fn first_non_finite(x: &[f64], f: &[f64], drive: &[f64], other: CoreError) -> CoreError {
    check_finite("x", x)
        .and_then(|()| check_finite("F", f))
        .and_then(|()| check_finite("drive", drive))
        .err()
        .unwrap_or(other)
}

/// [`cycle_block`] with the time of block sample `c` from `time(c)` (read at crossings only).
/// `x` and `F` are checked finite in the pass itself (the pass is bound by the chain of
/// additions of `∮ F dx`, and the test costs nothing beside it); a block with a non-finite
/// sample reports the first as the separate checks would, and leaves `state` unchanged.
// Index arithmetic: i < n (the block length) throughout.
#[allow(clippy::arithmetic_side_effects, clippy::too_many_lines)]
fn cycle_block_with(
    time: impl Fn(usize) -> f64,
    x: &[f64],
    f: &[f64],
    drive: &[f64],
    offset: u64,
    (low, high): (f64, f64),
    state: &mut CycleState,
) -> Result<BlockCycles, CoreError> {
    let n = x.len();
    check_same_len("x", n, "F", f.len())?;
    check_same_len("x", n, "drive", drive.len())?;
    // the errors in the order of the separate checks: x, F, drive, then the parameters
    if !std::ptr::eq(drive, x) {
        // a tangential stream's drive is its x: checked in the pass
        if let Err(e) = check_finite("drive", drive) {
            return Err(first_non_finite(x, f, drive, e));
        }
    }
    if !(low.is_finite() && high.is_finite()) {
        let e = CoreError::InvalidParameter {
            name: "levels",
            value: if low.is_finite() { high } else { low },
            reason: "trigger levels must be finite",
        };
        return Err(first_non_finite(x, f, drive, e));
    }
    if u64::try_from(n)
        .ok()
        .and_then(|k| offset.checked_add(k))
        .is_none()
    {
        return Err(first_non_finite(x, f, drive, CoreError::TooLong { len: n }));
    }
    let mut out = BlockCycles::default();
    if n == 0 {
        return Ok(out);
    }
    let can_cross = high > low;
    let mut s = *state;
    // cum: ∮ F dx since the last crossing (the carried part included)
    let mut cum = s.acc;
    let (mut xp, mut fp) = (s.x_prev, s.f_prev);
    let (mut xmax, mut xmin, mut fmax, mut fmin) = (s.x_max, s.x_min, s.f_max, s.f_min);
    let mut i = 0;
    // every sample of x and F finite (the pass visits each once)
    let mut finite = true;
    while i < n {
        // the next crossing (the trigger level follows the drive up to it), then the samples
        // before it in one tight pass: the trapezoids in the same order as one sample at a
        // time (the same sum, bit for bit), the extrema
        let c = if can_cross {
            next_crossing(drive, i, low, high, &mut s.level)
        } else {
            n
        };
        let mut j = i;
        if j < c && !xp.is_finite() {
            // the record's first sample: no trapezoid before it
            finite &= x[j].is_finite() & f[j].is_finite();
            (xmax, xmin, fmax, fmin) = (
                xmax.max(x[j]),
                xmin.min(x[j]),
                fmax.max(f[j]),
                fmin.min(f[j]),
            );
            (xp, fp) = (x[j], f[j]);
            j += 1;
        }
        for (&xi, &fi) in x[j..c].iter().zip(&f[j..c]) {
            finite &= xi.is_finite() & fi.is_finite();
            cum += 0.5 * (fi + fp) * (xi - xp);
            // compare-and-select (finite samples, checked above): f64::max/min's NaN rules
            // cost a compare, a blend and a dependency each on a generic x86-64 build
            xmax = if xi > xmax { xi } else { xmax };
            xmin = if xi < xmin { xi } else { xmin };
            fmax = if fi > fmax { fi } else { fmax };
            fmin = if fi < fmin { fi } else { fmin };
            xp = xi;
            fp = fi;
        }
        if c >= n {
            break;
        }
        // a crossing at c: the cycle since the previous one ends here (its extrema exclude
        // this sample, which starts the next cycle)
        let (xi, fi) = (x[c], f[c]);
        finite &= xi.is_finite() & fi.is_finite();
        if xp.is_finite() {
            cum += 0.5 * (fi + fp) * (xi - xp);
        }
        out.crossings.push(offset.saturating_add(c as u64));
        if s.have_crossing {
            let energy = cum + 0.5 * (fi + s.f_cross) * (s.x_cross - xi);
            out.start.push(s.t_cross);
            out.end.push(time(c));
            out.energy.push(energy);
            out.amplitude.push(0.5 * (xmax - xmin));
            out.offset.push(0.5 * (fmax + fmin));
        }
        s.have_crossing = true;
        s.x_cross = xi;
        s.f_cross = fi;
        s.t_cross = time(c);
        cum = 0.0;
        (xmax, xmin, fmax, fmin) = (xi, xi, fi, fi);
        xp = xi;
        fp = fi;
        i = c + 1;
    }
    if !finite {
        let e = CoreError::InvalidState {
            reason: "a non-finite sample was seen but not found again",
        };
        return Err(first_non_finite(x, f, drive, e));
    }
    if !can_cross {
        // no crossing possible (high <= low): the level is the block's last mark
        if let Some(&d) = drive.iter().rev().find(|&&d| d <= low || d >= high) {
            s.level = if d <= low { -1 } else { 1 };
        }
    }
    s.acc = cum;
    s.x_prev = xp;
    s.f_prev = fp;
    (s.x_max, s.x_min, s.f_max, s.f_min) = (xmax, xmin, fmax, fmin);
    *state = s;
    Ok(out)
}

#[cfg(test)]
mod tests {
    #[test]
    fn fold_sums_built_by_hand_are_checked_not_indexed() {
        let mut sums = super::FoldSums::new(4, 2).unwrap();
        sums.n_bins = 0;
        let t = [0.0, 0.5];
        let r = super::fold_phase(&t, &t, &t, 0, &[0.0, 1.0], &[0.0, 1.0], &mut sums);
        assert!(matches!(r, Err(crate::CoreError::InvalidState { .. })));
        let mut sums = super::FoldSums::new(4, 2).unwrap();
        sums.n_bins = 8; // buffers still sized for 4
        let r = super::fold_phase(&t, &t, &t, 0, &[0.0, 1.0], &[0.0, 1.0], &mut sums);
        assert!(matches!(r, Err(crate::CoreError::InvalidState { .. })));
    }

    use super::*;

    fn run(x: &[f64], centre: f64, thr: f64) -> (Vec<Excursion>, Option<Excursion>) {
        let mut s = Schmitt::new(centre, thr).unwrap();
        let mut done = Vec::new();
        s.push(x, None, &mut done).unwrap();
        (done, s.open)
    }

    /// The match-per-sample loop `Schmitt::push` replaced: the reference.
    fn push_reference(st: &mut Schmitt, trigger: &[f64], value: &[f64], done: &mut Vec<Excursion>) {
        let hi = st.centre + st.threshold;
        let lo = st.centre - st.threshold;
        let centre = st.centre;
        let mut open = st.open;
        for (index, (&u, &v)) in (st.count..).zip(trigger.iter().zip(value)) {
            let s: i8 = if u > hi {
                1
            } else if u < lo {
                -1
            } else {
                0
            };
            match &mut open {
                Some(e) if s == 0 || s == e.sign => {
                    let beyond = s != 0;
                    let better = if e.sign > 0 {
                        v > e.extreme_value
                    } else {
                        v < e.extreme_value
                    };
                    if better {
                        e.extreme = index;
                        e.extreme_value = v;
                        e.returned = false;
                    } else if (u - centre) * f64::from(e.sign) < 0.0 {
                        e.returned = true;
                    }
                    if beyond {
                        e.last_beyond = index;
                    }
                }
                _ if s == 0 => {}
                _ => {
                    if let Some(mut e) = open.take() {
                        e.returned = true;
                        done.push(e);
                    }
                    open = Some(Excursion {
                        sign: s,
                        start: index,
                        extreme: index,
                        extreme_value: v,
                        last_beyond: index,
                        returned: false,
                    });
                }
            }
        }
        st.open = open;
        st.count += trigger.len() as u64;
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]
        /// The locals loop equals the reference on noisy sines and random walks with
        /// separate value signals, plateaus (ties) and values near the extremes of the
        /// double range, pushed in chunks.
        #[test]
        fn push_equals_the_reference(
            seed in 0u64..10_000, n in 0usize..3000, cut in 0usize..3000,
            scale in proptest::sample::select(vec![1.0, 1e-300, 1e300]),
            quant in proptest::sample::select(vec![0.0, 0.25]),
            separate in proptest::bool::ANY,
            slow in proptest::bool::ANY, piece in 1usize..400,
        ) {
            let mut st = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(7);
            let mut rnd = move || {
                st = st.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                ((st >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            };
            let q = |v: f64| if quant > 0.0 { (v / quant).round() * quant } else { v };
            // slow: excursions of hundreds of samples, most of them in the blocks of the fast
            // path (and the ties of the quantised values inside them)
            let (w, noise) = if slow { (0.004, 0.1) } else { (0.05, 0.6) };
            let u: Vec<f64> = (0..n)
                .map(|i| scale * q((i as f64 * w).sin() + noise * rnd()))
                .collect();
            let v: Vec<f64> = if separate {
                u.iter().map(|a| a + scale * q(0.3 * rnd())).collect()
            } else {
                u.clone()
            };
            let cut = cut.min(n);
            let (centre, thr) = (0.1 * scale, 0.4 * scale);
            let mut a = Schmitt::new(centre, thr).unwrap();
            let mut b = a.clone();
            let (mut da, mut db) = (Vec::new(), Vec::new());
            // two chunks, the second in pieces of `piece` samples: the open excursion (its
            // return flag above all) compared after every push
            let mut ends = vec![cut];
            while ends[ends.len() - 1] < n {
                ends.push((ends[ends.len() - 1] + piece).min(n));
            }
            let mut s0 = 0;
            for s1 in ends {
                a.push(&u[s0..s1], Some(&v[s0..s1]), &mut da).unwrap();
                push_reference(&mut b, &u[s0..s1], &v[s0..s1], &mut db);
                proptest::prop_assert_eq!(&a, &b);
                s0 = s1;
            }
            proptest::prop_assert_eq!(&da, &db);
        }
    }

    #[test]
    fn hand_checked_sequence() {
        // band ±1 around 0: the wiggle 1.5 -> 0.5 -> 1.8 is one excursion, -1.2 starts the next.
        let x = [0.0, 1.5, 0.5, 1.8, 0.9, -0.5, -1.2, -3.0, -0.8, 0.2];
        let (done, open) = run(&x, 0.0, 1.0);
        assert_eq!(done.len(), 1);
        let e = done[0];
        assert_eq!((e.sign, e.start, e.extreme, e.last_beyond), (1, 1, 3, 3));
        assert!(e.returned);
        let o = open.unwrap();
        assert_eq!((o.sign, o.start, o.extreme, o.last_beyond), (-1, 6, 7, 7));
        assert!(o.returned, "0.2 crossed the centre after the valley");
    }

    #[test]
    fn chunks_equal_one_pass_and_bad_input_is_an_error() {
        let x: Vec<f64> = (0..5000)
            .map(|i| (f64::from(i) * 0.013).sin() + 0.3 * (f64::from(i) * 1.7).sin())
            .collect();
        let (whole, open) = run(&x, 0.0, 0.5);
        assert!(whole.len() > 10);
        for cut in [0, 1, 777, 4999, 5000] {
            let mut s = Schmitt::new(0.0, 0.5).unwrap();
            let mut done = Vec::new();
            s.push(&x[..cut], None, &mut done).unwrap();
            s.push(&x[cut..], None, &mut done).unwrap();
            assert_eq!(done, whole);
            assert_eq!(s.open, open);
        }
        let mut s = Schmitt::new(0.0, 0.5).unwrap();
        let before = s.clone();
        assert!(s.push(&[0.0, f64::NAN], None, &mut Vec::new()).is_err());
        assert_eq!(s, before);
        assert!(Schmitt::new(0.0, 0.0).is_err());
        assert!(Schmitt::new(f64::NAN, 1.0).is_err());
    }
    /// The one-sample-at-a-time loop `cycle_block` replaced (its next crossing is now found
    /// first and the samples before it summed in one tight pass): the reference.
    #[allow(clippy::arithmetic_side_effects, clippy::too_many_arguments)]
    fn cycle_block_reference(
        t: &[f64],
        x: &[f64],
        f: &[f64],
        drive: &[f64],
        offset: u64,
        low: f64,
        high: f64,
        state: &mut CycleState,
    ) -> Result<BlockCycles, CoreError> {
        let n = x.len();
        check_same_len("t", t.len(), "x", n)?;
        check_same_len("x", n, "F", f.len())?;
        check_same_len("x", n, "drive", drive.len())?;
        check_finite("t", t)?;
        check_finite("x", x)?;
        check_finite("F", f)?;
        check_finite("drive", drive)?;
        if !(low.is_finite() && high.is_finite()) {
            return Err(CoreError::InvalidParameter {
                name: "levels",
                value: if low.is_finite() { high } else { low },
                reason: "trigger levels must be finite",
            });
        }
        u64::try_from(n)
            .ok()
            .and_then(|k| offset.checked_add(k))
            .ok_or(CoreError::TooLong { len: n })?;
        let mut out = BlockCycles::default();
        if n == 0 {
            return Ok(out);
        }
        let can_cross = high > low;
        let mut s = *state;
        // cum: ∮ F dx since the last crossing (the carried part included)
        let mut cum = s.acc;
        let (mut xp, mut fp) = (s.x_prev, s.f_prev);
        let (mut xmax, mut xmin, mut fmax, mut fmin) = (s.x_max, s.x_min, s.f_max, s.f_min);
        for i in 0..n {
            let (xi, fi) = (x[i], f[i]);
            if xp.is_finite() {
                cum += 0.5 * (fi + fp) * (xi - xp);
            }
            let mark: i8 = if drive[i] <= low {
                -1
            } else {
                i8::from(drive[i] >= high)
            };
            let before = s.level;
            if mark != 0 {
                s.level = mark;
            }
            if can_cross && mark == 1 && before == -1 {
                // a crossing at i: the cycle since the previous one ends here (its extrema
                // exclude this sample, which starts the next cycle)
                out.crossings.push(offset.saturating_add(i as u64));
                if s.have_crossing {
                    let energy = cum + 0.5 * (fi + s.f_cross) * (s.x_cross - xi);
                    out.start.push(s.t_cross);
                    out.end.push(t[i]);
                    out.energy.push(energy);
                    out.amplitude.push(0.5 * (xmax - xmin));
                    out.offset.push(0.5 * (fmax + fmin));
                }
                s.have_crossing = true;
                s.x_cross = xi;
                s.f_cross = fi;
                s.t_cross = t[i];
                cum = 0.0;
                (xmax, xmin, fmax, fmin) = (xi, xi, fi, fi);
            } else {
                xmax = xmax.max(xi);
                xmin = xmin.min(xi);
                fmax = fmax.max(fi);
                fmin = fmin.min(fi);
            }
            xp = xi;
            fp = fi;
        }
        s.acc = cum;
        s.x_prev = xp;
        s.f_prev = fp;
        (s.x_max, s.x_min, s.f_max, s.f_min) = (xmax, xmin, fmax, fmin);
        *state = s;
        Ok(out)
    }

    fn run_chunks(
        t: &[f64],
        x: &[f64],
        f: &[f64],
        d: &[f64],
        cuts: &[usize],
        low: f64,
        high: f64,
        fast: bool,
    ) -> (BlockCycles, CycleState) {
        let mut st = CycleState::default();
        let mut got = BlockCycles::default();
        let mut a = 0;
        for &b in cuts.iter().chain(std::iter::once(&x.len())) {
            let b = b.clamp(a, x.len());
            let args = (&t[a..b], &x[a..b], &f[a..b], &d[a..b]);
            let c = if fast {
                cycle_block(args.0, args.1, args.2, args.3, a as u64, low, high, &mut st)
            } else {
                cycle_block_reference(args.0, args.1, args.2, args.3, a as u64, low, high, &mut st)
            }
            .unwrap();
            got.crossings.extend(c.crossings);
            got.start.extend(c.start);
            got.end.extend(c.end);
            got.amplitude.extend(c.amplitude);
            got.offset.extend(c.offset);
            got.energy.extend(c.energy);
            a = b;
        }
        (got, st)
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|a| a.to_bits()).collect()
    }

    /// Runs between crossings of hundreds to thousands of samples (cycles of 700 to 3000
    /// samples, noisy, chunks cut anywhere, the drive x itself or another channel): the
    /// one-sample loop's numbers, bit for bit.
    #[test]
    fn long_cycles_equal_the_one_sample_loop_bit_for_bit() {
        for (per, n, cuts) in [
            (700.0, 9000, vec![]),
            (1500.0, 12_000, vec![1, 255, 257, 4000, 4001, 9999]),
            (3000.0, 20_000, vec![6000, 6512]),
        ] {
            let mut seed = 0x9E37_79B9_7F4A_7C15_u64;
            let mut noise = move || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let ph = |i: usize| 2.0 * std::f64::consts::PI * i as f64 / per;
            let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
            let x: Vec<f64> = (0..n)
                .map(|i| 2e-5 * ph(i).sin() + 1e-7 * noise())
                .collect();
            let f: Vec<f64> = (0..n)
                .map(|i| 40.0 * (ph(i) + 0.3).sin() + 0.1 * noise())
                .collect();
            let d: Vec<f64> = (0..n).map(|i| (ph(i) - 0.2).sin()).collect();
            for (drive, low, high) in [(&x, -1e-5, 1e-5), (&d, -0.5, 0.5)] {
                let (a, sa) = run_chunks(&t, &x, &f, drive, &cuts, low, high, true);
                let (b, sb) = run_chunks(&t, &x, &f, drive, &cuts, low, high, false);
                assert!(a.energy.len() >= 2, "per {per}: {} cycles", a.energy.len());
                assert_eq!(a.crossings, b.crossings);
                assert_eq!(bits(&a.energy), bits(&b.energy), "per {per}");
                assert_eq!(bits(&a.amplitude), bits(&b.amplitude));
                assert_eq!(bits(&a.offset), bits(&b.offset));
                assert_eq!(sa.acc.to_bits(), sb.acc.to_bits());
                assert_eq!(sa.x_max.to_bits(), sb.x_max.to_bits());
                assert_eq!(sa.f_min.to_bits(), sb.f_min.to_bits());
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn cycle_block_equals_the_one_sample_loop_bit_for_bit(
            xs in proptest::collection::vec(-2.0_f64..2.0, 1..600),
            fs in proptest::collection::vec(-3.0_f64..3.0, 600),
            ds in proptest::collection::vec(-1.5_f64..1.5, 600),
            drive_is_x in proptest::bool::ANY,
            low in -1.0_f64..1.0,
            width in -0.5_f64..1.0,
            mut cuts in proptest::collection::vec(0_usize..600, 0..6),
        ) {
            let n = xs.len();
            let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
            let f = &fs[..n];
            let d = if drive_is_x { xs.clone() } else { ds[..n].to_vec() };
            cuts.sort_unstable();
            let high = low + width; // width <= 0: no crossing can count
            let (a, sa) = run_chunks(&t, &xs, f, &d, &cuts, low, high, true);
            let (b, sb) = run_chunks(&t, &xs, f, &d, &cuts, low, high, false);
            proptest::prop_assert_eq!(&a.crossings, &b.crossings);
            proptest::prop_assert_eq!(bits(&a.energy), bits(&b.energy));
            proptest::prop_assert_eq!(bits(&a.start), bits(&b.start));
            proptest::prop_assert_eq!(bits(&a.end), bits(&b.end));
            proptest::prop_assert_eq!(bits(&a.amplitude), bits(&b.amplitude));
            proptest::prop_assert_eq!(bits(&a.offset), bits(&b.offset));
            proptest::prop_assert_eq!(sa.level, sb.level);
            proptest::prop_assert_eq!(sa.acc.to_bits(), sb.acc.to_bits());
            proptest::prop_assert_eq!(sa.x_prev.to_bits(), sb.x_prev.to_bits());
            proptest::prop_assert_eq!(sa.have_crossing, sb.have_crossing);
        }
    }

    proptest::proptest! {
        #[test]
        fn period_means_pair_is_two_period_means_bit_for_bit(
            // up to 1000 samples: periods longer than a block of trapezoids_until (128)
            steps in proptest::collection::vec(0.001_f64..0.1, 1..1000),
            fs in proptest::collection::vec(-3.0_f64..3.0, 1000),
            xs in proptest::collection::vec(-2.0_f64..2.0, 1000),
            mut edges in proptest::collection::vec(-0.5_f64..60.0, 0..12),
            on_samples in proptest::collection::vec(0_usize..1000, 0..4),
        ) {
            let mut t = vec![0.0_f64];
            for s in &steps {
                let last = t[t.len() - 1];
                t.push(last + s);
            }
            let n = t.len();
            for k in on_samples {
                edges.push(t[k % n]); // edges exactly on samples
            }
            edges.sort_by(f64::total_cmp);
            let (f, x) = (&fs[..n], &xs[..n]);
            let (mf, mx) = period_means_pair(&t, f, x, &edges).unwrap();
            proptest::prop_assert_eq!(bits(&mf), bits(&period_means(&t, f, &edges).unwrap()));
            proptest::prop_assert_eq!(bits(&mx), bits(&period_means(&t, x, &edges).unwrap()));
        }
    }

    #[test]
    fn period_means_pair_refuses_what_period_means_does() {
        let t = [0.0, 1.0, 1.0, 2.0];
        let v = [0.0; 4];
        assert!(period_means_pair(&t, &v, &v, &[0.5, 1.5]).is_err());
        assert!(period_means_pair(&[0.0, f64::NAN], &v[..2], &v[..2], &[0.5]).is_err());
        assert!(period_means_pair(&[0.0, 1.0], &v[..2], &v[..2], &[0.5, 0.2]).is_err());
        assert!(period_means_pair(&[0.0], &v[..1], &v[..1], &[]).is_err());
        assert!(period_means_pair(&[0.0, 1.0], &v[..2], &v[..1], &[]).is_err());
    }

    #[test]
    fn cycle_block_any_chunking_equals_one_pass() {
        let n = 4000_usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&s| (s * 37.0).sin() + 0.05 * (s * 3111.0).sin())
            .collect();
        let f: Vec<f64> = t.iter().map(|&s| (s * 37.0 + 0.4).sin() + 0.2).collect();
        let mut st = CycleState::default();
        let whole = cycle_block(&t, &x, &f, &x, 0, -0.25, 0.25, &mut st).unwrap();
        // 37 rad/s over 4 s: 23.5 periods -> 23 crossings, 22 complete cycles
        assert_eq!(whole.crossings.len(), 23);
        assert_eq!(whole.energy.len(), 22);
        for k in 0..whole.energy.len() {
            assert!((whole.amplitude[k] - 1.0).abs() < 0.06);
            assert!((whole.offset[k] - 0.2).abs() < 0.01);
            // the loop of sin vs sin(. + 0.4): area π sin(0.4) per cycle, positive orientation
            assert!((whole.energy[k].abs() - std::f64::consts::PI * 0.4_f64.sin()).abs() < 0.08);
        }
        for cuts in [
            vec![1_usize],
            vec![17, 18, 2000],
            vec![3999],
            vec![500, 1500, 2500],
        ] {
            let mut st = CycleState::default();
            let mut got = BlockCycles::default();
            let mut a = 0;
            for &b in cuts.iter().chain(std::iter::once(&n)) {
                let c = cycle_block(
                    &t[a..b],
                    &x[a..b],
                    &f[a..b],
                    &x[a..b],
                    a as u64,
                    -0.25,
                    0.25,
                    &mut st,
                )
                .unwrap();
                got.crossings.extend(c.crossings);
                got.start.extend(c.start);
                got.end.extend(c.end);
                got.amplitude.extend(c.amplitude);
                got.offset.extend(c.offset);
                got.energy.extend(c.energy);
                a = b;
            }
            assert_eq!(got.crossings, whole.crossings);
            assert_eq!(got.amplitude, whole.amplitude);
            for (g, w) in got.energy.iter().zip(&whole.energy) {
                assert!((g - w).abs() < 1e-12);
            }
        }
        let before = st;
        assert!(cycle_block(&[0.0], &[f64::NAN], &[0.0], &[0.0], 0, -1.0, 1.0, &mut st).is_err());
        assert!(cycle_block(&[0.0], &[0.0], &[0.0], &[0.0], u64::MAX, -1.0, 1.0, &mut st).is_err());
        assert_eq!(st, before);
    }

    #[test]
    fn sampled_cycle_block_equals_the_stamped_one_bit_for_bit() {
        let n = 5000_usize;
        let (t0, dt) = (0.125, 1.0 / 3000.0);
        let mut t = vec![0.0; n];
        crate::stream::fill_time(&mut t, t0, dt, 0).unwrap();
        let x: Vec<f64> = t
            .iter()
            .map(|&s| (s * 41.0).sin() + 0.07 * (s * 2917.0).sin())
            .collect();
        let f: Vec<f64> = t.iter().map(|&s| (s * 41.0 + 0.3).cos() - 0.1).collect();
        for cuts in [vec![], vec![1_usize, 2], vec![777, 3001], vec![4999]] {
            let (mut sa, mut sb) = (CycleState::default(), CycleState::default());
            let mut a = 0;
            for &b in cuts.iter().chain(std::iter::once(&n)) {
                let r = a..b;
                let (xs, fs) = (&x[r.clone()], &f[r.clone()]);
                let one = cycle_block(&t[r], xs, fs, xs, a as u64, -0.3, 0.3, &mut sa).unwrap();
                let two =
                    cycle_block_sampled(t0, dt, xs, fs, xs, a as u64, -0.3, 0.3, &mut sb).unwrap();
                assert_eq!(one, two);
                assert_eq!(sa, sb);
                a = b;
            }
        }
        let mut st = CycleState::default();
        assert!(cycle_block_sampled(f64::NAN, dt, &x, &f, &x, 0, -1.0, 1.0, &mut st).is_err());
        assert!(cycle_block_sampled(t0, dt, &x, &f, &x, 1 << 53, -1.0, 1.0, &mut st).is_err());
    }

    #[test]
    fn cycle_block_reports_the_first_non_finite_sample_as_the_separate_checks() {
        let n = 300;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-2).collect();
        let x: Vec<f64> = t.iter().map(|&s| (s * 9.0).sin()).collect();
        let f: Vec<f64> = t.iter().map(|&s| (s * 9.0).cos()).collect();
        for (xi, fi, p) in [
            (Some(5), None, 0),
            (Some(250), Some(3), 0),
            (None, Some(299), 1),
        ] {
            for levels in [(-0.5, 0.5), (f64::NAN, 0.5)] {
                let (mut xb, mut fb) = (x.clone(), f.clone());
                if let Some(i) = xi {
                    xb[i] = f64::INFINITY;
                }
                if let Some(i) = fi {
                    fb[i] = f64::NAN;
                }
                let mut st = CycleState::default();
                let before = st;
                let e = cycle_block(&t, &xb, &fb, &xb, 0, levels.0, levels.1, &mut st);
                let want = if p == 0 {
                    check_finite("x", &xb).unwrap_err()
                } else {
                    check_finite("F", &fb).unwrap_err()
                };
                // NaN fields compare as text
                assert_eq!(format!("{:?}", e.unwrap_err()), format!("{want:?}"));
                assert_eq!(format!("{st:?}"), format!("{before:?}"));
                // a separate drive (normal recordings): x, then F, then the drive
                let e = cycle_block(&t, &xb, &fb, &fb, 0, levels.0, levels.1, &mut st);
                assert_eq!(format!("{:?}", e.unwrap_err()), format!("{want:?}"));
            }
        }
    }

    #[test]
    fn loop_area_sensitivity_matches_finite_differences() {
        let x = [0.0, 1.0, 2.0, 1.5, 0.3, -0.4, 0.1];
        let f = [0.5, 1.0, 0.2, -0.7, -1.0, 0.0, 0.4];
        let (sf, sx) = loop_area_sensitivity(&x, &f, &[0, 7]).unwrap();
        let area = |x: &[f64], f: &[f64]| crate::masing::loop_area(x, f).unwrap();
        let (mut gf, mut gx) = (0.0, 0.0);
        let h = 1e-6;
        for i in 0..7 {
            let mut f2 = f;
            f2[i] += h;
            let d = (area(&x, &f2) - area(&x, &f)) / h;
            gf += d * d;
            let mut x2 = x;
            x2[i] += h;
            let d = (area(&x2, &f) - area(&x, &f)) / h;
            gx += d * d;
        }
        assert!((sf[0] - gf).abs() < 1e-6 * gf.max(1.0), "{} {}", sf[0], gf);
        assert!((sx[0] - gx).abs() < 1e-6 * gx.max(1.0), "{} {}", sx[0], gx);
        assert!(loop_area_sensitivity(&x, &f, &[3, 2]).is_err());
    }
}
