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
        let value = value.unwrap_or(trigger);
        check_same_len("x", trigger.len(), "value", value.len())?;
        check_finite("value", value)?;
        let end = u64::try_from(trigger.len())
            .ok()
            .and_then(|n| self.count.checked_add(n))
            .ok_or(CoreError::TooLong { len: trigger.len() })?;
        let hi = self.centre + self.threshold;
        let lo = self.centre - self.threshold;
        let centre = self.centre;
        let mut open = self.open;
        let mut index = self.count;
        for (&u, &v) in trigger.iter().zip(value) {
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
            index += 1;
        }
        self.open = open;
        self.count = end;
        Ok(())
    }
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
