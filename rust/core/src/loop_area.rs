//! Loop areas `∮ F dx` of cycles (shoelace sums) and their sensitivity to sample noise.
//!
//! [`loop_area`] makes two passes over the samples, both vectorised and dispatched at run
//! time ([`crate::simd`]): one for finiteness, the largest magnitudes and the force sum,
//! one for the compensated sum of the trapezoid terms. The samples are scaled by powers of
//! two (exact: no rounding, no division per sample) so that 1e±300 data neither overflow
//! nor underflow.

use crate::error::{check_same_len, CoreError};
use crate::simd::{self, dispatch};

/// Independent chains of additions in the sums (two AVX2 registers, one AVX-512 register).
const LANES: usize = 8;

/// What the first pass finds: all finite, max |x|, max |F|, Σ F.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scan {
    pub finite: bool,
    pub ax: f64,
    pub af: f64,
    pub sum_f: f64,
}

/// Finiteness, largest magnitudes and force sum of `(x, F)` (same length) in one pass.
#[inline(always)]
fn scan_pair_generic(x: &[f64], f: &[f64]) -> Scan {
    let n = x.len().min(f.len());
    let (x, f) = (&x[..n], &f[..n]);
    let (mut ax, mut af, mut sf, mut nan) = (
        [0.0_f64; LANES],
        [0.0_f64; LANES],
        [0.0_f64; LANES],
        [0.0_f64; LANES],
    );
    let mut xc = x.chunks_exact(LANES);
    let mut fc = f.chunks_exact(LANES);
    for (xs, fs) in (&mut xc).zip(&mut fc) {
        for k in 0..LANES {
            let (u, v) = (xs[k].abs(), fs[k].abs());
            ax[k] = if u > ax[k] { u } else { ax[k] };
            af[k] = if v > af[k] { v } else { af[k] };
            sf[k] += fs[k];
            // x * 0 is 0 for a finite x, NaN for inf or NaN
            nan[k] += xs[k] * 0.0 + fs[k] * 0.0;
        }
    }
    for (k, (&u, &v)) in xc.remainder().iter().zip(fc.remainder()).enumerate() {
        ax[k] = if u.abs() > ax[k] { u.abs() } else { ax[k] };
        af[k] = if v.abs() > af[k] { v.abs() } else { af[k] };
        sf[k] += v;
        nan[k] += u * 0.0 + v * 0.0;
    }
    let max = |a: [f64; LANES]| a.iter().fold(0.0_f64, |m, &v| if v > m { v } else { m });
    Scan {
        finite: nan.iter().all(|&v| v == 0.0),
        ax: max(ax),
        af: max(af),
        sum_f: sf.iter().sum(),
    }
}

dispatch! {
    /// [`scan_pair_generic`] at `level`.
    pub fn scan_pair(x: &[f64], f: &[f64]) -> Scan = scan_pair_generic;
}

/// Lane sums of the trapezoid terms `0.5 (F_i' + F_{i+1}') (x_{i+1}' - x_i')` over
/// `i < n - 1`, with `x' = x·ux`, `F' = F·uf - fm`: sample pair `i` in lane `i mod 8` (the
/// pairs past the last whole block of 8 are left to the caller), each lane compensated by
/// Knuth's two-sum (`s + c` is the lane's sum to rounding of the compensation).
// Index arithmetic: n >= 2 checked.
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
fn shoelace_generic(
    x: &[f64],
    f: &[f64],
    ux: f64,
    uf: f64,
    fm: f64,
) -> ([f64; LANES], [f64; LANES]) {
    let n = x.len().min(f.len());
    let (mut s, mut c) = ([0.0_f64; LANES], [0.0_f64; LANES]);
    if n < 2 {
        return (s, c);
    }
    let (xa, xb, fa, fb) = (&x[..n - 1], &x[1..n], &f[..n - 1], &f[1..n]);
    let it = xa
        .chunks_exact(LANES)
        .zip(xb.chunks_exact(LANES))
        .zip(fa.chunks_exact(LANES))
        .zip(fb.chunks_exact(LANES));
    for (((xa, xb), fa), fb) in it {
        for k in 0..LANES {
            let v = term(xa[k], xb[k], fa[k], fb[k], ux, uf, fm);
            let t = s[k] + v;
            let bb = t - s[k];
            c[k] += (s[k] - (t - bb)) + (v - bb);
            s[k] = t;
        }
    }
    (s, c)
}

dispatch! {
    /// [`shoelace_generic`] at `level`.
    pub fn shoelace(x: &[f64], f: &[f64], ux: f64, uf: f64, fm: f64) -> ([f64; LANES], [f64; LANES]) = shoelace_generic;
}

/// One trapezoid term of scaled, centred samples (the same expression on every path).
#[inline(always)]
fn term(xi: f64, xj: f64, fi: f64, fj: f64, ux: f64, uf: f64, fm: f64) -> f64 {
    let (fi, fj) = (fi * uf - fm, fj * uf - fm);
    0.5 * (fi + fj) * (xj * ux - xi * ux)
}

/// The power of two at or below a positive finite `a` (the smallest normal one for a
/// subnormal `a`), and its reciprocal: exact scale factors.
fn pow2_scale(a: f64) -> (f64, f64) {
    let p = f64::from_bits(a.to_bits() & 0x7ff0_0000_0000_0000);
    let p = if p == 0.0 { f64::MIN_POSITIVE } else { p };
    (p, 1.0 / p)
}

/// Neumaier's compensated sum.
#[derive(Default)]
struct Neumaier {
    sum: f64,
    comp: f64,
}

impl Neumaier {
    fn add(&mut self, v: f64) {
        let t = self.sum + v;
        if self.sum.abs() >= v.abs() {
            self.comp += (self.sum - t) + v;
        } else {
            self.comp += (v - t) + self.sum;
        }
        self.sum = t;
    }
}

/// `∮ F dx` of the closed polygon through `(x_i, F_i)` (last point joined to the first):
/// positive for a clockwise (dissipative) loop. Uses the trapezoid form with the mean force
/// removed and compensated summation, so large offsets in `x` or `F` cost no accuracy.
///
/// The samples are scaled by powers of two near their largest magnitudes (exact), the
/// terms summed in eight compensated lanes combined by a compensated sum: the area to about
/// 1e-16 of the terms' scale. Bit for bit the same on every SIMD level.
pub fn loop_area(x: &[f64], f: &[f64]) -> Result<f64, CoreError> {
    loop_area_at(simd::level(), x, f)
}

/// [`loop_area`] with its kernels at `level` (the tests compare the levels).
// Index arithmetic: n >= 1; the tail runs over pairs below n - 1.
#[allow(clippy::arithmetic_side_effects)]
pub fn loop_area_at(level: simd::Level, x: &[f64], f: &[f64]) -> Result<f64, CoreError> {
    check_same_len("x", x.len(), "F", f.len())?;
    let n = x.len();
    if n == 0 {
        return Err(CoreError::Empty { name: "x" });
    }
    let sc = scan_pair(level, x, f);
    if !sc.finite {
        // name the first non-finite sample
        crate::error::check_finite("x", x)?;
        crate::error::check_finite("F", f)?;
    }
    if sc.ax == 0.0 || sc.af == 0.0 {
        return Ok(0.0);
    }
    let (sx, ux) = pow2_scale(sc.ax);
    let (sf, uf) = pow2_scale(sc.af);
    // Σ F·uf = uf Σ F exactly unless Σ F overflowed (then sum the scaled samples)
    let sum_scaled = if sc.sum_f.is_finite() {
        sc.sum_f * uf
    } else {
        f.iter().map(|&v| v * uf).sum::<f64>()
    };
    let fm = sum_scaled / n as f64;
    let (s, c) = shoelace(level, x, f, ux, uf, fm);
    let mut a = Neumaier::default();
    for &v in &s {
        a.add(v);
    }
    a.comp += c.iter().sum::<f64>();
    let done = (n - 1) / LANES * LANES;
    for i in done..n - 1 {
        a.add(term(x[i], x[i + 1], f[i], f[i + 1], ux, uf, fm));
    }
    // the closing term, last sample to first
    a.add(term(x[n - 1], x[0], f[n - 1], f[0], ux, uf, fm));
    let area = (a.sum + a.comp) * sx * sf;
    crate::error::check_output("loop area", &[area])?;
    Ok(area)
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
            loop_area(&x[a..b], &f[a..b])?
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

    /// The implementation before the dispatched one (divisions per sample, one Neumaier
    /// chain): the accuracy reference.
    /// `∮ F dx` of the closed polygon through `(x_i, F_i)` (last point joined to the first):
    /// positive for a clockwise (dissipative) loop. Uses the trapezoid form with the mean force
    /// removed and compensated summation, so large offsets in `x` or `F` cost no accuracy.
    fn loop_area_before(x: &[f64], f: &[f64]) -> Result<f64, CoreError> {
        crate::error::check_same_len("x", x.len(), "F", f.len())?;
        if x.is_empty() {
            return Err(CoreError::Empty { name: "x" });
        }
        crate::error::check_finite("x", x)?;
        crate::error::check_finite("F", f)?;
        let n = x.len();
        // Work in units of the largest |x| and |F| so that sums and products of 1e±300 data
        // neither overflow nor underflow (found by fuzzing); the scales multiply the result.
        let sx = x.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
        let sf = f.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
        if sx == 0.0 || sf == 0.0 {
            return Ok(0.0);
        }
        let fm = f.iter().map(|&v| v / sf).sum::<f64>() / n as f64;
        let (mut sum, mut comp) = (0.0_f64, 0.0_f64);
        // Point i joined to the next, the last to the first.
        for (i, j) in (0..n).zip((1..n).chain(std::iter::once(0))) {
            let (fi, fj) = (f[i] / sf - fm, f[j] / sf - fm);
            let term = 0.5 * (fi + fj) * (x[j] / sx - x[i] / sx);
            // Neumaier summation.
            let t = sum + term;
            if sum.abs() >= term.abs() {
                comp += (sum - t) + term;
            } else {
                comp += (term - t) + sum;
            }
            sum = t;
        }
        let area = (sum + comp) * sx * sf;
        crate::error::check_output("loop area", &[area])?;
        Ok(area)
    }

    fn signal(n: usize, seed: u64, scale: f64, offset: f64) -> (Vec<f64>, Vec<f64>) {
        let mut r = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = || {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            (r >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let x: Vec<f64> = (0..n)
            .map(|i| scale * ((i as f64 * 0.01).sin() + 0.01 * next()) + offset)
            .collect();
        let f: Vec<f64> = (0..n)
            .map(|i| scale * ((i as f64 * 0.01 + 0.3).sin() + 0.01 * next()) - 3.0 * offset)
            .collect();
        (x, f)
    }

    #[test]
    fn every_simd_level_equals_the_generic_one_bit_for_bit() {
        for &(n, scale, offset) in &[
            (1, 1.0, 0.0),
            (2, 1.0, 0.5),
            (3, 1e-3, 0.0),
            (7, 1.0, 0.0),
            (8, 1.0, 1.0),
            (9, 1e150, 0.0),
            (17, 1e-150, 0.0),
            (1000, 1.0, 100.0),
            (100_003, 40e-6, 1e-3),
        ] {
            let (x, f) = signal(n, n as u64, scale, offset * scale);
            let want = loop_area_at(crate::simd::Level::Generic, &x, &f).unwrap();
            for lv in crate::simd::Level::ALL
                .into_iter()
                .filter(|l| l.supported())
            {
                let got = loop_area_at(lv, &x, &f).unwrap();
                assert_eq!(got.to_bits(), want.to_bits(), "{lv:?} n={n}");
                assert_eq!(
                    scan_pair(lv, &x, &f),
                    scan_pair(crate::simd::Level::Generic, &x, &f)
                );
            }
        }
    }

    #[test]
    fn as_accurate_as_the_sequential_neumaier_sum() {
        for seed in 0..40_u64 {
            let n = 3 + (seed as usize * 7919) % 5000;
            let scale = [1.0, 1e-6, 1e6, 1e-150, 1e150][seed as usize % 5];
            let (x, f) = signal(n, seed, scale, (seed % 3) as f64 * 10.0 * scale);
            let new = loop_area(&x, &f).unwrap();
            let old = loop_area_before(&x, &f).unwrap();
            // the terms' scale: Σ |ΔF| |Δx| of the polygon's edges
            let mag: f64 = (0..n)
                .map(|i| {
                    let j = (i + 1) % n;
                    (f[i] - f[j]).abs().max(f[i].abs() * 1e-3) * (x[j] - x[i]).abs()
                })
                .sum();
            assert!(
                (new - old).abs() <= 1e-13 * mag,
                "seed {seed}: {new} vs {old} (scale {mag})"
            );
        }
        // exactly representable areas stay exact: a unit square traversed clockwise
        let x = [0.0, 0.0, 1.0, 1.0];
        let f = [0.0, 1.0, 1.0, 0.0];
        assert_eq!(loop_area(&x, &f).unwrap(), 1.0);
        assert_eq!(loop_area(&[0.0; 5], &[1.0; 5]).unwrap(), 0.0);
        assert!(loop_area(&[0.0, f64::NAN], &[1.0, 2.0]).is_err());
        assert!(loop_area(&[], &[]).is_err());
    }

    #[test]
    fn loop_area_sensitivity_matches_finite_differences() {
        let x = [0.0, 1.0, 2.0, 1.5, 0.3, -0.4, 0.1];
        let f = [0.5, 1.0, 0.2, -0.7, -1.0, 0.0, 0.4];
        let (sf, sx) = loop_area_sensitivity(&x, &f, &[0, 7]).unwrap();
        let area = |x: &[f64], f: &[f64]| loop_area(x, f).unwrap();
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
