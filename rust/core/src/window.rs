//! The per-sample work of one analysis window of a tangential recording, in one pass.
//!
//! [`fold_window`] folds the window's samples into phase bins (the cycle averaging) and, in
//! the same pass over the samples (one release of the Python lock), derives everything else
//! the analysis needs of them: the cycle bounds; each cycle's loop area `∮ F dx` and the
//! area's noise sensitivities; the cycle-to-cycle spread of the per-cycle bin means and each cycle's half ranges. No
//! per-cycle-and-bin table is kept: a cycle's bin (a "cell") is a contiguous run of samples
//! (the phase never decreases), so each cell's mean is complete when the run ends and goes
//! straight into its bin's moments (sums shifted by the bin's first cell mean, with the
//! co-moment with the phase that the spread's phase correction needs; see `Bin`). Memory: a
//! few values per bin and per cycle. The
//! period means of `F` and `x` between the peaks ([`crate::fold::period_means_pair`]'s
//! numbers, whose two running integrals stay in registers in a loop of their own) are
//! carried over each cycle's samples as the cycle completes, after its loop area, while the
//! samples are in cache (`window/period.rs`), instead of a pass over the window afterwards.
//!
//! The numbers are those of the separate kernels ([`fold_phase`](crate::fold::fold_phase),
//! [`fold_spread`](crate::fold::fold_spread), [`loop_areas`](crate::loop_area::loop_areas),
//! [`loop_area_sensitivity`](crate::loop_area::loop_area_sensitivity),
//! [`period_means`](crate::fold::period_means)) to rounding: the per-bin sums and the
//! period means bit for bit, the rest to ~1e-12 relative (another summation order).
//!
//! The detrending pass that precedes the fold ([`detrend_pair_scan_into`], [`WindowScan`]) is in
//! `window/detrend.rs`, a fold's cell and segment records in `window/cell.rs`, the period
//! means' running state in `window/period.rs`, the tests in `window/tests.rs`.

use crate::error::{check_finite, check_same_len, CoreError};

/// One window folded (see the module docs). Per bin: samples, `Σx`, `ΣF`, `Σφ`, `Σφ²`,
/// `Σx²`, `Σt` (φ the phase within the cycle), and the cycle-to-cycle spread of the per-cycle
/// bin means of x and F (phase-corrected as [`crate::fold::fold_spread`]; NaN below two
/// cycles with samples in the bin). Per cycle: its first sample (-1: none), bounds (`n + 1`
/// sample indices), loop area (NaN below 3 samples), `Σ coef_F²`, `Σ coef_x²` of the area,
/// half ranges of its bin means of x and F (NaN without samples). Per period between
/// consecutive `edges`: the mean of F and of x.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowFold {
    pub n_bins: usize,
    pub n_cycles: usize,
    pub count: Vec<f64>,
    pub sum_x: Vec<f64>,
    pub sum_f: Vec<f64>,
    pub sum_phase: Vec<f64>,
    pub sum_phase2: Vec<f64>,
    pub sum_xx: Vec<f64>,
    pub sum_t: Vec<f64>,
    pub x_std: Vec<f64>,
    pub f_std: Vec<f64>,
    pub first: Vec<i64>,
    pub bounds: Vec<usize>,
    pub energy: Vec<f64>,
    pub sens_f: Vec<f64>,
    pub sens_x: Vec<f64>,
    pub amplitude: Vec<f64>,
    pub force_range: Vec<f64>,
    pub mean_f: Vec<f64>,
    pub mean_x: Vec<f64>,
}

/// One phase bin during the pass: its sample sums (in sample order: `Σx`, `ΣF`, `Σφ`, `Σφ²`,
/// `Σx²`, `Σt`), its samples, and the moments of its per-cycle means (the cells' means of x,
/// F and φ) as sums shifted by the bin's first cell mean: cycles, the shift, the sums of the
/// shifted means, of their squares and of their products with the shifted phase. The shifted
/// sums are independent additions (Welford's running means were a dependent chain of
/// divisions and products a cell, which runs every few samples); the shift keeps them
/// accurate: a shifted mean is the exact difference of two close doubles, so an offset far
/// above the spread (x around 1e3 varying by 1e-6) costs no digits, where Welford's running
/// mean rounded at the offset's scale.
#[derive(Debug, Clone, Copy, Default)]
struct Bin {
    sums: [f64; 6],
    samples: f64,
    k: f64,
    /// the shift of x, F, φ (φ's twice: the lanes of `d`)
    shift: [f64; 4],
    /// `[Σdx, Σdf, Σdp, -]`, `[Σdx², Σdf², Σdp², -]`, `[Σdx·dp, Σdf·dp, -, -]` (each cell
    /// adds the four lanes `[dx, df, dp, dp]`, their squares and their products with dp: three
    /// vector additions; the lanes marked `-` are not read)
    d: [[f64; 4]; 3],
}

impl Bin {
    /// A complete cell of `n` samples with sums `cx`, `cf`, `cp` of x, F, φ: its means into
    /// the bin's moments; returns the means of x and F (the cycle's ranges).
    #[inline(always)]
    fn add_cell(&mut self, n: f64, cx: f64, cf: f64, cp: f64) -> (f64, f64) {
        // the divisions of fold_spread's cell means (the same numbers)
        let m = [cx / n, cf / n, cp / n, cp / n];
        if self.k == 0.0 {
            self.shift = m;
        }
        let v = [
            m[0] - self.shift[0],
            m[1] - self.shift[1],
            m[2] - self.shift[2],
            m[3] - self.shift[3],
        ];
        let dp = v[2];
        self.k += 1.0;
        let [d0, d1, d2] = &mut self.d;
        for l in 0..4 {
            d0[l] += v[l];
            d1[l] += v[l] * v[l];
            d2[l] += v[l] * dp;
        }
        (m[0], m[1])
    }

    /// Sample standard deviations of `mx - gx·φ` and `mf - gf·φ` over the cycles (NaN below
    /// two cycles, or where a slope is NaN: an empty neighbour bin, as fold_spread).
    fn spread(&self, gx: f64, gf: f64) -> (f64, f64) {
        let k = self.k;
        if k < 2.0 {
            return (f64::NAN, f64::NAN);
        }
        let [[d0, d1, d2, _], [d3, d4, d5, _], [d6, d7, _, _]] = self.d;
        let d = [d0, d1, d2, d3, d4, d5, d6, d7];
        // centred moments of the shifted means: the squares, the co-moments with φ
        let m2p = d[5] - d[2] * d[2] / k;
        let one = |sd: f64, sdd: f64, sdp: f64, g: f64| {
            let m2 = sdd - sd * sd / k;
            let c = sdp - sd * d[2] / k;
            let var = (m2 - 2.0 * g * c + g * g * m2p) / (k - 1.0);
            if var.is_nan() {
                f64::NAN
            } else {
                var.max(0.0).sqrt()
            }
        };
        (one(d[0], d[3], d[6], gx), one(d[1], d[4], d[7], gf))
    }
}

/// Neumaier (compensated) sum: the loop areas' summation (as [`crate::masing::loop_area`]).
#[derive(Debug, Clone, Copy, Default)]
struct Neumaier {
    sum: f64,
    comp: f64,
}

impl Neumaier {
    #[inline(always)]
    fn add(&mut self, term: f64) {
        let t = self.sum + term;
        // (sum - t) + term when |sum| >= |term|, else (term - t) + sum: as selects, not a
        // branch (the same numbers; the branch was mispredicted where the area crosses zero)
        let first = self.sum.abs() >= term.abs();
        let (big, small) = if first {
            (self.sum, term)
        } else {
            (term, self.sum)
        };
        self.comp += (big - t) + small;
        self.sum = t;
    }
}

/// Lanes of the cycle sums (independent chains of additions).
const LANES: usize = 4;

/// Terms a block of [`cycle_area`]'s sums (a multiple of [`LANES`]).
const AREA_BLOCK: usize = 64;

/// The loop area of one cycle's samples (shoelace, scaled and compensated as
/// [`crate::masing::loop_area`]) and its noise sensitivities: `(area, Σ coef_F², Σ coef_x²)`,
/// the area in the samples' units; `ux`, `uf` scale x and F, `fm` centres the scaled F. Run
/// once a cycle is complete, on samples still in cache. The sums run in four lanes (sample
/// `i` in lane `i mod 4`), each area lane compensated (Knuth's two-sum: the exact rounding
/// error of each addition, what Neumaier's ordered one gives, without its compare and
/// selects) and the lanes combined by a compensated sum: the area to ~1e-16 of its terms'
/// scale, as the sequential Neumaier sum, in independent chains of additions (the
/// sequential sum was one chain of dependent additions a sample).
// Index arithmetic: m >= 3, so m - 1 and m - 2 are samples of the cycle.
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
fn cycle_area(x: &[f64], f: &[f64], ux: f64, uf: f64, fm: f64, scale: f64) -> (f64, f64, f64) {
    let m = x.len().min(f.len());
    if m < 3 {
        return (f64::NAN, 0.0, 0.0);
    }
    let (x, f) = (&x[..m], &f[..m]);
    // the shoelace terms 0.5·(F[i-1] + F[i])·(x[i] - x[i-1]) of the scaled samples, i >= 1
    let term = |xp: f64, xs: f64, fp: f64, fs: f64| {
        let (xp, xs, fp, fs) = (xp * ux, xs * ux, fp * uf - fm, fs * uf - fm);
        0.5 * (fp + fs) * (xs - xp)
    };
    let (mut s, mut c) = ([0.0_f64; LANES], [0.0_f64; LANES]);
    let (xa, xb, fa, fb) = (&x[..m - 1], &x[1..], &f[..m - 1], &f[1..]);
    // by blocks: the terms in a loop of their own (a map over four shifted slices, which
    // vectorises whole; computed inside the lanes' loop it was built two at a time with
    // shuffles, a fifth of the fold's time), then the lanes' compensated sums over them
    // (the same terms in the same lanes and order)
    // (each sample scaled once a block, into `sx`, `sf`: the numbers term's products make,
    // where a term scaled both of its samples)
    let full = (m - 1) / LANES * LANES;
    let mut buf = [0.0_f64; AREA_BLOCK];
    let (mut sx, mut sf) = ([0.0_f64; AREA_BLOCK + 1], [0.0_f64; AREA_BLOCK + 1]);
    let mut a0 = 0_usize;
    while a0 < full {
        let b0 = (a0 + AREA_BLOCK).min(full);
        let k = b0 - a0;
        // samples a0..=b0 (b0 <= m - 1)
        for ((ox, of), (&xv, &fv)) in sx[..=k]
            .iter_mut()
            .zip(&mut sf[..=k])
            .zip(x[a0..=b0].iter().zip(&f[a0..=b0]))
        {
            *ox = xv * ux;
            *of = fv * uf - fm;
        }
        let src = sx[..k].iter().zip(&sx[1..=k]).zip(&sf[..k]).zip(&sf[1..=k]);
        for (o, (((&xp, &xs), &fp), &fs)) in buf[..k].iter_mut().zip(src) {
            *o = 0.5 * (fp + fs) * (xs - xp);
        }
        for v4 in buf[..k].chunks_exact(LANES) {
            for l in 0..LANES {
                let v = v4[l];
                // two-sum: t + e = s + v exactly
                let t = s[l] + v;
                let bb = t - s[l];
                c[l] += (s[l] - (t - bb)) + (v - bb);
                s[l] = t;
            }
        }
        a0 = b0;
    }
    let mut a = Neumaier::default();
    for &v in &s {
        a.add(v);
    }
    a.comp += c.iter().sum::<f64>();
    let done = (m - 1) / LANES * LANES;
    for i in done..m - 1 {
        a.add(term(xa[i], xb[i], fa[i], fb[i]));
    }
    // the closing term, last sample to first
    a.add(term(x[m - 1], x[0], f[m - 1], f[0]));
    // each sample's neighbours i - 1 and i + 1 as four slices of one length
    let (xa, xb, fa, fb) = (&x[..m - 2], &x[2..], &f[..m - 2], &f[2..]);
    let (mut sf, mut sx) = ([0.0_f64; LANES], [0.0_f64; LANES]);
    let full = (m - 2) / LANES * LANES;
    let (mut pf, mut px) = ([0.0_f64; AREA_BLOCK], [0.0_f64; AREA_BLOCK]);
    let mut a0 = 0_usize;
    while a0 < full {
        let b0 = (a0 + AREA_BLOCK).min(full);
        let k = b0 - a0;
        let src = xa[a0..b0]
            .iter()
            .zip(&xb[a0..b0])
            .zip(&fa[a0..b0])
            .zip(&fb[a0..b0]);
        for ((of, ox), (((&xp, &xs), &fp), &fs)) in pf[..k].iter_mut().zip(&mut px[..k]).zip(src) {
            let cf = 0.5 * (xp - xs);
            let cx = 0.5 * (fs - fp);
            *of = cf * cf;
            *ox = cx * cx;
        }
        for (qf, qx) in pf[..k].chunks_exact(LANES).zip(px[..k].chunks_exact(LANES)) {
            for l in 0..LANES {
                sf[l] += qf[l];
                sx[l] += qx[l];
            }
        }
        a0 = b0;
    }
    let (mut sf, mut sx) = (
        (sf[0] + sf[1]) + (sf[2] + sf[3]),
        (sx[0] + sx[1]) + (sx[2] + sx[3]),
    );
    for i in (m - 2) / LANES * LANES..m - 2 {
        let cf = 0.5 * (xa[i] - xb[i]);
        let cx = 0.5 * (fb[i] - fa[i]);
        sf += cf * cf;
        sx += cx * cx;
    }
    // the first sample (neighbours: the last and the second), then the last (the one before
    // it and the first)
    let (c0f, c0x) = (0.5 * (x[m - 1] - x[1]), 0.5 * (f[1] - f[m - 1]));
    let (c1f, c1x) = (0.5 * (x[m - 2] - x[0]), 0.5 * (f[0] - f[m - 2]));
    (
        (a.sum + a.comp) * scale,
        sf + c0f * c0f + c1f * c1f,
        sx + c0x * c0x + c1x * c1x,
    )
}

crate::simd::dispatch! {
    /// [`cycle_area`] compiled for `level`, out of line: run once a cycle completes, it
    /// keeps its own registers. Inlined into the fold's pass, its blocks of terms added to
    /// the pass's register pressure, and the run loop kept one pair of the cell's running
    /// sums on the stack (a store and a load in those sums' chains every sample).
    #[inline(never)]
    fn cycle_area_at(x: &[f64], f: &[f64], ux: f64, uf: f64, fm: f64, scale: f64) -> (f64, f64, f64) = cycle_area;
}

fn bad(name: &'static str, value: f64, reason: &'static str) -> CoreError {
    CoreError::InvalidParameter {
        name,
        value,
        reason,
    }
}

fn check_knots(kt: &[f64], kp: &[f64], n_cycles: usize) -> Result<(), CoreError> {
    check_same_len("knot_t", kt.len(), "knot_phase", kp.len())?;
    check_finite("knot_t", kt)?;
    check_finite("knot_phase", kp)?;
    if kt.len() < 2 {
        return Err(CoreError::Empty { name: "knot_t" });
    }
    for (i, w) in kt.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(CoreError::NotIncreasing {
                name: "knot_t",
                index: i.saturating_add(1),
                value: w[1],
                prev: w[0],
            });
        }
    }
    let top = kp.last().copied().unwrap_or(0.0);
    if kp.first().is_some_and(|&p| p < 0.0)
        || top > n_cycles as f64
        || kp.windows(2).any(|w| w[1] < w[0])
    {
        return Err(bad(
            "knot_phase",
            top,
            "knot phases must be non-decreasing, in [0, n_cycles]",
        ));
    }
    Ok(())
}

/// Checks `t` (strictly increasing), `x`, `F` (finite, same length) and `edges`
/// (non-decreasing); returns the largest `|x|` and `|F|` and the mean of F.
fn check_samples(t: &[f64], x: &[f64], f: &[f64], edges: &[f64]) -> Result<[f64; 3], CoreError> {
    check_same_len("t", t.len(), "x", x.len())?;
    check_same_len("t", t.len(), "F", f.len())?;
    if let Some(v) = clean_samples(t, x, f) {
        check_finite("edges", edges)?;
        check_edges(edges)?;
        return Ok(v);
    }
    // something is wrong: the checks one by one name it
    check_finite("t", t)?;
    check_finite("x", x)?;
    check_finite("F", f)?;
    check_finite("edges", edges)?;
    if t.len() < 2 {
        return Err(CoreError::Empty { name: "t" });
    }
    for (i, w) in t.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(CoreError::NotIncreasing {
                name: "t",
                index: i.saturating_add(1),
                value: w[1],
                prev: w[0],
            });
        }
    }
    check_edges(edges)?;
    let (_, sx, _) = finite_max_abs(x);
    let (_, sf, sum_f) = finite_max_abs(f);
    Ok([sx, sf, force_centre(f, sum_f, sf)])
}

/// The mean of `F / sf`, the centre of the scaled force in the loop areas (any value near the
/// mean serves: the shoelace sum of a closed loop does not depend on it but for rounding):
/// from the sum of F (`sum_f`, summed with the channel's check) where that is finite, else
/// summed over `F / sf` (no overflow).
fn force_centre(f: &[f64], sum_f: f64, sf: f64) -> f64 {
    if sf <= 0.0 {
        return 0.0;
    }
    let n = f.len() as f64;
    if sum_f.is_finite() {
        sum_f / sf / n
    } else {
        f.iter().map(|&v| v / sf).sum::<f64>() / n
    }
}

fn check_edges(edges: &[f64]) -> Result<(), CoreError> {
    for (i, w) in edges.windows(2).enumerate() {
        if w[1] < w[0] {
            return Err(CoreError::NotIncreasing {
                name: "edges",
                index: i.saturating_add(1),
                value: w[1],
                prev: w[0],
            });
        }
    }
    Ok(())
}

/// Whether every value of `v` is finite, the largest `|v|` (0 for none) and the sum of `v`
/// (four lanes; inf or NaN where it overflows): four lanes of compare-selects (`f64::max`'s
/// NaN handling kept the loop scalar).
// Index arithmetic: k < 4.
#[allow(clippy::arithmetic_side_effects)]
fn finite_max_abs(v: &[f64]) -> (bool, f64, f64) {
    let mut m = [0.0_f64; 4];
    let mut s = [0.0_f64; 4];
    let mut ok = [true; 4];
    let mut chunks = v.chunks_exact(4);
    for c in &mut chunks {
        for k in 0..4 {
            let a = c[k].abs();
            m[k] = if a > m[k] { a } else { m[k] };
            s[k] += c[k];
            ok[k] &= c[k].is_finite();
        }
    }
    for (k, &x) in chunks.remainder().iter().enumerate() {
        let a = x.abs();
        m[k] = if a > m[k] { a } else { m[k] };
        s[k] += x;
        ok[k] &= x.is_finite();
    }
    let big = m.iter().fold(0.0_f64, |a, &b| if b > a { b } else { a });
    (ok.iter().all(|&o| o), big, (s[0] + s[1]) + (s[2] + s[3]))
}

/// [`check_samples`]' checks and numbers in a vectorised pass a channel (the maxima, and the
/// sum of F for its centre in the same pass); None when a check fails (the separate checks
/// then name the first failure).
// bitwise ands: no early exit, so the loop over t vectorises
#[allow(clippy::arithmetic_side_effects, clippy::needless_bitwise_bool)]
fn clean_samples(t: &[f64], x: &[f64], f: &[f64]) -> Option<[f64; 3]> {
    if t.len() < 2 {
        return None;
    }
    // finite and strictly increasing t (NaN fails every comparison); finite x, F and their
    // largest magnitudes: a pass a channel, each vectorised (the largest of magnitudes is
    // the same number in any order)
    let ok = t[0].is_finite()
        && t[..t.len() - 1]
            .iter()
            .zip(&t[1..])
            .fold(true, |o, (&a, &b)| o & (b > a) & b.is_finite());
    let (ok_x, sx, _) = finite_max_abs(x);
    let (ok_f, sf, sum_f) = finite_max_abs(f);
    let ok = ok && ok_x && ok_f;
    if !ok {
        return None;
    }
    Some([sx, sf, force_centre(f, sum_f, sf)])
}

/// A complete cell (`n` samples, sums `cx`, `cf`, `cp` of x, F, φ) of a bin whose sample
/// sums are now `cur`: into the bin and the cycle's ranges `r` of cell means.
#[inline(always)]
fn flush_cell(
    bin: &mut Bin,
    r: &mut [f64; 4],
    n: f64,
    (cx, cf, cp): (f64, f64, f64),
    cur: &[f64; 6],
) {
    bin.sums = *cur;
    bin.samples += n;
    let (mx, mf) = bin.add_cell(n, cx, cf, cp);
    // the largest of the means and of their negations (the smallest, negated: the same
    // selections, as `-m > -r` is `m < r`) by one rule in four lanes, f64::max without its
    // NaN handling (a NaN mean is skipped): one compare-select of four lanes (the two
    // maxima and two minima were a compare and a mask shuffle each, a cell)
    let v = [mx, mf, -mx, -mf];
    for l in 0..4 {
        r[l] = if v[l] > r[l] { v[l] } else { r[l] };
    }
}

/// `n_bins >= 1`, and `n_cycles × n_bins` cells that fit.
fn check_sizes(n_bins: usize, n_cycles: usize) -> Result<(), CoreError> {
    if n_bins == 0 {
        return Err(bad("n_bins", 0.0, "must be >= 1"));
    }
    if n_cycles > (1 << 32) || n_bins > (1 << 24) {
        return Err(bad(
            "n_cycles",
            n_cycles as f64,
            "n_cycles × n_bins is too large",
        ));
    }
    Ok(())
}

impl WindowFold {
    /// Zero sums, NaN per-cycle quantities, no bounds or period means yet.
    fn empty(n_bins: usize, n_cycles: usize) -> Self {
        let z = |k| vec![0.0_f64; k];
        let (nb, nc) = (n_bins, n_cycles);
        WindowFold {
            n_bins,
            n_cycles,
            count: z(nb),
            sum_x: z(nb),
            sum_f: z(nb),
            sum_phase: z(nb),
            sum_phase2: z(nb),
            sum_xx: z(nb),
            sum_t: z(nb),
            x_std: z(nb),
            f_std: z(nb),
            first: vec![-1; nc],
            bounds: Vec::new(),
            energy: vec![f64::NAN; nc],
            sens_f: z(nc),
            sens_x: z(nc),
            amplitude: vec![f64::NAN; nc],
            force_range: vec![f64::NAN; nc],
            mean_f: Vec::new(),
            mean_x: Vec::new(),
        }
    }
}

/// Fold `(t, x, F)` (one window, `t` strictly increasing) by the phase knots `(kt, kp)` into
/// `n_bins` bins per cycle over `n_cycles` cycles, with the phases and bins of
/// [`crate::fold::fold_phase`], and derive the per-cycle quantities and period means (see
/// [`WindowFold`]) in the same pass. The samples folded are those with
/// `kt[0] <= t < kt[last]`; a cycle's samples run from its first folded sample to the next
/// cycle's (the last to the first sample at or after `kt[last]`).
// Index arithmetic: b < n_bins and c < n_cycles (checked against the allocations), j + 1 <
// the knots' length (t < kt[last] inside the loop), i < end <= n inside the loops.
// Not inlined: with fat LTO the binding inlined it into its wrapper, where the fold's loop
// kept more of its state on the stack (26 against 22 ms a window of 2^20 samples).
pub fn fold_window(
    t: &[f64],
    x: &[f64],
    f: &[f64],
    kt: &[f64],
    kp: &[f64],
    n_bins: usize,
    n_cycles: usize,
    edges: &[f64],
) -> Result<WindowFold, CoreError> {
    fold_window_with(t, x, f, (kt, kp), (n_bins, n_cycles), edges, None)
}

/// [`fold_window`] of samples a pass made by [`detrend_pair_scan_into`] found clean: `scan`
/// is its [`WindowScan`], whose numbers (the largest `|x|` and `|F|`, the force's centre) are
/// those the fold's own check pass finds, so that pass is left out (the knots, the edges and
/// the lengths are still checked). A scan that found something wrong is refused: the caller
/// folds with [`fold_window`], whose checks name it.
///
/// # Errors
/// As [`fold_window`], and [`CoreError::InvalidParameter`] for a scan that is not clean or
/// of another length.
pub fn fold_window_scanned(
    t: &[f64],
    x: &[f64],
    f: &[f64],
    (kt, kp): (&[f64], &[f64]),
    (n_bins, n_cycles): (usize, usize),
    edges: &[f64],
    scan: &WindowScan,
) -> Result<WindowFold, CoreError> {
    if !scan.clean || scan.n != t.len() {
        return Err(bad(
            "scan",
            scan.n as f64,
            "not a clean scan of these samples: fold with fold_window",
        ));
    }
    fold_window_with(
        t,
        x,
        f,
        (kt, kp),
        (n_bins, n_cycles),
        edges,
        Some([scan.max_abs_x, scan.max_abs_f, scan.force_centre]),
    )
}

/// [`fold_window`], its check pass over the samples left out where `scanned` gives what it
/// finds (`[largest |x|, largest |F|, centre of F]`).
fn fold_window_with(
    t: &[f64],
    x: &[f64],
    f: &[f64],
    (kt, kp): (&[f64], &[f64]),
    (n_bins, n_cycles): (usize, usize),
    edges: &[f64],
    scanned: Option<[f64; 3]>,
) -> Result<WindowFold, CoreError> {
    fold_window_at(
        crate::simd::level(),
        (t, x, f),
        (kt, kp),
        (n_bins, n_cycles),
        edges,
        scanned,
    )
}

/// [`fold_window_with`] with its pass compiled for `level` ([`crate::simd`]): the same
/// numbers at every level (plain Rust in one order of operations; the tests compare the
/// levels). AVX-512's 32 vector registers hold the open cell's nine running sums and the
/// knot segment's numbers together.
#[doc(hidden)]
pub fn fold_window_at(
    level: crate::simd::Level,
    (t, x, f): (&[f64], &[f64], &[f64]),
    (kt, kp): (&[f64], &[f64]),
    (n_bins, n_cycles): (usize, usize),
    edges: &[f64],
    scanned: Option<[f64; 3]>,
) -> Result<WindowFold, CoreError> {
    check_sizes(n_bins, n_cycles)?;
    check_knots(kt, kp, n_cycles)?;
    let scales = match scanned {
        Some(v) => {
            check_same_len("t", t.len(), "x", x.len())?;
            check_same_len("t", t.len(), "F", f.len())?;
            check_finite("edges", edges)?;
            check_edges(edges)?;
            v
        }
        None => check_samples(t, x, f, edges)?,
    };
    crate::simd::run(
        level,
        FoldPass {
            txf: (t, x, f),
            knots: (kt, kp),
            sizes: (n_bins, n_cycles),
            edges,
            scales,
            level,
        },
    )
}

/// [`fold_window_at`]'s pass over checked samples as a [`crate::simd::Kernel`].
#[derive(Clone, Copy)]
struct FoldPass<'a> {
    txf: (&'a [f64], &'a [f64], &'a [f64]),
    knots: (&'a [f64], &'a [f64]),
    sizes: (usize, usize),
    edges: &'a [f64],
    scales: [f64; 3],
    level: crate::simd::Level,
}

impl crate::simd::Kernel for FoldPass<'_> {
    type Output = Result<WindowFold, CoreError>;

    #[inline(always)]
    fn run_at(self) -> Self::Output {
        fold_pass(self)
    }
}

/// The fold's pass over checked samples (see [`fold_window`]).
// Index arithmetic: as fold_window's.
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
fn fold_pass(p: FoldPass<'_>) -> Result<WindowFold, CoreError> {
    let FoldPass {
        txf: (t, x, f),
        knots: (kt, kp),
        sizes: (n_bins, n_cycles),
        edges,
        scales: [sx, sf, fm],
        level,
    } = p;
    let (nb, nc) = (n_bins, n_cycles);
    let mut w = WindowFold::empty(nb, nc);
    let mut bins = vec![Bin::default(); nb];
    // per cycle: the largest and smallest cell mean of x, of F
    let mut ranges = vec![NO_RANGE; nc];
    // the open cell's cycle's ranges (`ranges[cc]` while it is open)
    let mut rng = NO_RANGE;
    // scales of the loop areas (as loop_area, over the window: no overflow of the products)
    let (ux, uf) = (
        if sx > 0.0 { 1.0 / sx } else { 0.0 },
        if sf > 0.0 { 1.0 / sf } else { 0.0 },
    );
    let area_scale = sx * sf;
    let (t0, t1) = (kt[0], kt[kt.len() - 1]);
    // the samples folded: [start, end) (t increasing), less those past the last cycle (a
    // suffix: the phase never decreases)
    let start = t.partition_point(|&v| v < t0);
    let end = t.partition_point(|&v| v < t1);
    let (t_all, x_all, f_all) = (t, x, f);
    let (t, x, f) = (&t[..end], &x[..end], &f[..end]);
    let mut j = 0_usize;
    let mut seg = Segment::of(kt, kp, 0);
    let mut last_ph = f64::NEG_INFINITY;
    // the open cell (cycle cc, bin cb) is tracked by the phase intervals it covers, [c_lo,
    // c_hi) and, within the cycle, [b_lo, b_hi) of frac·n_bins: a sample inside both is in
    // the same cell, with no float-to-integer conversion; the indices are those of `floor`
    // as fold_phase's, bit for bit
    let (mut c_lo, mut c_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut b_lo, mut b_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    // the current cycle; the open cell's cycle and bin (MAX: none yet)
    let mut cyc = 0_usize;
    let (mut cc, mut cb) = (usize::MAX, usize::MAX);
    let nbf = nb as f64;
    // the open cell's first sample and sums of x, F, φ; its bin's sample sums, kept in
    // registers while the cell's run of samples lasts (the same additions in the same order
    // as adding into the bin sample by sample)
    let mut cell_start = start;
    let mut cell = Cell::default();
    // the open cycle's first sample, and the end of the folded samples
    let mut a0 = start;
    let mut a1 = end;
    let mut area_cycle: Option<usize> = None;
    let mut pm = PeriodMeans::new(edges.len());
    // the phase of sample i where the inner loop below computed it (in the same knot
    // segment, so as this path would), else -1 (phases are >= kp[0] >= 0)
    let mut carried = -1.0_f64;
    let mut i = start;
    while i < end {
        // a sample that may start a knot segment, a cycle or a cell
        let ti = t[i];
        let (ph, clamped) = if carried >= 0.0 {
            (carried, false)
        } else {
            if ti >= seg.k_hi {
                // ti < t1 = kt[last]: j + 1 stays a knot
                while kt[j + 1] <= ti {
                    j += 1;
                }
                seg = Segment::of(kt, kp, j);
            }
            let raw = if ti == seg.k_lo {
                seg.p_lo
            } else {
                seg.phase(ti)
            };
            // never back (rounding at a knot): each cell stays one run of samples
            let clamped = raw < last_ph;
            (if clamped { last_ph } else { raw }, clamped)
        };
        carried = -1.0;
        last_ph = ph;
        if !(ph >= c_lo && ph < c_hi) {
            // another cycle: ph >= kp[0] >= 0 and finite, below 2^33, so the conversion is
            // floor
            let c = ph as usize;
            if c >= nc {
                // past the last cycle, as every later sample
                a1 = i;
                break;
            }
            c_lo = c as f64;
            c_hi = c_lo + 1.0;
            cyc = c;
            (b_lo, b_hi) = (f64::INFINITY, f64::NEG_INFINITY);
            if w.first[c] < 0 {
                w.first[c] = i64::try_from(i).unwrap_or(i64::MAX);
            }
            if let Some(ac) = area_cycle {
                (w.energy[ac], w.sens_f[ac], w.sens_x[ac]) =
                    cycle_area_at(level, &x[a0..i], &f[a0..i], ux, uf, fm, area_scale);
                // the period means' integrals over the same samples, still in cache
                pm.advance((t_all, f_all, x_all), edges, Some(i - 1));
            }
            area_cycle = Some(c);
            a0 = i;
        }
        let frac = ph - c_lo;
        let g = frac * nbf;
        if !(g >= b_lo && g < b_hi) {
            // another bin (or cycle): the cell is complete
            let b;
            (b, b_lo, b_hi) = next_bin(g, b_hi, cb, nb);
            if cb != usize::MAX {
                let n = (i - cell_start) as i64 as f64;
                cell.flush(&mut bins[cb], &mut rng, n);
            }
            if cc != cyc {
                // the open cycle's ranges in registers (in `ranges[cc]` each cell's update
                // was a masked store the next cell's load waited on)
                if cc != usize::MAX {
                    ranges[cc] = rng;
                }
                rng = ranges[cyc];
            }
            cc = cyc;
            cb = b;
            cell = Cell {
                cur: bins[cb].sums,
                ..Cell::default()
            };
            cell_start = i;
        }
        cell.add(x[i], f[i], frac, ti);
        i += 1;
        if clamped {
            // the next sample's phase may need the clamp too
            continue;
        }
        // The samples that follow in the same knot segment, cycle and bin. Within a segment
        // the phase is a monotone function of t (so no clamp: this sample was not clamped),
        // and g < g_hi places a sample in the cell: g >= b_lo (monotone) and frac < 1
        // (frac >= 1 gives g >= n_bins); the last bin's edge n_bins is its cycle's end but
        // for rounding, which the path above decides.
        let taken = i;
        loop {
            let g_hi = if b_hi > nbf { nbf } else { b_hi };
            let ph;
            (i, ph) = cell.run((t, x, f), i, end, &seg, (c_lo, nbf, g_hi));
            if ph < 0.0 {
                break;
            }
            // sample i is past the cell: where it starts the next bin of the same cycle (not
            // the last bin), the cell changes here as the path above would change it (there
            // ph = carried, not clamped; frac < 1 as g < b_hi + 1 <= n_bins - 1, so the same
            // cycle; next_bin's first case), else that path takes it
            let frac = ph - c_lo;
            let g = frac * nbf;
            if !(g < b_hi + 1.0 && cb + 2 < nb) {
                carried = ph;
                break;
            }
            let n = (i - cell_start) as i64 as f64;
            cell.flush(&mut bins[cb], &mut rng, n);
            cb += 1;
            (b_lo, b_hi) = (b_hi, b_hi + 1.0);
            cell = Cell {
                cur: bins[cb].sums,
                ..Cell::default()
            };
            cell_start = i;
            cell.add(x[i], f[i], frac, t[i]);
            i += 1;
        }
        if i > taken {
            // the phase of the last sample taken (run's expression, so its number)
            last_ph = seg.phase(t[i - 1]);
        }
    }
    if cb != usize::MAX {
        let n = (a1 - cell_start) as i64 as f64;
        cell.flush(&mut bins[cb], &mut rng, n);
        ranges[cc] = rng;
    }
    if let Some(ac) = area_cycle {
        (w.energy[ac], w.sens_f[ac], w.sens_x[ac]) =
            cycle_area_at(level, &x[a0..a1], &f[a0..a1], ux, uf, fm, area_scale);
    }
    finish(
        &mut w,
        &bins,
        &ranges,
        (t_all, f_all, x_all, edges),
        end,
        pm,
    )?;
    Ok(w)
}

/// [`fold_window`]'s last steps after the pass over the samples: the bin sums into `w`, the
/// loop-area check, the period means, the spread, the per-cycle ranges and the bounds.
// Index arithmetic: b < n_bins, the bins' and sums' length.
#[allow(clippy::arithmetic_side_effects)]
fn finish(
    w: &mut WindowFold,
    bins: &[Bin],
    ranges: &[[f64; 4]],
    (t_all, f_all, x_all, edges): (&[f64], &[f64], &[f64], &[f64]),
    end: usize,
    pm: PeriodMeans,
) -> Result<(), CoreError> {
    let (nb, nc) = (w.n_bins, w.n_cycles);
    for (b, s) in bins.iter().enumerate() {
        w.count[b] = s.samples;
        w.sum_x[b] = s.sums[0];
        w.sum_f[b] = s.sums[1];
        w.sum_phase[b] = s.sums[2];
        w.sum_phase2[b] = s.sums[3];
        w.sum_xx[b] = s.sums[4];
        w.sum_t[b] = s.sums[5];
    }
    for (k, a) in w.energy.iter().enumerate() {
        if a.is_infinite() {
            return Err(CoreError::OutOfRange {
                what: "loop area",
                index: k,
                value: *a,
            });
        }
    }
    // the period means between the edges (period_means_pair's numbers), their integrals
    // carried over each cycle as it completed (window/period.rs) and taken to the end here
    (w.mean_f, w.mean_x) = pm.finish((t_all, f_all, x_all), edges);
    // the spread, phase-corrected by each bin's slope along phase (fold_spread)
    let half_n = nb as f64 / 2.0;
    let mean_of = |s: &[f64], b: usize| s[b] / w.count[b];
    for (b, m) in bins.iter().enumerate() {
        let (bn, bp) = ((b + 1) % nb, (b + nb - 1) % nb);
        let gx = (mean_of(&w.sum_x, bn) - mean_of(&w.sum_x, bp)) * half_n;
        let gf = (mean_of(&w.sum_f, bn) - mean_of(&w.sum_f, bp)) * half_n;
        (w.x_std[b], w.f_std[b]) = m.spread(gx, gf);
    }
    for (c, r) in ranges.iter().enumerate() {
        // [max x, max F, -min x, -min F] (flush_cell); the negations are exact
        let (x_hi, f_hi, x_lo, f_lo) = (r[0], r[1], -r[2], -r[3]);
        if x_hi >= x_lo {
            w.amplitude[c] = 0.5 * (x_hi - x_lo);
            w.force_range[c] = 0.5 * (f_hi - f_lo);
        }
    }
    // bounds: each cycle's first sample, an empty cycle starting where the next one does
    let mut bounds = vec![end; nc + 1];
    let mut next = end;
    for (o, &fi) in bounds.iter_mut().zip(&w.first).rev() {
        if let Ok(v) = usize::try_from(fi) {
            next = next.min(v);
        }
        *o = next;
    }
    w.bounds = bounds;
    Ok(())
}

mod cell;
mod detrend;
mod period;
use cell::{next_bin, Cell, Segment, NO_RANGE};
pub use detrend::{
    detrend_pair, detrend_pair_into, detrend_pair_scan_at, detrend_pair_scan_into,
    detrend_pair_scan_uniform_at, detrend_pair_scan_uniform_into, WindowScan,
};
use period::PeriodMeans;

#[cfg(test)]
mod tests;
