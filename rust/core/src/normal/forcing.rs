//! The driving pressure between samples: a piecewise polynomial through `(t_i, p_i)`.
//!
//! - `Linear`: straight lines between samples (C0).
//! - `Cubic`: cubic Hermite (C1) with slopes `dpdt` when given, else the second-order finite
//!   differences of `numpy.gradient(p, t, edge_order=2)`. scipy's
//!   `CubicHermiteSpline(t, p, np.gradient(p, t, edge_order=2))` is the same function, which
//!   lets a benchmark hand scipy exactly the problem the core solves.
//!
//! Slopes are computed per interval from three neighbours, so the interpolant needs no memory
//! beyond the caller's arrays (O(1) extra for any length).

use crate::error::{check_finite, check_same_len, CoreError};

/// How `p(t)` is continued between samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interp {
    Linear,
    Cubic,
}

/// One interval of the interpolant: `p = c0 + c1 s + c2 s² + c3 s³`, `s = (t - t0) / h`.
#[derive(Debug, Clone, Copy)]
pub struct Segment {
    pub t0: f64,
    pub h: f64,
    /// `1 / h` (multiplying is cheaper than dividing in the integrator's inner loop).
    pub inv_h: f64,
    pub c: [f64; 4],
}

impl Segment {
    /// The cubic Hermite segment from `(t0, p0)` to `(t0 + h, p1)` with slopes `d0`, `d1`.
    #[inline]
    pub fn hermite(t0: f64, h: f64, p0: f64, p1: f64, d0: f64, d1: f64) -> Self {
        let (m0, m1) = (h * d0, h * d1);
        Self {
            t0,
            h,
            inv_h: 1.0 / h,
            c: [
                p0,
                m0,
                3.0 * (p1 - p0) - 2.0 * m0 - m1,
                2.0 * (p0 - p1) + m0 + m1,
            ],
        }
    }

    /// `p(t)`.
    #[inline]
    pub fn value(&self, t: f64) -> f64 {
        let s = (t - self.t0) * self.inv_h;
        self.c[0] + s * (self.c[1] + s * (self.c[2] + s * self.c[3]))
    }

    /// `p(t)` and `dp/dt`.
    #[inline]
    pub fn value_deriv(&self, t: f64) -> (f64, f64) {
        let s = (t - self.t0) * self.inv_h;
        let p = self.c[0] + s * (self.c[1] + s * (self.c[2] + s * self.c[3]));
        let d = (self.c[1] + s * (2.0 * self.c[2] + s * 3.0 * self.c[3])) * self.inv_h;
        (p, d)
    }
}

/// A validated sampled forcing `p(t)`.
#[derive(Debug, Clone, Copy)]
pub struct Forcing<'a> {
    t: &'a [f64],
    p: &'a [f64],
    dpdt: Option<&'a [f64]>,
    interp: Interp,
}

/// Check that `t` is finite and strictly increasing.
pub fn check_time(t: &[f64]) -> Result<(), CoreError> {
    check_finite("t", t)?;
    for (index, w) in (1..).zip(t.windows(2)) {
        if w[1] <= w[0] {
            return Err(CoreError::NotIncreasing {
                name: "t",
                index,
                value: w[1],
                prev: w[0],
            });
        }
    }
    Ok(())
}

impl<'a> Forcing<'a> {
    /// Validate lengths, finiteness and monotone time (at least two samples).
    pub fn new(
        t: &'a [f64],
        p: &'a [f64],
        dpdt: Option<&'a [f64]>,
        interp: Interp,
    ) -> Result<Self, CoreError> {
        if t.is_empty() {
            return Err(CoreError::Empty { name: "t" });
        }
        check_same_len("t", t.len(), "p", p.len())?;
        if t.len() < 2 {
            return Err(CoreError::InvalidParameter {
                name: "len(t)",
                value: t.len() as f64,
                reason: "at least two samples are needed",
            });
        }
        check_time(t)?;
        check_finite("p", p)?;
        if let Some(d) = dpdt {
            check_same_len("t", t.len(), "dpdt", d.len())?;
            check_finite("dpdt", d)?;
        }
        Ok(Self { t, p, dpdt, interp })
    }

    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    pub fn times(&self) -> &'a [f64] {
        self.t
    }

    pub fn values(&self) -> &'a [f64] {
        self.p
    }

    /// Whether exact slopes `dpdt` were given.
    pub fn has_dpdt(&self) -> bool {
        self.dpdt.is_some()
    }

    /// How `p` is continued between samples.
    pub fn interp(&self) -> Interp {
        self.interp
    }

    /// Slope at sample `i < len` (given, or `numpy.gradient(..., edge_order=2)`).
    // Index arithmetic only: `i < len` (checked by the caller) and `len >= 2` (checked by
    // `Forcing::new`), so no index over- or underflows.
    #[allow(clippy::arithmetic_side_effects)]
    pub(crate) fn slope(&self, i: usize) -> f64 {
        if let Some(d) = self.dpdt {
            return d[i];
        }
        let (t, p, n) = (self.t, self.p, self.t.len());
        if n == 2 {
            return (p[1] - p[0]) / (t[1] - t[0]);
        }
        if i == 0 {
            let (d1, d2) = (t[1] - t[0], t[2] - t[1]);
            let a = -(2.0 * d1 + d2) / (d1 * (d1 + d2));
            let b = (d1 + d2) / (d1 * d2);
            let c = -d1 / (d2 * (d1 + d2));
            a * p[0] + b * p[1] + c * p[2]
        } else if i == n - 1 {
            let (d1, d2) = (t[n - 2] - t[n - 3], t[n - 1] - t[n - 2]);
            let a = d2 / (d1 * (d1 + d2));
            let b = -(d2 + d1) / (d1 * d2);
            let c = (2.0 * d2 + d1) / (d2 * (d1 + d2));
            a * p[n - 3] + b * p[n - 2] + c * p[n - 1]
        } else {
            let (d1, d2) = (t[i] - t[i - 1], t[i + 1] - t[i]);
            let a = -d2 / (d1 * (d1 + d2));
            let b = (d2 - d1) / (d1 * d2);
            let c = d1 / (d2 * (d1 + d2));
            a * p[i - 1] + b * p[i] + c * p[i + 1]
        }
    }

    /// The interpolant on `[t_i, t_{i+1}]`, `i < len - 1`.
    // Index arithmetic only: `i < len` (checked by the caller) and `len >= 2` (checked by
    // `Forcing::new`), so no index over- or underflows.
    #[allow(clippy::arithmetic_side_effects)]
    pub(crate) fn segment(&self, i: usize) -> Segment {
        let (t0, t1) = (self.t[i], self.t[i + 1]);
        let (p0, p1) = (self.p[i], self.p[i + 1]);
        let h = t1 - t0;
        let c = match self.interp {
            Interp::Linear => [p0, p1 - p0, 0.0, 0.0],
            Interp::Cubic => {
                return Segment::hermite(t0, h, p0, p1, self.slope(i), self.slope(i + 1));
            }
        };
        Segment {
            t0,
            h,
            inv_h: 1.0 / h,
            c,
        }
    }

    /// `dp/dt` at sample `i < len` as the interpolant sees it (right-sided at the last sample).
    // Index arithmetic only: `i < len` (checked by the caller) and `len >= 2` (checked by
    // `Forcing::new`), so no index over- or underflows.
    #[allow(clippy::arithmetic_side_effects)]
    pub(crate) fn sample_deriv(&self, i: usize) -> f64 {
        match self.interp {
            Interp::Cubic => self.slope(i),
            Interp::Linear => {
                let j = i.min(self.t.len() - 2);
                (self.p[j + 1] - self.p[j]) / (self.t[j + 1] - self.t[j])
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_hermite_reproduces_cubics_with_exact_slopes() {
        let f = |t: f64| 1.0 + 2.0 * t - 0.5 * t * t + 0.25 * t * t * t;
        let df = |t: f64| 2.0 - t + 0.75 * t * t;
        let t: Vec<f64> = (0..7)
            .map(|k| 0.3 * f64::from(k) + 0.01 * f64::from(k * k))
            .collect();
        let p: Vec<f64> = t.iter().map(|&v| f(v)).collect();
        let d: Vec<f64> = t.iter().map(|&v| df(v)).collect();
        let fo = Forcing::new(&t, &p, Some(&d), Interp::Cubic).unwrap();
        for i in 0..t.len() - 1 {
            let s = fo.segment(i);
            for q in [0.0, 0.2, 0.5, 0.9, 1.0] {
                let tt = t[i] + q * (t[i + 1] - t[i]);
                let (v, dv) = s.value_deriv(tt);
                assert!((v - f(tt)).abs() < 1e-12 && (dv - df(tt)).abs() < 1e-11);
            }
        }
    }

    #[test]
    fn finite_difference_slopes_are_exact_for_quadratics() {
        let t = [0.0, 0.1, 0.25, 0.3, 0.7];
        let p: Vec<f64> = t.iter().map(|&v| 3.0 - v + 2.0 * v * v).collect();
        let fo = Forcing::new(&t, &p, None, Interp::Cubic).unwrap();
        for (i, &tv) in t.iter().enumerate() {
            assert!((fo.slope(i) - (-1.0 + 4.0 * tv)).abs() < 1e-12);
        }
    }

    #[test]
    fn rejects_bad_time() {
        let p = [0.0, 1.0, 2.0];
        assert!(matches!(
            Forcing::new(&[0.0, 1.0, 1.0], &p, None, Interp::Cubic),
            Err(CoreError::NotIncreasing { index: 2, .. })
        ));
        assert!(matches!(
            Forcing::new(&[0.0, 1.0], &p, None, Interp::Cubic),
            Err(CoreError::LengthMismatch { .. })
        ));
        assert!(Forcing::new(&[0.0], &[1.0], None, Interp::Linear).is_err());
        assert!(Forcing::new(&[0.0, f64::NAN, 2.0], &p, None, Interp::Linear).is_err());
    }
}
