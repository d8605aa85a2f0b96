//! Isotonic (least-squares monotone) regression by the pool-adjacent-violators algorithm, and
//! the monotone projection of a path between its turning points.
//!
//! [`isotonic`] is Busing's single-pass PAVA (J. Stat. Softw. 102, 2022, Algorithm 1) with
//! unit weights, in the arithmetic of `scipy.optimize.isotonic_regression` (each block's mean
//! from its running weighted sum, ties pooled, a decreasing fit as the increasing fit of the
//! reversed values), so that the numbers are SciPy's without importing SciPy.
//! [`monotone_path`] replaces each stretch between consecutive edges by its isotonic
//! regression, rising or falling as the stretch goes.

use crate::error::{check_finite, CoreError};

/// The increasing isotonic regression of `y` into `out` (same length), unit weights.
// Index arithmetic: b <= i < n, b - 1 only when b > 0, i + 1 only when i < n - 1.
#[allow(clippy::arithmetic_side_effects)]
fn pava_increasing(y: &[f64], out: &mut [f64], w: &mut Vec<f64>, r: &mut Vec<usize>) {
    let n = y.len();
    if n == 0 {
        return;
    }
    let x = out;
    x.copy_from_slice(y);
    w.clear();
    w.resize(n, 1.0);
    r.clear();
    r.resize(n + 1, 0);
    r[1] = 1;
    let mut b = 0_usize;
    let mut xb_prev = x[0];
    let mut wb_prev = w[0];
    let mut i = 1_usize;
    while i < n {
        b += 1;
        let mut xb = x[i];
        let mut wb = w[i];
        let mut sb = wb * xb;
        if xb_prev >= xb {
            b -= 1;
            sb += wb_prev * xb_prev;
            wb += wb_prev;
            xb = sb / wb;
            while i < n - 1 && xb >= x[i + 1] {
                i += 1;
                sb += w[i] * x[i];
                wb += w[i];
                xb = sb / wb;
            }
            while b > 0 && x[b - 1] >= xb {
                b -= 1;
                sb += w[b] * x[b];
                wb += w[b];
                xb = sb / wb;
            }
        }
        x[b] = xb;
        xb_prev = xb;
        w[b] = wb;
        wb_prev = wb;
        r[b + 1] = i + 1;
        i += 1;
    }
    // unpool: block k covers r[k]..r[k+1] (from the last block back, so that a block's value
    // is read before an earlier block's samples overwrite its slot)
    let blocks = b + 1;
    for k in (0..blocks).rev() {
        let v = x[k];
        for s in &mut x[r[k]..r[k + 1]] {
            *s = v;
        }
    }
}

/// The isotonic regression of `y` (unit weights), increasing or decreasing: the numbers of
/// `scipy.optimize.isotonic_regression(y, increasing=...).x`.
pub fn isotonic(y: &[f64], increasing: bool) -> Result<Vec<f64>, CoreError> {
    check_finite("y", y)?;
    let mut out = vec![0.0; y.len()];
    let (mut w, mut r) = (Vec::new(), Vec::new());
    fit_into(y, increasing, &mut out, &mut w, &mut r);
    Ok(out)
}

fn fit_into(y: &[f64], increasing: bool, out: &mut [f64], w: &mut Vec<f64>, r: &mut Vec<usize>) {
    if increasing {
        pava_increasing(y, out, w, r);
    } else {
        let rev: Vec<f64> = y.iter().rev().copied().collect();
        pava_increasing(&rev, out, w, r);
        out.reverse();
    }
}

/// `x` projected on monotone stretches between the sorted, distinct sample indices `edges`
/// (the first 0, the last `x.len()`): each stretch `edges[k]..edges[k+1]` of two samples or
/// more is replaced by its isotonic regression, rising when the sample after the stretch (its
/// own last sample for the last stretch) is not below the stretch's first.
// Index arithmetic: a < b <= n inside the loop (checked), min(b, n - 1) with n >= 1.
#[allow(clippy::arithmetic_side_effects)]
pub fn monotone_path(x: &[f64], edges: &[usize]) -> Result<Vec<f64>, CoreError> {
    check_finite("x", x)?;
    let n = x.len();
    let mut out = x.to_vec();
    for wdw in edges.windows(2) {
        let (a, b) = (wdw[0], wdw[1]);
        if a >= b || b > n {
            return Err(CoreError::InvalidParameter {
                name: "edges",
                value: b as f64,
                reason: "edges must increase strictly and end at most at the length of x",
            });
        }
    }
    let (mut w, mut r) = (Vec::new(), Vec::new());
    for wdw in edges.windows(2) {
        let (a, b) = (wdw[0], wdw[1]);
        if b - a < 2 {
            continue;
        }
        let seg = &x[a..b];
        let rising = if b == n {
            seg[seg.len() - 1] >= seg[0]
        } else {
            x[b.min(n - 1)] >= seg[0]
        };
        fit_into(seg, rising, &mut out[a..b], &mut w, &mut r);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plain PAVA by repeated pooling of adjacent violators (the definition).
    fn reference(y: &[f64]) -> Vec<f64> {
        let mut blocks: Vec<(f64, f64)> = Vec::new(); // (sum, count)
        for &v in y {
            blocks.push((v, 1.0));
            while blocks.len() > 1 {
                let (s1, c1) = blocks[blocks.len() - 1];
                let (s0, c0) = blocks[blocks.len() - 2];
                if s0 / c0 >= s1 / c1 {
                    blocks.pop();
                    blocks.pop();
                    blocks.push((s0 + s1, c0 + c1));
                } else {
                    break;
                }
            }
        }
        blocks
            .iter()
            .flat_map(|&(s, c)| std::iter::repeat_n(s / c, c as usize))
            .collect()
    }

    #[test]
    fn pava_matches_the_definition() {
        let mut state = 12345_u64;
        for n in 0..60 {
            let y: Vec<f64> = (0..n)
                .map(|_| {
                    state = state
                        .wrapping_mul(6_364_136_223_846_793_005)
                        .wrapping_add(1);
                    ((state >> 33) % 7) as f64 - 3.0
                })
                .collect();
            let got = isotonic(&y, true).unwrap();
            let want = reference(&y);
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 1e-12, "{y:?}: {got:?} vs {want:?}");
            }
            let down = isotonic(&y, false).unwrap();
            assert!(down.windows(2).all(|p| p[1] <= p[0]));
        }
    }

    #[test]
    fn monotone_path_example() {
        // the doctest of contactlab.tangential.preprocess.monotone_path
        let x = [0.0, 2.0, 1.0, 3.0, 2.0, 1.5, 1.6, 0.0];
        let got = monotone_path(&x, &[0, 3, 8]).unwrap();
        let want = [0.0, 1.5, 1.5, 3.0, 2.0, 1.55, 1.55, 0.0];
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-15, "{got:?}");
        }
        assert!(monotone_path(&x, &[0, 9]).is_err());
        assert!(monotone_path(&[f64::NAN], &[0, 1]).is_err());
    }
}
