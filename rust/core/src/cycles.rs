//! Blocks of whole cycles of a periodic recording, cut at the drive's crossings of a band
//! (streamed, with a state carried between blocks).

use crate::error::{check_finite, check_same_len, CoreError};

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

/// Samples a block of [`first_beyond`]'s search (its compares are or-ed over a block without
/// an exit, which vectorises; the block with a hit is searched again sample by sample).
const SEARCH_BLOCK: usize = 16;

/// The first index of `v` whose value is `<= level` (`ABOVE = false`) or `>= level`
/// (`ABOVE = true`), `v.len()` when none: `position`'s answer (a NaN is neither), searched by
/// blocks whose compares are or-ed without an early exit (a loop that exits at the first hit
/// is compiled one sample at a time).
// Index arithmetic: base + p < v.len().
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
fn first_beyond_generic<const ABOVE: bool>(v: &[f64], level: f64) -> usize {
    let hit = |d: f64| if ABOVE { d >= level } else { d <= level };
    let mut chunks = v.chunks_exact(SEARCH_BLOCK);
    let mut base = 0_usize;
    for c in &mut chunks {
        if c.iter().fold(false, |a, &d| a | hit(d)) {
            return base + c.iter().position(|&d| hit(d)).unwrap_or(SEARCH_BLOCK);
        }
        base += SEARCH_BLOCK;
    }
    base + chunks
        .remainder()
        .iter()
        .position(|&d| hit(d))
        .unwrap_or(chunks.remainder().len())
}

#[inline(always)]
fn first_at_or_below(v: &[f64], level: f64) -> usize {
    first_beyond_generic::<false>(v, level)
}

#[inline(always)]
fn first_at_or_above(v: &[f64], level: f64) -> usize {
    first_beyond_generic::<true>(v, level)
}

crate::simd::dispatch! {
    /// [`first_beyond_generic`] (`<= level`) compiled for `level_`.
    fn first_at_or_below_at(v: &[f64], level: f64) -> usize = first_at_or_below;
}

crate::simd::dispatch! {
    /// [`first_beyond_generic`] (`>= level`) compiled for `level_`.
    fn first_at_or_above_at(v: &[f64], level: f64) -> usize = first_at_or_above;
}

/// The first upward crossing of `drive[from..]` through `[low, high]` (`low < high`) as a
/// Schmitt trigger with the carried `level`: the drive must have been `<= low` since the last
/// `>= high`; `drive.len()` when there is none. `level` follows the drive up to the crossing
/// (to the end without one), as one sample at a time would leave it. The scans for the next
/// sample beyond a level are vectorised ([`first_beyond_generic`]: the same indices as
/// `position`).
// Index arithmetic: from <= k <= drive.len() throughout.
#[allow(clippy::arithmetic_side_effects)]
fn next_crossing(drive: &[f64], from: usize, low: f64, high: f64, level: &mut i8) -> usize {
    let n = drive.len();
    let simd = crate::simd::level();
    let mut k = from;
    if *level != -1 {
        let p = first_at_or_below_at(simd, &drive[k..], low);
        if k + p >= n {
            if first_at_or_above_at(simd, &drive[k..], high) < n - k {
                *level = 1;
            }
            return n;
        }
        *level = -1;
        k += p + 1;
    }
    let p = first_at_or_above_at(simd, &drive[k..], high);
    if k + p < n {
        *level = 1;
        k + p
    } else {
        n
    }
}

/// Upward crossings of `drive` through the band `[low, high]` (a Schmitt trigger: the drive
/// must have been `<= low` since the last `>= high` before a new `>= high` counts) and the
/// cycles they complete, in one pass over a block starting at global index `offset`; `state`
/// carries everything across blocks, so any chunking gives the same cycles. A band with
/// `high <= low` (a constant block) finds no crossing. On error `state` is unchanged.
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
    #[allow(clippy::arithmetic_side_effects)]
    let time = |c: usize| t0 + dt * ((offset + c as u64) as f64);
    cycle_block_with(time, x, f, drive, offset, (low, high), state)
}

/// The upward crossings alone of [`cycle_block`] (global indices; the same crossings, the
/// same checks and errors, `state.level` carried the same way), without the per-cycle
/// quantities: the windows of a streamed analysis whose per-cycle table nobody reads are
/// cut at these. The pass is the trigger's search over `drive` (a vectorised scan for the
/// next sample beyond the band) and the finiteness checks of `x` and `F`, instead of the
/// chain of additions of `∮ F dx` a sample (2.2 of a streamed `analyze`'s 32 ns a sample).
/// Only `state.level` is updated: a stream is cut by this function or by [`cycle_block`],
/// not both (the per-cycle state would be stale).
///
/// # Errors
/// As [`cycle_block_sampled`]: channels of other lengths, a non-finite sample (the first,
/// in the order x, F, drive), levels not finite, a block past 2^53 samples. On error
/// `state` is unchanged.
// Index arithmetic: c < n where indexed; offset + n checked.
#[allow(clippy::arithmetic_side_effects)]
pub fn crossings_block(
    x: &[f64],
    f: &[f64],
    drive: &[f64],
    offset: u64,
    levels: (f64, f64),
    state: &mut CycleState,
) -> Result<Vec<u64>, CoreError> {
    crossings_block_with(x, f, drive, offset, levels, state, false)
}

/// [`crossings_block`] of samples the caller has checked finite (a streamed reader's
/// chunks, each scanned by its range pass): the same crossings and `state.level`, without
/// the finiteness scans of `x`, `F` and `drive` (two reads of the block of the three the
/// pass made). The lengths, the levels and the sample count are checked as there; a
/// non-finite sample only makes the crossings meaningless.
///
/// # Errors
/// As [`crossings_block`], but for the finiteness of the samples.
pub fn crossings_block_checked(
    x: &[f64],
    f: &[f64],
    drive: &[f64],
    offset: u64,
    levels: (f64, f64),
    state: &mut CycleState,
) -> Result<Vec<u64>, CoreError> {
    crossings_block_with(x, f, drive, offset, levels, state, true)
}

/// [`crossings_block`] (`finite`: the samples are known finite, not scanned).
// Index arithmetic: c < n where indexed; offset + n checked.
#[allow(clippy::arithmetic_side_effects)]
fn crossings_block_with(
    x: &[f64],
    f: &[f64],
    drive: &[f64],
    offset: u64,
    (low, high): (f64, f64),
    state: &mut CycleState,
    finite: bool,
) -> Result<Vec<u64>, CoreError> {
    let n = x.len();
    check_same_len("x", n, "F", f.len())?;
    check_same_len("x", n, "drive", drive.len())?;
    u64::try_from(n)
        .ok()
        .and_then(|k| offset.checked_add(k))
        .filter(|&end| end <= 1 << 53)
        .ok_or(CoreError::TooLong { len: n })?;
    // vectorised scans (the drive once when it is x); the separate checks name a failure
    let is_finite = |v: &[f64]| crate::extrema::finite_min_max(v).0;
    if !finite && !(is_finite(x) && is_finite(f) && (std::ptr::eq(drive, x) || is_finite(drive))) {
        check_finite("x", x)?;
        check_finite("F", f)?;
        check_finite("drive", drive)?;
    }
    if !(low.is_finite() && high.is_finite()) {
        return Err(CoreError::InvalidParameter {
            name: "levels",
            value: if low.is_finite() { high } else { low },
            reason: "trigger levels must be finite",
        });
    }
    let mut out = Vec::new();
    if n == 0 {
        return Ok(out);
    }
    let mut level = state.level;
    if high > low {
        let mut i = 0;
        while i < n {
            let c = next_crossing(drive, i, low, high, &mut level);
            if c >= n {
                break;
            }
            out.push(offset + c as u64);
            i = c + 1;
        }
    } else if let Some(&d) = drive.iter().rev().find(|&&d| d <= low || d >= high) {
        // no crossing possible (high <= low): the level is the block's last mark
        level = if d <= low { -1 } else { 1 };
    }
    state.level = level;
    Ok(out)
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
#[allow(clippy::arithmetic_side_effects)]
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
    use super::*;
    use crate::fold::{period_means, period_means_pair};

    /// The one-sample-at-a-time loop `cycle_block` replaced (its next crossing is now found
    /// first and the samples before it summed in one tight pass): the reference.
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
        /// The crossings alone: those of `cycle_block`, and its trigger level carried, over
        /// any chunking, any band (none possible too), the drive x itself or another channel.
        #[test]
        fn crossings_block_is_cycle_blocks_crossings(
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
            let high = low + width;
            let (a, sa) = run_chunks(&t, &xs, f, &d, &cuts, low, high, true);
            let mut st = CycleState::default();
            let mut got = Vec::new();
            let mut k = 0;
            for &b in cuts.iter().chain(std::iter::once(&n)) {
                let b = b.clamp(k, n);
                let r = k..b;
                let dr = if drive_is_x { &xs[r.clone()] } else { &d[r.clone()] };
                got.extend(
                    crossings_block(&xs[r.clone()], &f[r], dr, k as u64, (low, high), &mut st)
                        .unwrap(),
                );
                k = b;
            }
            proptest::prop_assert_eq!(&got, &a.crossings);
            proptest::prop_assert_eq!(st.level, sa.level);
        }
    }

    /// `next_crossing` as it was before its scans were vectorised: `position` one sample at
    /// a time (the reference of the blocked search).
    fn next_crossing_reference(
        drive: &[f64],
        from: usize,
        low: f64,
        high: f64,
        level: &mut i8,
    ) -> usize {
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

    /// The blocked scans find what `position` finds at every SIMD level this CPU has: hits in
    /// the first, a middle and the last block, in the remainder, none, NaN (neither side),
    /// constant and short inputs.
    #[test]
    fn blocked_scans_are_positions_at_every_level() {
        let mut cases: Vec<Vec<f64>> = vec![vec![], vec![0.5], vec![0.0; 37], vec![f64::NAN; 40]];
        let mut seed = 12345_u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((seed >> 11) as f64) / ((1_u64 << 53) as f64)
        };
        for n in [1_usize, 15, 16, 17, 31, 32, 33, 100, 257] {
            for hit in [0, 1, n / 2, n.saturating_sub(1)] {
                let mut v: Vec<f64> = (0..n).map(|_| 0.2 + 0.5 * next()).collect();
                if hit < n {
                    v[hit] = 0.05;
                }
                if n > 3 {
                    v[n / 3] = f64::NAN;
                }
                cases.push(v.clone());
                for d in &mut v {
                    *d = 1.0 - *d;
                }
                cases.push(v);
            }
        }
        for v in &cases {
            for level in crate::simd::Level::ALL
                .into_iter()
                .filter(|l| l.supported())
            {
                for lv in [0.1, 0.2, 0.5, 0.9, 0.95, f64::NAN] {
                    let below = v.iter().position(|&d| d <= lv).unwrap_or(v.len());
                    let above = v.iter().position(|&d| d >= lv).unwrap_or(v.len());
                    assert_eq!(first_at_or_below_at(level, v, lv), below, "{level:?} {v:?}");
                    assert_eq!(first_at_or_above_at(level, v, lv), above, "{level:?} {v:?}");
                }
            }
            for start in [-1_i8, 0, 1] {
                for from in [0, v.len() / 2, v.len()] {
                    let (mut a, mut b) = (start, start);
                    let got = next_crossing(v, from, 0.1, 0.9, &mut a);
                    let want = next_crossing_reference(v, from, 0.1, 0.9, &mut b);
                    assert_eq!((got, a), (want, b));
                }
            }
        }
    }

    proptest::proptest! {
        /// The crossings of samples known finite (`crossings_block_checked`, the scans left
        /// out) are `crossings_block`'s over any chunking and band, and the trigger level
        /// carried the same; the one-sample `next_crossing_reference` finds them too.
        #[test]
        fn checked_crossings_are_the_scanned_ones(
            xs in proptest::collection::vec(-2.0_f64..2.0, 1..700),
            fs in proptest::collection::vec(-3.0_f64..3.0, 700),
            low in -1.0_f64..1.0,
            width in -0.5_f64..1.0,
            mut cuts in proptest::collection::vec(0_usize..700, 0..6),
        ) {
            let n = xs.len();
            let f = &fs[..n];
            cuts.sort_unstable();
            let high = low + width;
            let (mut sa, mut sb) = (CycleState::default(), CycleState::default());
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let mut k = 0;
            for &e in cuts.iter().chain(std::iter::once(&n)) {
                let e = e.clamp(k, n);
                let (xr, fr) = (&xs[k..e], &f[k..e]);
                a.extend(crossings_block(xr, fr, xr, k as u64, (low, high), &mut sa).unwrap());
                b.extend(
                    crossings_block_checked(xr, fr, xr, k as u64, (low, high), &mut sb).unwrap(),
                );
                k = e;
            }
            proptest::prop_assert_eq!(&a, &b);
            proptest::prop_assert_eq!(sa.level, sb.level);
            if high > low {
                let (mut want, mut level, mut i) = (Vec::new(), 0_i8, 0_usize);
                while i < n {
                    let c = next_crossing_reference(&xs, i, low, high, &mut level);
                    if c >= n {
                        break;
                    }
                    want.push(c as u64);
                    i = c + 1;
                }
                proptest::prop_assert_eq!(&a, &want);
            }
        }
    }

    /// A non-finite sample or bad levels: `cycle_block`'s error, and the state unchanged.
    #[test]
    fn crossings_block_refuses_what_cycle_block_refuses() {
        let n = 300;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-2).collect();
        let x: Vec<f64> = t.iter().map(|&s| (s * 9.0).sin()).collect();
        let f: Vec<f64> = t.iter().map(|&s| (s * 9.0).cos()).collect();
        for (xi, fi) in [(Some(5), None), (Some(250), Some(3)), (None, Some(299))] {
            for levels in [(-0.5, 0.5), (f64::NAN, 0.5)] {
                let (mut xb, mut fb) = (x.clone(), f.clone());
                if let Some(i) = xi {
                    xb[i] = f64::INFINITY;
                }
                if let Some(i) = fi {
                    fb[i] = f64::NAN;
                }
                for drive_is_x in [true, false] {
                    let d = if drive_is_x { &xb } else { &fb };
                    let (mut s1, mut s2) = (CycleState::default(), CycleState::default());
                    s2.level = 1;
                    let before = s2;
                    let want = cycle_block(&t, &xb, &fb, d, 0, levels.0, levels.1, &mut s1);
                    let got = crossings_block(&xb, &fb, d, 0, levels, &mut s2);
                    assert_eq!(
                        format!("{:?}", got.unwrap_err()),
                        format!("{:?}", want.unwrap_err())
                    );
                    assert_eq!(format!("{s2:?}"), format!("{before:?}"));
                }
            }
        }
        let mut st = CycleState::default();
        assert!(crossings_block(&x, &f, &x, 0, (f64::NAN, 0.5), &mut st).is_err());
        assert!(crossings_block(&x, &f, &x, 1 << 53, (-0.5, 0.5), &mut st).is_err());
        assert!(crossings_block(&x, &f[..10], &x, 0, (-0.5, 0.5), &mut st).is_err());
        // (NaN fields: compared as text)
        assert_eq!(format!("{st:?}"), format!("{:?}", CycleState::default()));
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
}
