//! Averages over the cycles of a periodic recording: the phase-bin fold (per-bin and
//! per-cycle-and-bin sums accumulated over chunks), its cycle-to-cycle spread, and time
//! averages between cycle edges (period means).

use crate::error::{check_finite, check_same_len, CoreError};

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
    // t finite and strictly increasing, checked as the walk reads it (NaN fails the
    // comparison): one read of t, not a pass of its own (the walk's chain of additions
    // leaves room for the compares; the pass read t at memory speed); the separate checks
    // name the first failure, before any of the edges (as they did)
    let (ok, means) = period_means_pair_walk(t, f, x, edges);
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
    Ok(means)
}

/// [`period_means_pair`]'s walk over at least two samples (`f` and `x` as long as `t`):
/// whether `t` is finite and strictly increasing (every sample read once: the pairs the
/// trapezoids step over, then the rest), and the means, which are those of checked samples
/// when it is. Edges need not be checked (NaN or decreasing edges give NaN or wrong means,
/// never a panic).
// Index arithmetic: j + 1 < n where j + 1 is taken (trapezoids_checked_until stops there).
#[allow(clippy::arithmetic_side_effects)]
fn period_means_pair_walk(
    t: &[f64],
    f: &[f64],
    x: &[f64],
    edges: &[f64],
) -> (bool, (Vec<f64>, Vec<f64>)) {
    let n = t.len();
    let mut ce_f = Vec::with_capacity(edges.len());
    let mut ce_x = Vec::with_capacity(edges.len());
    let (mut j, mut cf, mut cx) = (0_usize, 0.0_f64, 0.0_f64);
    let mut ok = t[0].is_finite();
    for &e in edges {
        if e <= t[0] {
            ce_f.push(0.0);
            ce_x.push(0.0);
            continue;
        }
        (j, cf, cx, ok) = trapezoids_checked_until(t, (f, x), j, e, (cf, cx), ok);
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
    // the samples after the last step taken (pair j, j + 1 on)
    for w in t[j..].windows(2) {
        ok &= (w[1] > w[0]) & w[1].is_finite();
    }
    let means = |ce: &[f64]| -> Vec<f64> {
        ce.windows(2)
            .zip(edges.windows(2))
            .map(|(c, e)| (c[1] - c[0]) / (e[1] - e[0]))
            .collect()
    };
    (ok, (means(&ce_f), means(&ce_x)))
}

/// [`trapezoids_until`] checking each pair of samples it steps over (`t[j + 1]` finite and
/// above `t[j]`, into `ok`): the same sums, bit for bit.
// Index arithmetic: j + 1 < n, the shortest slice's length.
#[allow(clippy::arithmetic_side_effects)]
#[inline(never)]
fn trapezoids_checked_until(
    t: &[f64],
    (f, x): (&[f64], &[f64]),
    mut j: usize,
    e: f64,
    (mut cf, mut cx): (f64, f64),
    mut ok: bool,
) -> (usize, f64, f64, bool) {
    let n = t.len().min(f.len()).min(x.len());
    while j + 1 < n && t[j + 1] <= e {
        ok &= (t[j + 1] > t[j]) & t[j + 1].is_finite();
        let dt = t[j + 1] - t[j];
        cf += 0.5 * (f[j + 1] + f[j]) * dt;
        cx += 0.5 * (x[j + 1] + x[j]) * dt;
        j += 1;
    }
    (j, cf, cx, ok)
}

/// [`period_means_pair`]'s cumulative trapezoid integrals `(cf, cx)` of `F` and `x` carried
/// from sample `j` over the samples up to the last at or before `e`: returns the new `j` and
/// sums. Its own function: inlined into the loop over the edges, the two sums lived on the
/// stack (a store and a load in their chain every sample, 5 ns a sample against about 1).
// Index arithmetic: j + 1 < n, the shortest slice's length.
#[allow(clippy::arithmetic_side_effects)]
#[inline(never)]
pub(crate) fn trapezoids_until(
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

#[cfg(test)]
mod tests {
    use super::*;

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
    fn period_means_pair_finds_a_bad_time_wherever_its_walk_reads_it() {
        // t checked as the trapezoids are walked: a NaN, an infinity, a repeated or a falling
        // stamp at any sample (before the first edge, between edges, after the last, the
        // first sample) is refused as period_means refuses it, naming the same sample
        let n = 40;
        let t0: Vec<f64> = (0..n).map(|i| i as f64 * 0.25).collect();
        let f: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).cos()).collect();
        let edges = [1.1, 2.0, 4.6, 7.3];
        let (mf, mx) = period_means_pair(&t0, &f, &x, &edges).unwrap();
        assert_eq!(mf, period_means(&t0, &f, &edges).unwrap());
        assert_eq!(mx, period_means(&t0, &x, &edges).unwrap());
        for i in 0..n {
            let prev = if i > 0 { t0[i - 1] } else { -1.0 };
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, prev, prev - 0.1] {
                let mut t = t0.clone();
                t[i] = bad;
                let want = period_means(&t, &f, &edges);
                let got = period_means_pair(&t, &f, &x, &edges);
                if i == 0 && bad.is_finite() {
                    assert!(want.is_ok() && got.is_ok(), "{i} {bad}");
                    continue;
                }
                assert!(want.is_err(), "{i} {bad}");
                // (by their text: an error holding a NaN is not equal to itself)
                let (got, want) = (got.unwrap_err(), want.unwrap_err());
                assert_eq!(format!("{got:?}"), format!("{want:?}"), "{i} {bad}");
            }
        }
    }
}
