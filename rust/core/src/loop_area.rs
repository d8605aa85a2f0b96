//! Loop areas `∮ F dx` of cycles (shoelace sums) and their sensitivity to sample noise.

use crate::error::{check_same_len, CoreError};

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

/// Noise sensitivity of each cycle's loop area `x[bounds[k]..bounds[k+1]]`: the shoelace
/// area is linear in every sample's `F` with coefficient `(x[i-1] - x[i+1]) / 2` and in its
/// `x` with `(F[i+1] - F[i-1]) / 2` (indices cyclic within the cycle). Returns per cycle
/// `(Σ coef_F², Σ coef_x²)`, so that independent sample noise `σF`, `σx` gives the area a
/// variance `σF² Σ coef_F² + σx² Σ coef_x²`.
// Index arithmetic: i < m = b - a with a <= b <= len checked, so a + (i ± 1) mod m < len.
#[allow(clippy::arithmetic_side_effects)]
pub fn loop_area_sensitivity(
    x: &[f64],
    f: &[f64],
    bounds: &[usize],
) -> Result<(Vec<f64>, Vec<f64>), CoreError> {
    check_same_len("x", x.len(), "F", f.len())?;
    let cycles = bounds.len().saturating_sub(1);
    let (mut out_f, mut out_x) = (Vec::with_capacity(cycles), Vec::with_capacity(cycles));
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b > x.len() || a > b {
            return Err(CoreError::InvalidParameter {
                name: "bounds",
                value: b as f64,
                reason: "cycle bounds must be non-decreasing and within the signal",
            });
        }
        let (xs, fs) = (&x[a..b], &f[a..b]);
        let m = xs.len();
        let (mut sf, mut sx) = (0.0_f64, 0.0_f64);
        for i in 0..m {
            let (p, n) = (
                if i == 0 { m - 1 } else { i - 1 },
                if i + 1 == m { 0 } else { i + 1 },
            );
            let cf = 0.5 * (xs[p] - xs[n]);
            let cx = 0.5 * (fs[n] - fs[p]);
            sf += cf * cf;
            sx += cx * cx;
        }
        out_f.push(sf);
        out_x.push(sx);
    }
    Ok((out_f, out_x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loop_area_sensitivity_matches_finite_differences() {
        let x = [0.0, 1.0, 2.0, 1.5, 0.3, -0.4, 0.1];
        let f = [0.5, 1.0, 0.2, -0.7, -1.0, 0.0, 0.4];
        let (sf, sx) = loop_area_sensitivity(&x, &f, &[0, 7]).unwrap();
        let area = |x: &[f64], f: &[f64]| crate::masing::loop_area(x, f).unwrap();
        let (mut gf, mut gx) = (0.0, 0.0);
        let h = 1e-6;
        for i in 0..7 {
            let mut f2 = f;
            f2[i] += h;
            let d = (area(&x, &f2) - area(&x, &f)) / h;
            gf += d * d;
            let mut x2 = x;
            x2[i] += h;
            let d = (area(&x2, &f) - area(&x, &f)) / h;
            gx += d * d;
        }
        assert!((sf[0] - gf).abs() < 1e-6 * gf.max(1.0), "{} {}", sf[0], gf);
        assert!((sx[0] - gx).abs() < 1e-6 * gx.max(1.0), "{} {}", sx[0], gx);
        assert!(loop_area_sensitivity(&x, &f, &[3, 2]).is_err());
    }
}
