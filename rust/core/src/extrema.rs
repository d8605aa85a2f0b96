//! Finiteness and range of a channel in one pass: the checks a streamed analysis makes of
//! every chunk it reads (its range is the magnitude check and the cycle trigger's band) and
//! of every window it analyses (`contactlab._physical.check_channel`: zero, constant or out
//! of any physical scale). numpy needed a pass each for `isfinite(...).all()`, `min` and
//! `max` (three reads of a window of 8 MB a channel); here one read, eight lanes.

/// `(all finite, min, max)` of `v`, the extremes over its finite values (`(+inf, -inf)`
/// when it has none). The extremes are values of `v` (exact): the smallest and largest by
/// `<` (of `0.0` and `-0.0`, whichever comes first in its lane).
/// Vectorised and dispatched at run time ([`crate::simd`]): the same numbers on every level.
#[must_use]
pub fn finite_min_max(v: &[f64]) -> (bool, f64, f64) {
    finite_min_max_at(crate::simd::level(), v)
}

crate::simd::dispatch! {
    /// [`finite_min_max`] with its kernel at `level`.
    pub fn finite_min_max_at(v: &[f64]) -> (bool, f64, f64) = finite_min_max_generic;
}

#[inline(always)]
fn finite_min_max_generic(v: &[f64]) -> (bool, f64, f64) {
    const L: usize = 8;
    let mut lo = [f64::INFINITY; L];
    let mut hi = [f64::NEG_INFINITY; L];
    // x * 0 is 0 for a finite x and NaN for inf or NaN: the sum stays 0 (or -0) while every
    // value is finite (no compare-and-branch in the loop)
    let mut nan = [0.0_f64; L];
    let mut chunks = v.chunks_exact(L);
    for c in &mut chunks {
        for k in 0..L {
            let x = c[k];
            lo[k] = if x < lo[k] { x } else { lo[k] };
            hi[k] = if x > hi[k] { x } else { hi[k] };
            nan[k] += x * 0.0;
        }
    }
    for (k, &x) in chunks.remainder().iter().enumerate() {
        lo[k] = if x < lo[k] { x } else { lo[k] };
        hi[k] = if x > hi[k] { x } else { hi[k] };
        nan[k] += x * 0.0;
    }
    let finite = nan.iter().all(|&s| s == 0.0);
    if finite {
        let mn = lo
            .iter()
            .fold(f64::INFINITY, |a, &b| if b < a { b } else { a });
        let mx = hi
            .iter()
            .fold(f64::NEG_INFINITY, |a, &b| if b > a { b } else { a });
        return (true, mn, mx);
    }
    // not all finite (rare: the caller refuses the channel): the extremes of the finite ones
    let (mut mn, mut mx) = (f64::INFINITY, f64::NEG_INFINITY);
    for &x in v.iter().filter(|x| x.is_finite()) {
        if x < mn {
            mn = x;
        }
        if x > mx {
            mx = x;
        }
    }
    (false, mn, mx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_simd_level_equals_the_generic_one() {
        for n in [0_usize, 1, 7, 8, 9, 63, 64, 65, 1001] {
            let mut v: Vec<f64> = (0..n).map(|i| ((i * 7919) % 1013) as f64 - 500.0).collect();
            let want = finite_min_max_at(crate::simd::Level::Generic, &v);
            for lv in crate::simd::Level::ALL
                .into_iter()
                .filter(|l| l.supported())
            {
                assert_eq!(finite_min_max_at(lv, &v), want, "{lv:?} {n}");
            }
            if n > 3 {
                v[n / 2] = f64::NAN;
                let want = finite_min_max_at(crate::simd::Level::Generic, &v);
                assert!(!want.0);
                for lv in crate::simd::Level::ALL
                    .into_iter()
                    .filter(|l| l.supported())
                {
                    assert_eq!(finite_min_max_at(lv, &v), want, "{lv:?} {n}");
                }
            }
        }
    }
    use proptest::prelude::*;

    fn reference(v: &[f64]) -> (bool, f64, f64) {
        let fin: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
        (
            fin.len() == v.len(),
            fin.iter().copied().fold(f64::INFINITY, f64::min),
            fin.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }

    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            20 => -1e300..1e300_f64,
            20 => -1.0..1.0_f64,
            1 => Just(f64::NAN),
            1 => Just(f64::INFINITY),
            1 => Just(f64::NEG_INFINITY),
            1 => Just(0.0),
            1 => Just(f64::MAX),
            1 => Just(f64::MIN),
        ]
    }

    proptest! {
        #[test]
        fn equals_the_filtered_reference(v in proptest::collection::vec(value(), 0..100)) {
            let (f, mn, mx) = finite_min_max(&v);
            let (rf, rmn, rmx) = reference(&v);
            prop_assert_eq!(f, rf);
            prop_assert_eq!(mn, rmn);
            prop_assert_eq!(mx, rmx);
        }
    }

    #[test]
    fn each_non_finite_value_anywhere_is_found() {
        for n in 1..40 {
            for i in 0..n {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut v: Vec<f64> = (0..n).map(|k| k as f64 - 3.0).collect();
                    v[i] = bad;
                    let (f, mn, mx) = finite_min_max(&v);
                    assert!(!f, "n {n} i {i} {bad}");
                    assert_eq!((mn, mx), (reference(&v).1, reference(&v).2));
                }
            }
        }
        assert_eq!(
            finite_min_max(&[]),
            (true, f64::INFINITY, f64::NEG_INFINITY)
        );
    }
}
