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
        for (index, (&u, &v)) in (self.count..).zip(trigger.iter().zip(value)) {
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
        self.open = open;
        self.count = end;
        Ok(())
    }
}

/// Sums of a phase-bin fold (the cycle averaging of a periodic recording), accumulated over
/// any number of chunks: per bin (`n_bins`) and per cycle and bin (`n_cycles × n_bins`,
/// row-major by cycle). Means are sums over counts; the caller divides.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldSums {
    pub n_bins: usize,
    pub n_cycles: usize,
    /// Per bin: samples, Σx, ΣF, Σφ, Σφ², Σx² (φ: phase within the cycle, in [0, 1)).
    pub count: Vec<f64>,
    pub sum_x: Vec<f64>,
    pub sum_f: Vec<f64>,
    pub sum_phase: Vec<f64>,
    pub sum_phase2: Vec<f64>,
    pub sum_xx: Vec<f64>,
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
    for (i, ((&ti, &xi), &fi)) in t.iter().zip(x).zip(f).enumerate() {
        if !(ti >= t0 && ti < t1) {
            continue;
        }
        if ti < kt[j] {
            j = 0; // time went back (a new chunk of another stretch): search from the start
        }
        while kt[j + 1] <= ti {
            j += 1;
        }
        // numpy.interp's arithmetic: the knot's value on the knot, else slope·(t - t_j) + p_j.
        let ph = if ti == kt[j] {
            kp[j]
        } else {
            let slope = (kp[j + 1] - kp[j]) / (kt[j + 1] - kt[j]);
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
