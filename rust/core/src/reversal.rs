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
        self.push_finite(trigger, value, done)
    }

    /// [`Schmitt::push`] of samples the caller has checked finite (an analysis window's,
    /// scanned already): the same excursions without the finiteness pass over them (a NaN
    /// or an infinity only makes the excursions meaningless). `value`, when given, must be
    /// as long as `trigger`.
    ///
    /// # Errors
    /// [`CoreError::LengthMismatch`] for a `value` of another length,
    /// [`CoreError::TooLong`] when the sample count would overflow.
    pub fn push_finite(
        &mut self,
        trigger: &[f64],
        value: Option<&[f64]>,
        done: &mut Vec<Excursion>,
    ) -> Result<(), CoreError> {
        if let Some(v) = value {
            check_same_len("x", trigger.len(), "value", v.len())?;
        }
        let value = value.unwrap_or(trigger);
        let end = u64::try_from(trigger.len())
            .ok()
            .and_then(|n| self.count.checked_add(n))
            .ok_or(CoreError::TooLong { len: trigger.len() })?;
        self.push_loop(crate::simd::level(), trigger, value, done, end);
        Ok(())
    }

    /// The loop of [`Schmitt::push_finite`] compiled for `level` (AVX2 / AVX-512 when the
    /// CPU has them: comparisons and selects only, so every level makes the same decisions)
    /// over `trigger` and `value` of one length; `end` the sample count after them.
    fn push_loop(
        &mut self,
        level: crate::simd::Level,
        trigger: &[f64],
        value: &[f64],
        done: &mut Vec<Excursion>,
        end: u64,
    ) {
        self.open = crate::simd::run(
            level,
            PushLoop {
                st: self,
                trigger,
                value,
                done,
            },
        );
        self.count = end;
    }
}

/// [`Schmitt::push`]'s loop over checked samples as a [`crate::simd::Kernel`]: the open
/// excursion after the samples.
struct PushLoop<'a> {
    st: &'a Schmitt,
    trigger: &'a [f64],
    value: &'a [f64],
    done: &'a mut Vec<Excursion>,
}

impl crate::simd::Kernel for PushLoop<'_> {
    type Output = Option<Excursion>;

    // Index arithmetic: i < n, stop <= n; the sample index is saturating.
    #[allow(clippy::arithmetic_side_effects)]
    #[inline(always)]
    fn run_at(self) -> Option<Excursion> {
        let PushLoop {
            st,
            trigger,
            value,
            done,
        } = self;
        let hi = st.centre + st.threshold;
        let lo = st.centre - st.threshold;
        let centre = st.centre;
        // the open excursion in locals (an `Option<Excursion>` matched every sample kept it
        // in memory: 7 ns a sample, against about 2 now); the same decisions as
        // `push_reference` in the tests, sample for sample
        let mut has = st.open.is_some();
        let mut e = st.open.unwrap_or(Excursion {
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
        let mut index = st.count;
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
        if has {
            Some(e)
        } else {
            None
        }
    }
}

/// Samples a block of [`Schmitt::push`]'s fast path holds (at most 64: one bit a sample in
/// [`mask_of`]'s masks).
const BLOCK: usize = 32;
const _: () = assert!(BLOCK <= 64);

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
    // the trigger's running extreme away from the excursion's side (the smallest above,
    // the largest below): a sample leaves the band on the other side, or comes back beyond
    // the centre, exactly when that extreme does (it is one of the samples; a NaN is passed
    // over by both comparisons, as by the per-sample ones)
    let away = |a: f64, b: f64| if UP { a < b } else { a > b };
    // four independent running extremes of each (a chain of selects a sample was the
    // loop's latency); the block's extremes are theirs whatever the order
    let mut best = [e.extreme_value; 4];
    let mut back_most = [if UP { f64::INFINITY } else { f64::NEG_INFINITY }; 4];
    for j in 0..BLOCK / 4 {
        for k in 0..4 {
            let (uk, vk) = (u[4 * j + k], v[4 * j + k]);
            best[k] = if better(vk, best[k]) { vk } else { best[k] };
            back_most[k] = if away(uk, back_most[k]) {
                uk
            } else {
                back_most[k]
            };
        }
    }
    let mut top = best[0];
    let mut bottom = back_most[0];
    for k in 1..4 {
        top = if better(best[k], top) { best[k] } else { top };
        bottom = if away(back_most[k], bottom) {
            back_most[k]
        } else {
            bottom
        };
    }
    // a sample beyond the band on the other side: a new excursion starts in the block
    if if UP { bottom < lo } else { bottom > hi } {
        return false;
    }
    let back_of = |x: f64| if UP { x < centre } else { x > centre };
    let beyond_of = |x: f64| if UP { x > hi } else { x < lo };
    // any sample back beyond the centre (most blocks have none: their mask is not made)
    let any_back = back_of(bottom);
    if better(top, e.extreme_value) {
        // the first sample of the block's extreme value (numerically equal: ±0 are one; top
        // is one of the block's values, as it beats the excursion's)
        let at = mask_of(v, |x| x == top);
        let m = if at == 0 {
            0
        } else {
            at.trailing_zeros() as usize
        };
        e.extreme = base + m as u64;
        e.extreme_value = v[m];
        // beyond the centre after it (m < BLOCK <= 64: both shifts are defined); the
        // samples back beyond the centre as a bit mask (bit k: sample k; branch-free, so it
        // vectorises), made only when there is one
        e.returned = any_back && (mask_of(u, back_of) >> m) >> 1 != 0;
    } else {
        e.returned |= any_back;
    }
    // the block's last sample beyond the band: its last sample when that is (most blocks
    // deep in an excursion), else the highest bit of the mask
    if beyond_of(u[BLOCK - 1]) {
        e.last_beyond = base + (BLOCK - 1) as u64;
    } else {
        let beyond = mask_of(u, beyond_of);
        if beyond != 0 {
            e.last_beyond = base + u64::from(beyond.ilog2()); // the highest bit set
        }
    }
    true
}

/// Bit `k` set where `f(xs[k])` holds (`xs` at most 64 long): branch-free, so it vectorises
/// (a compare and a move-mask a few samples).
#[inline(always)]
fn mask_of(xs: &[f64; BLOCK], f: impl Fn(f64) -> bool) -> u64 {
    let mut m = 0_u64;
    for (k, &x) in xs.iter().enumerate() {
        m |= u64::from(f(x)) << k;
    }
    m
}

#[cfg(test)]
mod tests {
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
            // the loop compiled for every SIMD level this CPU has (the same decisions)
            let mut at: Vec<_> = crate::simd::Level::ALL
                .into_iter()
                .filter(|l| l.supported())
                .map(|l| (l, a.clone(), Vec::new()))
                .collect();
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
                for (level, st, d) in &mut at {
                    let end = st.count + (s1 - s0) as u64;
                    st.push_loop(*level, &u[s0..s1], &v[s0..s1], d, end);
                    proptest::prop_assert_eq!(&*st, &b, "level {:?}", level);
                }
                s0 = s1;
            }
            proptest::prop_assert_eq!(&da, &db);
            for (level, _, d) in &at {
                proptest::prop_assert_eq!(d, &db, "level {:?}", level);
            }
        }
    }

    #[test]
    fn push_finite_is_push_without_the_check() {
        let x: Vec<f64> = (0..5000).map(|i| (f64::from(i) * 0.01).sin()).collect();
        let (mut a, mut da) = (Schmitt::new(0.0, 0.5).unwrap(), Vec::new());
        let (mut b, mut db) = (a.clone(), Vec::new());
        a.push(&x, None, &mut da).unwrap();
        b.push_finite(&x, None, &mut db).unwrap();
        assert_eq!((a, da), (b, db));
        // the check is push's: a NaN is refused by push, not by push_finite
        let mut y = x.clone();
        y[77] = f64::NAN;
        let mut c = Schmitt::new(0.0, 0.5).unwrap();
        assert!(c.push(&y, None, &mut Vec::new()).is_err());
        assert!(c.push_finite(&y, None, &mut Vec::new()).is_ok());
        assert!(c.push_finite(&y, Some(&y[1..]), &mut Vec::new()).is_err());
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
}
