//! Cutting a uniformly sampled recording into whole cycles on a common phase grid.
//!
//! Cycle `c`, phase bin `j` is read at fractional sample position
//! `start + c·period + j·period/n_bins`. Integer positions return the sample itself (so a
//! recording with an integer number of samples per period is folded without any
//! interpolation); between samples the value is a cubic Hermite with central-difference
//! slopes (one-sided, second order, at the ends).

use crate::error::{check_finite, check_positive, CoreError};

#[inline]
// Index arithmetic only: `i < x.len()` and `x.len() >= 2` (checked by `sample_at` and
// `fold_cycles`, the only callers), so no index over- or underflows.
#[allow(clippy::arithmetic_side_effects)]
fn slope(x: &[f64], i: usize) -> f64 {
    let n = x.len();
    if n == 2 {
        x[1] - x[0]
    } else if i == 0 {
        0.5 * (-3.0 * x[0] + 4.0 * x[1] - x[2])
    } else if i == n - 1 {
        0.5 * (x[n - 3] - 4.0 * x[n - 2] + 3.0 * x[n - 1])
    } else {
        0.5 * (x[i + 1] - x[i - 1])
    }
}

/// Value of the sampled signal at fractional index `pos` (clamped to `[0, len - 1]`).
pub fn sample_at(x: &[f64], pos: f64) -> Result<f64, CoreError> {
    if x.is_empty() {
        return Err(CoreError::Empty { name: "x" });
    }
    if pos.is_nan() {
        return Err(CoreError::InvalidParameter {
            name: "pos",
            value: pos,
            reason: "must not be NaN",
        });
    }
    if x.len() == 1 {
        return Ok(x[0]);
    }
    let v = interpolate(x, pos);
    if !v.is_finite() {
        return Err(CoreError::OutOfRange {
            what: "interpolated sample",
            index: 0,
            value: v,
        });
    }
    Ok(v)
}

/// [`sample_at`] for `x.len() >= 2` and a number `pos`.
#[inline]
// Index arithmetic only: `i < x.len()` and `x.len() >= 2` (checked by `sample_at` and
// `fold_cycles`, the only callers), so no index over- or underflows.
#[allow(clippy::arithmetic_side_effects)]
fn interpolate(x: &[f64], pos: f64) -> f64 {
    let n = x.len();
    let i = (pos.floor() as usize).min(n - 1);
    let s = pos - i as f64;
    if s <= 0.0 || i == n - 1 {
        return x[i];
    }
    let v = hermite(x, i, s, 1.0);
    if v.is_finite() {
        return v;
    }
    // Samples near f64::MAX: the slopes and coefficients overflow (inf - inf = NaN, found by
    // fuzzing) although the value may not. The same cubic on the samples scaled by 2^-5
    // (exact) keeps every partial sum below f64::MAX; scaled back it is inf only when the
    // interpolated value itself is beyond the range.
    hermite(x, i, s, OVERFLOW_SCALE) / OVERFLOW_SCALE
}

/// 2^-5: on samples scaled by it the Hermite's coefficients and partial sums stay finite.
const OVERFLOW_SCALE: f64 = 0.031_25;

/// The cubic Hermite between samples `i` and `i + 1` at `s` in (0, 1), on the samples times `k`.
#[inline]
#[allow(clippy::arithmetic_side_effects)]
fn hermite(x: &[f64], i: usize, s: f64, k: f64) -> f64 {
    let (p0, p1) = (k * x[i], k * x[i + 1]);
    let (m0, m1) = (scaled_slope(x, i, k), scaled_slope(x, i + 1, k));
    let c2 = 3.0 * (p1 - p0) - 2.0 * m0 - m1;
    let c3 = 2.0 * (p0 - p1) + m0 + m1;
    p0 + s * (m0 + s * (c2 + s * c3))
}

/// [`slope`] at sample `i` of the samples times `k` (the stencil's three samples are scaled
/// before they are combined, so nothing overflows on the way).
// Index arithmetic: the window lo..hi holds i (lo <= i < hi <= x.len(), x.len() >= 2).
#[inline]
#[allow(clippy::arithmetic_side_effects)]
fn scaled_slope(x: &[f64], i: usize, k: f64) -> f64 {
    if k == 1.0 {
        return slope(x, i);
    }
    // The stencil of `slope` lies within three samples around i: the same window (with the
    // same end cases) scaled gives the scaled slope.
    let lo = i.saturating_sub(1).min(x.len().saturating_sub(3));
    let hi = (lo + 3).min(x.len());
    let w: Vec<f64> = x[lo..hi].iter().map(|v| k * v).collect();
    slope(&w, i - lo)
}

/// Fold `x` into `n_cycles × n_bins` values (row-major, one row per cycle) into `out`.
pub fn fold_cycles(
    x: &[f64],
    start: f64,
    period: f64,
    n_cycles: usize,
    n_bins: usize,
    out: &mut [f64],
) -> Result<(), CoreError> {
    check_finite("x", x)?;
    if x.len() < 2 {
        return Err(CoreError::InvalidParameter {
            name: "len(x)",
            value: x.len() as f64,
            reason: "at least two samples are needed",
        });
    }
    check_positive("period", period)?;
    if !(start.is_finite() && start >= 0.0) {
        return Err(CoreError::InvalidParameter {
            name: "start",
            value: start,
            reason: "must be finite and >= 0",
        });
    }
    if n_bins < 2 || n_cycles == 0 {
        return Err(CoreError::InvalidParameter {
            name: "n_bins",
            value: n_bins as f64,
            reason: "need n_bins >= 2 and n_cycles >= 1",
        });
    }
    let len = n_cycles
        .checked_mul(n_bins)
        .ok_or(CoreError::InvalidParameter {
            name: "n_cycles",
            value: n_cycles as f64,
            reason: "n_cycles * n_bins overflows",
        })?;
    crate::error::check_same_len("n_cycles * n_bins", len, "out", out.len())?;
    let last = start + (n_cycles as f64) * period - period / n_bins as f64;
    let max_pos = x.len().saturating_sub(1) as f64; // len >= 2 here
    if last > max_pos + 1e-9 {
        return Err(CoreError::InvalidParameter {
            name: "n_cycles",
            value: n_cycles as f64,
            reason: "the requested cycles run past the end of the recording",
        });
    }
    let step = period / n_bins as f64;
    for (c, row) in out.chunks_exact_mut(n_bins).enumerate() {
        let base = start + c as f64 * period;
        for (j, o) in row.iter_mut().enumerate() {
            let pos = (base + j as f64 * step).min(max_pos);
            *o = interpolate(x, pos);
        }
    }
    // Only an interpolant overshooting beyond f64::MAX between samples near it is not finite.
    if let Some(index) = out.iter().position(|v| !v.is_finite()) {
        return Err(CoreError::OutOfRange {
            what: "folded cycle",
            index,
            value: out[index],
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_period_folds_exact_samples() {
        let x: Vec<f64> = (0..40).map(|k| f64::from(k).sin()).collect();
        let mut out = vec![0.0; 3 * 10];
        fold_cycles(&x, 5.0, 10.0, 3, 10, &mut out).unwrap();
        for c in 0..3 {
            for j in 0..10 {
                assert_eq!(out[c * 10 + j], x[5 + c * 10 + j]);
            }
        }
    }

    #[test]
    fn fractional_positions_interpolate_smooth_signals() {
        let x: Vec<f64> = (0..400).map(|k| (0.05 * f64::from(k)).sin()).collect();
        let v = sample_at(&x, 100.37).unwrap();
        assert!((v - (0.05 * 100.37_f64).sin()).abs() < 1e-6);
    }

    #[test]
    fn sample_at_empty_or_nan_is_an_error() {
        assert_eq!(sample_at(&[], 0.0), Err(CoreError::Empty { name: "x" }));
        assert!(sample_at(&[1.0, 2.0], f64::NAN).is_err());
        assert_eq!(sample_at(&[4.0], 0.7), Ok(4.0));
        assert_eq!(sample_at(&[1.0, 2.0, 3.0], -5.0), Ok(1.0));
        assert_eq!(sample_at(&[1.0, 2.0, 3.0], 9.0), Ok(3.0));
        assert_eq!(sample_at(&[1.0, 2.0, 3.0], f64::INFINITY), Ok(3.0));
    }

    #[test]
    fn samples_near_the_double_range_interpolate_without_nan() {
        // found by AFL++ (fuzz/afl): -3·x[0] overflowed in the end slope, inf - inf gave NaN
        let mut x = vec![1e-300; 11];
        x[0] = f64::MAX;
        x[1] = 1.2e-279;
        let mut out = vec![0.0; 5 * 31];
        fold_cycles(&x, 1e-300, 1e-300, 5, 31, &mut out).unwrap();
        assert!(out.iter().all(|v| v.is_finite()));
        // the scaled route is the same cubic: on [M/2, M, M/2] the end slope 4·M overflows;
        // the Hermite midpoint (p0 + p1)/2 + (m0 - m1)/8 with m0 = M, m1 = 0 is 0.875 M
        let m = f64::MAX;
        let v = sample_at(&[0.5 * m, m, 0.5 * m], 0.5).unwrap();
        assert!((v / (0.875 * m) - 1.0).abs() < 1e-15, "{v}");
        let over = [0.0, f64::MAX, f64::MAX, 0.0];
        assert!(matches!(
            sample_at(&over, 1.5),
            Err(CoreError::OutOfRange { .. })
        ));
    }

    #[test]
    fn huge_cycle_counts_are_an_error_not_an_overflow() {
        let x = vec![0.0; 30];
        let mut out = vec![0.0; 4];
        let r = fold_cycles(&x, 0.0, 10.0, usize::MAX / 2, 4, &mut out);
        assert!(matches!(
            r,
            Err(CoreError::InvalidParameter {
                reason: "n_cycles * n_bins overflows",
                ..
            })
        ));
    }

    #[test]
    fn rejects_overrun() {
        let x = vec![0.0; 30];
        let mut out = vec![0.0; 40];
        assert!(fold_cycles(&x, 0.0, 10.0, 4, 10, &mut out).is_err());
    }
}
