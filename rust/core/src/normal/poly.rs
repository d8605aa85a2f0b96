//! Polynomials with ascending coefficients `c[0] + c[1] x + c[2] x² + …` (Konowalski 2009,
//! eq. 1 for the loop curves p(δ), eq. 6 for k_s(δ), eq. 16 for k_s(p)).
//!
//! The least-squares fit runs on scaled variables (x / max|x|, y / max|y|) so that SI inputs
//! (δ ~ 1e-7 m, p ~ 1e5 Pa) give a well-conditioned Vandermonde matrix; it is solved by SVD
//! with nalgebra and the coefficients are scaled back.

use nalgebra::{DMatrix, DVector};

use crate::error::{check_finite, check_same_len, CoreError};

/// `Σ c[i] x^i` by Horner's rule. An empty slice is the zero polynomial.
#[inline]
pub fn eval(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &a| acc * x + a)
}

/// Value and first derivative at `x` in one Horner pass.
#[inline]
pub fn eval_with_deriv(c: &[f64], x: f64) -> (f64, f64) {
    let mut p = 0.0;
    let mut d = 0.0;
    for &a in c.iter().rev() {
        d = d * x + p;
        p = p * x + a;
    }
    (p, d)
}

/// Coefficients of the derivative.
pub fn deriv(c: &[f64]) -> Vec<f64> {
    c.iter()
        .enumerate()
        .skip(1)
        .map(|(i, &a)| a * i as f64)
        .collect()
}

/// Coefficients of the antiderivative that vanishes at 0.
pub fn integral(c: &[f64]) -> Vec<f64> {
    std::iter::once(0.0)
        .chain(c.iter().enumerate().map(|(i, &a)| a / (i as f64 + 1.0)))
        .collect()
}

/// Weighted least-squares polynomial of `degree` through `(x, y)`, ascending coefficients.
///
/// `weights` (optional) multiply the residuals. Needs at least `degree + 1` points and a
/// non-degenerate `x` spread.
pub fn fit(
    x: &[f64],
    y: &[f64],
    degree: usize,
    weights: Option<&[f64]>,
) -> Result<Vec<f64>, CoreError> {
    check_same_len("x", x.len(), "y", y.len())?;
    check_finite("x", x)?;
    check_finite("y", y)?;
    if let Some(w) = weights {
        check_same_len("x", x.len(), "weights", w.len())?;
        check_finite("weights", w)?;
        if let Some(i) = w.iter().position(|&v| v < 0.0) {
            return Err(CoreError::InvalidParameter {
                name: "weights",
                value: w[i],
                reason: "weights must be >= 0",
            });
        }
    }
    let n = x.len();
    // degree < n, so degree + 1 cannot overflow (degree = usize::MAX is just too high).
    let m = match degree.checked_add(1) {
        Some(m) if m <= n => m,
        _ => {
            return Err(CoreError::InvalidParameter {
                name: "degree",
                value: degree as f64,
                reason: "needs at least degree + 1 points",
            })
        }
    };
    let xs = x.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
    let ys = y.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
    if xs == 0.0 {
        return Err(CoreError::InvalidParameter {
            name: "x",
            value: 0.0,
            reason: "all abscissae are zero; a polynomial cannot be fitted",
        });
    }
    let ys = if ys == 0.0 { 1.0 } else { ys };
    let mut a = DMatrix::<f64>::zeros(n, m);
    let mut b = DVector::<f64>::zeros(n);
    for i in 0..n {
        let w = weights.map_or(1.0, |w| w[i]);
        let u = x[i] / xs;
        let mut pw = w;
        for j in 0..m {
            a[(i, j)] = pw;
            pw *= u;
        }
        b[i] = w * y[i] / ys;
    }
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    if smin.is_nan() || smin <= 1e-13 * smax {
        return Err(CoreError::InvalidParameter {
            name: "x",
            value: xs,
            reason: "too few distinct abscissae for this polynomial degree",
        });
    }
    let sol = svd
        .solve(&b, 1e-14 * smax)
        .map_err(|_| CoreError::InvalidParameter {
            name: "x",
            value: xs,
            reason: "least-squares solve failed",
        })?;
    let mut scale = ys;
    let c: Vec<f64> = (0..m)
        .map(|j| {
            let c = sol[j] * scale;
            scale /= xs;
            c
        })
        .collect();
    crate::error::check_output("polynomial coefficient", &c)?;
    Ok(c)
}

/// Real roots of `c` in `[lo, hi]`, found by bracketing on a fine grid and bisection.
/// Polynomials here are of degree ≤ ~8 and the interval is the loop's range, so a grid of
/// `grid` cells (default 512 when 0) isolates roots reliably.
pub fn roots_in(c: &[f64], lo: f64, hi: f64, grid: usize) -> Vec<f64> {
    let cells = if grid == 0 { 512 } else { grid };
    let mut out = Vec::new();
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return out;
    }
    let step = (hi - lo) / cells as f64;
    let mut xa = lo;
    let mut fa = eval(c, xa);
    if fa == 0.0 {
        out.push(xa);
    }
    for k in 1..=cells {
        let xb = if k == cells { hi } else { lo + step * k as f64 };
        let fb = eval(c, xb);
        if fb == 0.0 {
            out.push(xb);
        } else if fa != 0.0 && fa.signum() != fb.signum() {
            let (mut a, mut b, mut fa2) = (xa, xb, fa);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                if m <= a || m >= b {
                    break;
                }
                let fm = eval(c, m);
                if fm == 0.0 {
                    a = m;
                    b = m;
                    break;
                }
                if fm.signum() == fa2.signum() {
                    a = m;
                    fa2 = fm;
                } else {
                    b = m;
                }
            }
            out.push(0.5 * (a + b));
        }
        xa = xb;
        fa = fb;
    }
    out
}

/// Minimum of `c` over `[lo, hi]` (at an end point or a critical point) and where it occurs.
pub fn min_on(c: &[f64], lo: f64, hi: f64) -> (f64, f64) {
    let mut best = (eval(c, lo), lo);
    let mut consider = |x: f64| {
        let v = eval(c, x);
        if v < best.0 {
            best = (v, x);
        }
    };
    consider(hi);
    for r in roots_in(&deriv(c), lo, hi, 0) {
        consider(r);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horner_and_derivative() {
        let c = [1.0, -2.0, 3.0, 0.5];
        let x = 0.7;
        let exact = 1.0 - 2.0 * x + 3.0 * x * x + 0.5 * x * x * x;
        let dexact = -2.0 + 6.0 * x + 1.5 * x * x;
        assert!((eval(&c, x) - exact).abs() < 1e-15);
        let (p, d) = eval_with_deriv(&c, x);
        assert!((p - exact).abs() < 1e-15 && (d - dexact).abs() < 1e-14);
        assert_eq!(deriv(&c), vec![-2.0, 6.0, 1.5]);
        let i = integral(&c);
        assert!((eval(&i, 1.0) - (1.0 - 1.0 + 1.0 + 0.125)).abs() < 1e-15);
    }

    #[test]
    fn fit_recovers_si_scaled_polynomial() {
        // Table 2 loading curve (MPa, µm) converted to SI: a_i * 1e6 * 1e6^i.
        let t2 = [0.01541, 1.33235, 1.49154, 2.28094, 1.57210];
        let si: Vec<f64> = t2
            .iter()
            .enumerate()
            .map(|(i, a)| a * 1e6 * 1e6_f64.powi(i as i32))
            .collect();
        let x: Vec<f64> = (0..200)
            .map(|k| -0.43e-6 + 0.65e-6 * f64::from(k) / 199.0)
            .collect();
        let y: Vec<f64> = x.iter().map(|&v| eval(&si, v)).collect();
        let c = fit(&x, &y, 4, None).unwrap();
        for (i, (&a, &b)) in c.iter().zip(&si).enumerate() {
            let back = a / 1e6 / 1e6_f64.powi(i as i32);
            assert!((back - t2[i]).abs() < 1e-9, "coef {i}: {back} vs {}", t2[i]);
            assert!(((a - b) / b).abs() < 1e-8);
        }
    }

    #[test]
    fn fit_rejects_degenerate_input() {
        assert!(fit(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0], 2, None).is_err());
        assert!(fit(&[1.0, 2.0], &[1.0, 2.0], 2, None).is_err());
        assert!(fit(&[0.0, 1.0, f64::NAN], &[1.0, 2.0, 3.0], 1, None).is_err());
        assert!(fit(&[0.0, 1.0], &[1.0, 2.0, 3.0], 1, None).is_err());
    }

    #[test]
    fn fit_with_the_largest_degree_is_an_error_not_an_overflow() {
        for degree in [usize::MAX, usize::MAX - 1, 3] {
            let r = fit(&[0.0, 1.0, 2.0], &[1.0, 2.0, 3.0], degree, None);
            assert!(matches!(
                r,
                Err(CoreError::InvalidParameter { name: "degree", .. })
            ));
        }
    }

    #[test]
    fn roots_and_minimum() {
        // (x - 0.2)(x + 0.5)(x - 1.5) = x³ - 1.2x² - 0.55x + 0.15
        let c = [0.15, -0.55, -1.2, 1.0];
        let r = roots_in(&c, -1.0, 1.0, 0);
        assert_eq!(r.len(), 2);
        assert!((r[0] + 0.5).abs() < 1e-12 && (r[1] - 0.2).abs() < 1e-12);
        let (v, at) = min_on(&[1.0, 0.0, 1.0], -1.0, 2.0);
        assert!((v - 1.0).abs() < 1e-15 && at.abs() < 1e-12);
    }

    proptest::proptest! {
        #[test]
        fn fit_round_trips_exact_samples(
            c in proptest::collection::vec(-3.0_f64..3.0, 1..6),
            xscale in 1e-8_f64..1e2,
            n in 12_usize..80,
        ) {
            let x: Vec<f64> = (0..n).map(|k| xscale * (-1.0 + 2.0 * k as f64 / (n - 1) as f64)).collect();
            // Coefficients scaled so every term is O(1) on the interval.
            let cs: Vec<f64> = c.iter().enumerate().map(|(i, a)| a / xscale.powi(i as i32)).collect();
            let y: Vec<f64> = x.iter().map(|&v| eval(&cs, v)).collect();
            let got = fit(&x, &y, cs.len() - 1, None).unwrap();
            for (i, (g, e)) in got.iter().zip(&cs).enumerate() {
                let tol = 1e-9 / xscale.powi(i as i32);
                proptest::prop_assert!((g - e).abs() <= tol, "coef {}: {} vs {}", i, g, e);
            }
        }

        #[test]
        fn roots_found_are_roots(
            r1 in -1.0_f64..1.0, r2 in -1.0_f64..1.0, r3 in -1.0_f64..1.0,
        ) {
            // (x - r1)(x - r2)(x - r3)
            let c = [-r1 * r2 * r3, r1 * r2 + r1 * r3 + r2 * r3, -(r1 + r2 + r3), 1.0];
            for r in roots_in(&c, -1.5, 1.5, 0) {
                proptest::prop_assert!(eval(&c, r).abs() < 1e-9);
            }
        }
    }
}
