//! The per-sample work of one analysis window of a tangential recording, in one call.
//!
//! [`fold_window`] folds the window's samples into phase bins (the cycle averaging) and, in
//! the same call (one release of the Python lock), derives what the analysis needs of the
//! samples: the cycle bounds, each cycle's loop area `∮ F dx` and its noise sensitivities,
//! and the period means of `F` and `x` between the turns.

use crate::error::CoreError;
use crate::signal::{fold_phase, loop_area_sensitivity, loop_areas, period_means, FoldSums};

/// One window folded: the fold sums, and per cycle its sample bounds,
/// loop area, the area's noise sensitivities (`Σ coef_F²`, `Σ coef_x²`, see
/// [`loop_area_sensitivity`]) and the period means of `F` and `x` between consecutive
/// `edges` (the peak instants).
#[derive(Debug, Clone, PartialEq)]
pub struct WindowFold {
    pub sums: FoldSums,
    /// First sample of each cycle, and the end of the last (`n_cycles + 1` values).
    pub bounds: Vec<usize>,
    pub energy: Vec<f64>,
    pub sens_f: Vec<f64>,
    pub sens_x: Vec<f64>,
    pub mean_f: Vec<f64>,
    pub mean_x: Vec<f64>,
    /// The edges of the period means.
    pub edges: Vec<f64>,
}

/// Fold `(t, x, F)` (one window, `t` strictly increasing) by the phase knots `(kt, kp)` into
/// `n_bins` bins per cycle over `n_cycles` cycles (as [`fold_phase`]) and derive the
/// per-cycle quantities (see [`WindowFold`]). The samples folded are those with
/// `kt[0] <= t < kt[last]`; a cycle's samples run from its first folded sample to the next
/// cycle's (the last to the first sample at or after `kt[last]`).
pub fn fold_window(
    t: &[f64],
    x: &[f64],
    f: &[f64],
    kt: &[f64],
    kp: &[f64],
    n_bins: usize,
    n_cycles: usize,
    edges: &[f64],
) -> Result<WindowFold, CoreError> {
    let mut sums = FoldSums::new(n_bins, n_cycles)?;
    // checks t, x, F and the knots before anything is added
    fold_phase(t, x, f, 0, kt, kp, &mut sums)?;
    let t1 = kt
        .last()
        .copied()
        .ok_or(CoreError::Empty { name: "knot_t" })?;
    // t is strictly increasing (period_means below checks it): the fold covers ..end
    let end = t.partition_point(|&v| v < t1);
    let bounds = cycle_bounds(&sums.first, end);
    let energy = loop_areas(x, f, &bounds)?;
    let (sens_f, sens_x) = loop_area_sensitivity(x, f, &bounds)?;
    let mean_f = period_means(t, f, edges)?;
    let mean_x = period_means(t, x, edges)?;
    Ok(WindowFold {
        sums,
        bounds,
        energy,
        sens_f,
        sens_x,
        mean_f,
        mean_x,
        edges: edges.to_vec(),
    })
}

/// Sample index where each cycle starts (a cycle without samples starts where the next one
/// does), and `end` after the last: `minimum.accumulate` from the end, as numpy would.
fn cycle_bounds(first: &[i64], end: usize) -> Vec<usize> {
    let mut out = vec![end; first.len().saturating_add(1)];
    let mut next = end;
    for (o, &fi) in out.iter_mut().zip(first).rev() {
        if let Ok(v) = usize::try_from(fi) {
            next = next.min(v);
        }
        *o = next;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn knots(t: &[f64], period: f64, n_cyc: usize) -> (Vec<f64>, Vec<f64>) {
        // peaks at t0 + k·period, valleys half way
        let t0 = t[3];
        let mut kt = Vec::new();
        let mut kp = Vec::new();
        for k in 0..=n_cyc {
            kt.push(t0 + k as f64 * period);
            kp.push(k as f64);
            if k < n_cyc {
                kt.push(t0 + (k as f64 + 0.5) * period);
                kp.push(k as f64 + 0.5);
            }
        }
        (kt, kp)
    }

    fn signal(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let mut noise = move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let t: Vec<f64> = (0..n).map(|i| 0.37 + i as f64 * 1e-3).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&v| (6.0 * v).sin() + 0.01 * noise())
            .collect();
        let f: Vec<f64> = t
            .iter()
            .map(|&v| (6.0 * v + 0.4).sin() + 0.05 * noise())
            .collect();
        (t, x, f)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// One call equals the separate kernels: `fold_phase`, the bounds numpy derives from
        /// the fold's first samples, `loop_areas`, `loop_area_sensitivity`, `period_means`.
        #[test]
        fn one_call_equals_the_separate_kernels(
            seed in 0u64..1000, n_bins in 4usize..40, n_cyc in 1usize..5, start in 0usize..300,
        ) {
            let (t, x, f) = signal(4000, seed);
            let period = 2.0 * std::f64::consts::PI / 6.0;
            let (kt, kp) = knots(&t[start..], period, n_cyc);
            let edges: Vec<f64> = kt.iter().step_by(2).copied().collect();
            let w = fold_window(&t, &x, &f, &kt, &kp, n_bins, n_cyc, &edges).unwrap();
            let mut plain = FoldSums::new(n_bins, n_cyc).unwrap();
            fold_phase(&t, &x, &f, 0, &kt, &kp, &mut plain).unwrap();
            prop_assert_eq!(&w.sums, &plain);
            // numpy: first = r_[first, end]; where(first < 0, end, first); minimum.accumulate
            // from the end (end: the first sample at or after the last knot)
            let end = t.iter().position(|&v| v >= kt[kt.len() - 1]).unwrap_or(t.len());
            let mut b: Vec<usize> = plain
                .first
                .iter()
                .map(|&v| if v < 0 { end } else { v as usize })
                .chain(std::iter::once(end))
                .collect();
            for i in (0..b.len() - 1).rev() {
                b[i] = b[i].min(b[i + 1]);
            }
            prop_assert_eq!(&w.bounds, &b);
            prop_assert_eq!(w.energy, loop_areas(&x, &f, &b).unwrap());
            let (sf, sx) = loop_area_sensitivity(&x, &f, &b).unwrap();
            prop_assert_eq!((w.sens_f, w.sens_x), (sf, sx));
            prop_assert_eq!(w.mean_f, period_means(&t, &f, &edges).unwrap());
            prop_assert_eq!(w.mean_x, period_means(&t, &x, &edges).unwrap());
            prop_assert_eq!(w.edges, edges);
        }
    }

    #[test]
    fn bounds_fill_empty_cycles_from_the_next() {
        assert_eq!(cycle_bounds(&[0, -1, 7, -1], 9), vec![0, 7, 7, 9, 9]);
        assert_eq!(cycle_bounds(&[], 4), vec![4]);
    }

    #[test]
    fn bad_input_is_an_error() {
        let (t, x, f) = signal(2000, 1);
        let (kt, kp) = knots(&t, 1.0, 1);
        let e = [kt[0], kt[2]];
        assert!(fold_window(&t, &x, &f, &kt, &kp, 8, 1, &e).is_ok());
        assert!(fold_window(&t, &x[1..], &f, &kt, &kp, 8, 1, &e).is_err());
        assert!(fold_window(&t, &x, &f, &kt, &kp, 0, 1, &e).is_err());
        assert!(fold_window(&t, &x, &f, &kt[..1], &kp[..1], 8, 1, &e).is_err());
        let mut tb = t.clone();
        tb[5] = tb[4];
        assert!(fold_window(&tb, &x, &f, &kt, &kp, 8, 1, &e).is_err());
        assert!(fold_window(&t, &x, &f, &kt, &kp, 8, 1, &[e[1], e[0]]).is_err());
    }
}
