//! The reading side of a streamed analysis (`contactlab.io.chunked`): the time axis of a
//! recording that stores a sampling interval, made chunk by chunk.

use crate::error::CoreError;

const LANES: usize = 8;

/// `out[i] = t0 + dt * (offset + i)`: the time axis of samples `offset..` of a recording
/// sampled every `dt` from `t0`, in one pass; bit for bit numpy's
/// `t0 + dt * np.arange(offset, offset + n, dtype=float64)` (the indices are exact in double
/// precision below 2^53, and each value is one product and one sum, rounded as IEEE says).
pub fn fill_time(out: &mut [f64], t0: f64, dt: f64, offset: u64) -> Result<(), CoreError> {
    let n = u64::try_from(out.len()).map_err(|_| CoreError::TooLong { len: out.len() })?;
    match offset.checked_add(n) {
        Some(end) if end <= 1 << 53 => {}
        _ => return Err(CoreError::TooLong { len: out.len() }),
    }
    fill_time_in(out, t0, dt, offset);
    Ok(())
}

/// Whether the axis of `n` samples from `offset` has exact indices (`offset + n <= 2^53`,
/// [`fill_time`]'s condition).
pub(crate) fn indices_exact(offset: u64, n: usize) -> bool {
    u64::try_from(n)
        .ok()
        .and_then(|n| offset.checked_add(n))
        .is_some_and(|end| end <= 1 << 53)
}

/// [`fill_time`] of an axis whose indices are exact ([`indices_exact`]), inlined into the
/// caller (a kernel compiled for each SIMD level: the same numbers at each).
#[inline(always)]
pub(crate) fn fill_time_in(out: &mut [f64], t0: f64, dt: f64, offset: u64) {
    // the indices as doubles, counted up in lanes (exact: whole numbers below 2^53; a
    // 64-bit integer to double conversion per sample has no SSE2 instruction)
    let k0 = offset as f64;
    let mut k = [0.0_f64; LANES];
    for (j, kj) in k.iter_mut().enumerate() {
        let jf = j as f64;
        *kj = k0 + jf;
    }
    let mut it = out.chunks_exact_mut(LANES);
    for o in &mut it {
        for (oj, kj) in o.iter_mut().zip(k.iter_mut()) {
            *oj = t0 + dt * *kj;
            *kj += LANES as f64;
        }
    }
    for (j, o) in it.into_remainder().iter_mut().enumerate() {
        *o = t0 + dt * k[j];
    }
}

/// Sample `i` of [`fill_time`]'s axis (bit for bit: the index is exact below 2^53).
#[inline(always)]
pub(crate) fn time_at(t0: f64, dt: f64, offset: u64, i: usize) -> f64 {
    // (callers keep offset + i below 2^53: indices_exact)
    #[allow(clippy::arithmetic_side_effects)]
    let k = (offset + i as u64) as f64;
    t0 + dt * k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_axis_is_offset_times_step() {
        for (n, offset) in [(10, 1000_u64), (1003, 123_456_789_012), (0, 5), (8, 0)] {
            let mut t = vec![0.0; n];
            fill_time(&mut t, 0.25, 1e-4, offset).unwrap();
            for (i, &v) in t.iter().enumerate() {
                assert_eq!(
                    v,
                    0.25 + 1e-4 * ((offset + i as u64) as f64),
                    "{n} {offset} {i}"
                );
            }
        }
        assert!(fill_time(&mut [0.0; 2], 0.0, 1.0, 1 << 53).is_err());
    }
}
