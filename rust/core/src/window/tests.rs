use super::*;
use crate::fold::{fold_phase, fold_spread, period_means, FoldSums};
use crate::loop_area::{loop_area_sensitivity, loop_areas};
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

fn signal(n: usize, seed: u64, scale: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
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
        .map(|&v| scale * ((6.0 * v).sin() + 0.01 * noise()))
        .collect();
    let f: Vec<f64> = t
        .iter()
        .map(|&v| (6.0 * v + 0.4).sin() + 0.05 * noise() + 0.3)
        .collect();
    (t, x, f)
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    let big = b.iter().fold(
        0.0_f64,
        |m, v| if v.is_finite() { m.max(v.abs()) } else { m },
    );
    a.len() == b.len()
        && a.iter().zip(b).all(|(u, v)| {
            (u.is_nan() && v.is_nan()) || (u - v).abs() <= tol * big.max(f64::MIN_POSITIVE)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// One pass equals the separate kernels: `fold_phase`'s per-bin sums and
    /// `period_means` bit for bit; `fold_spread`, the bounds numpy derives from the
    /// fold's first samples, `loop_areas`, `loop_area_sensitivity` to rounding.
    #[test]
    fn one_pass_equals_the_separate_kernels(
        seed in 0u64..1000, n_bins in 4usize..40, n_cyc in 1usize..5, start in 0usize..300,
        scale in prop::sample::select(vec![1.0, 1e-6, 1e150, 1e-150]),
    ) {
        let (t, x, f) = signal(4000, seed, scale);
        let period = 2.0 * std::f64::consts::PI / 6.0;
        let (kt, kp) = knots(&t[start..], period, n_cyc);
        let edges: Vec<f64> = kt.iter().step_by(2).copied().collect();
        let w = fold_window(&t, &x, &f, &kt, &kp, n_bins, n_cyc, &edges).unwrap();
        let mut s = FoldSums::new(n_bins, n_cyc).unwrap();
        fold_phase(&t, &x, &f, 0, &kt, &kp, &mut s).unwrap();
        prop_assert_eq!(&w.count, &s.count);
        prop_assert_eq!(&w.sum_x, &s.sum_x);
        prop_assert_eq!(&w.sum_f, &s.sum_f);
        prop_assert_eq!(&w.sum_phase, &s.sum_phase);
        prop_assert_eq!(&w.sum_phase2, &s.sum_phase2);
        prop_assert_eq!(&w.sum_xx, &s.sum_xx);
        prop_assert_eq!(&w.sum_t, &s.sum_t);
        prop_assert_eq!(&w.first, &s.first);
        let sp = fold_spread(&s).unwrap();
        // running moments against a two-pass spread: a small spread is the square root of
        // a cancelling variance (seen 1.6e-9 of the largest in 1000 cases)
        prop_assert!(close(&w.x_std, &sp.x_std, 1e-8), "{:?} {:?}", w.x_std, sp.x_std);
        prop_assert!(close(&w.f_std, &sp.f_std, 1e-8));
        prop_assert_eq!(&w.amplitude, &sp.amplitude);
        prop_assert_eq!(&w.force_range, &sp.force_range);
        // numpy: first = r_[first, end]; where(first < 0, end, first); minimum.accumulate
        // from the end (end: the first sample at or after the last knot)
        let end = t.iter().position(|&v| v >= kt[kt.len() - 1]).unwrap_or(t.len());
        let mut b: Vec<usize> = s
            .first
            .iter()
            .map(|&v| if v < 0 { end } else { v as usize })
            .chain(std::iter::once(end))
            .collect();
        for i in (0..b.len() - 1).rev() {
            b[i] = b[i].min(b[i + 1]);
        }
        prop_assert_eq!(&w.bounds, &b);
        prop_assert!(close(&w.energy, &loop_areas(&x, &f, &b).unwrap(), 1e-12));
        let (sf, sx) = loop_area_sensitivity(&x, &f, &b).unwrap();
        prop_assert!(close(&w.sens_f, &sf, 1e-12));
        prop_assert!(close(&w.sens_x, &sx, 1e-12));
        prop_assert_eq!(&w.mean_f, &period_means(&t, &f, &edges).unwrap());
        prop_assert_eq!(&w.mean_x, &period_means(&t, &x, &edges).unwrap());
    }
}

/// Equal, NaN where NaN.
fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(u, v)| u == v || (u.is_nan() && v.is_nan()))
}

/// The phases fold_phase gives (numpy.interp's arithmetic), None where they decrease
/// (rounding at a knot: fold_window holds the phase there, fold_phase does not).
fn monotone_phases(t: &[f64], kt: &[f64], kp: &[f64]) -> Option<()> {
    let mut last = f64::NEG_INFINITY;
    for &ti in t {
        if !(ti >= kt[0] && ti < kt[kt.len() - 1]) {
            continue;
        }
        let j = kt.partition_point(|&k| k <= ti) - 1;
        let slope = (kp[j + 1] - kp[j]) / (kt[j + 1] - kt[j]);
        let ph = if ti == kt[j] {
            kp[j]
        } else {
            slope * (ti - kt[j]) + kp[j]
        };
        if ph < last {
            return None;
        }
        last = ph;
    }
    Some(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Irregular sampling and knots: flat knot segments (a phase that stands still),
    /// steep ones (bins and cycles without samples), knots between samples and on them,
    /// one or two bins, samples before the first knot and after the last: the per-bin
    /// sums, first samples, bounds and ranges are fold_phase's bit for bit, the spread,
    /// areas and sensitivities the separate kernels' to rounding.
    #[test]
    fn irregular_knots_fold_as_fold_phase(
        seed in 0u64..1_000_000, n_bins in 1usize..12, n_cyc in 1usize..6,
        n in 20usize..400, n_knots in 2usize..30,
    ) {
        let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(7);
        let mut u = move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut t = Vec::with_capacity(n);
        let mut v = 0.0;
        for _ in 0..n {
            v += 0.05 + u();
            t.push(v);
        }
        let x: Vec<f64> = t.iter().map(|&ti| (0.7 * ti).sin() + 0.1 * u()).collect();
        let f: Vec<f64> = t.iter().map(|&ti| (0.7 * ti + 0.5).cos() + 0.1 * u() - 3.0).collect();
        // knots: some on samples, some between, from before the first sample to after
        // the last
        let span = t[n - 1] - t[0];
        let mut kt: Vec<f64> = (0..n_knots)
            .map(|_| {
                if u() < 0.3 {
                    t[(u() * n as f64) as usize % n]
                } else {
                    t[0] - 0.1 * span + 1.2 * span * u()
                }
            })
            .collect();
        kt.sort_by(f64::total_cmp);
        kt.dedup();
        prop_assume!(kt.len() >= 2);
        let mut kp: Vec<f64> = (0..kt.len())
            .map(|_| if u() < 0.2 { 0.0 } else { u() * n_cyc as f64 })
            .collect();
        kp.sort_by(f64::total_cmp);
        if u() < 0.3 {
            kp[0] = 0.0;
        }
        if u() < 0.3 {
            let last = kp.len() - 1;
            kp[last] = n_cyc as f64;
        }
        prop_assume!(monotone_phases(&t, &kt, &kp).is_some());
        let edges: Vec<f64> = kt.iter().step_by(2).copied().collect();
        let w = fold_window(&t, &x, &f, &kt, &kp, n_bins, n_cyc, &edges).unwrap();
        let mut sm = FoldSums::new(n_bins, n_cyc).unwrap();
        fold_phase(&t, &x, &f, 0, &kt, &kp, &mut sm).unwrap();
        prop_assert_eq!(&w.count, &sm.count);
        prop_assert_eq!(&w.sum_x, &sm.sum_x);
        prop_assert_eq!(&w.sum_f, &sm.sum_f);
        prop_assert_eq!(&w.sum_phase, &sm.sum_phase);
        prop_assert_eq!(&w.sum_phase2, &sm.sum_phase2);
        prop_assert_eq!(&w.sum_xx, &sm.sum_xx);
        prop_assert_eq!(&w.sum_t, &sm.sum_t);
        prop_assert_eq!(&w.first, &sm.first);
        let sp = fold_spread(&sm).unwrap();
        prop_assert!(close(&w.x_std, &sp.x_std, 1e-8), "{:?} {:?}", w.x_std, sp.x_std);
        prop_assert!(close(&w.f_std, &sp.f_std, 1e-8));
        prop_assert!(same(&w.amplitude, &sp.amplitude), "{:?} {:?}", w.amplitude, sp.amplitude);
        prop_assert!(same(&w.force_range, &sp.force_range));
        let end = t.iter().position(|&v| v >= kt[kt.len() - 1]).unwrap_or(t.len());
        let mut b: Vec<usize> = sm
            .first
            .iter()
            .map(|&v| if v < 0 { end } else { v as usize })
            .chain(std::iter::once(end))
            .collect();
        for i in (0..b.len() - 1).rev() {
            b[i] = b[i].min(b[i + 1]);
        }
        prop_assert_eq!(&w.bounds, &b);
        // the areas of the cycles' own samples: the last cycle's run to the last sample
        // folded (a cycle past n_cycles folds none)
        let areas = loop_areas(&x, &f, &b).unwrap();
        let (sf, sx) = loop_area_sensitivity(&x, &f, &b).unwrap();
        prop_assert!(close(&w.energy, &areas, 1e-12), "{:?} {:?}", w.energy, areas);
        prop_assert!(close(&w.sens_f, &sf, 1e-12));
        prop_assert!(close(&w.sens_x, &sx, 1e-12));
        prop_assert_eq!(&w.mean_f, &period_means(&t, &f, &edges).unwrap());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// The period means carried over each cycle as it completes (window/period.rs) equal
    /// `period_means` bit for bit whatever the edges: before the samples, on sample times,
    /// repeated, inside cycles, past the end.
    #[test]
    fn period_means_carried_by_cycle_equal_one_pass(
        seed in 0u64..1000, n_cyc in 1usize..6, start in 0usize..300,
        picks in prop::collection::vec((0usize..4100, 0usize..4), 0..24),
    ) {
        let (t, x, f) = signal(4000, seed, 1.0);
        let period = 2.0 * std::f64::consts::PI / 6.0;
        let (kt, kp) = knots(&t[start..], period, n_cyc);
        let mut edges: Vec<f64> = picks
            .iter()
            .map(|&(i, how)| match how {
                0 => t[i.min(t.len() - 1)],                           // on a sample
                1 => t[i.min(t.len() - 1)] + 0.37e-3,                 // between samples
                2 => t[0] - 1.0 + i as f64 * 1e-4,                    // before the samples
                _ => kt[i % kt.len()],                                // on a knot
            })
            .collect();
        edges.sort_by(f64::total_cmp);
        let w = fold_window(&t, &x, &f, &kt, &kp, 8, n_cyc, &edges).unwrap();
        // bit for bit (a repeated edge gives NaN, 0/0, in both)
        let bits = |v: &[f64]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
        prop_assert_eq!(bits(&w.mean_f), bits(&period_means(&t, &f, &edges).unwrap()));
        prop_assert_eq!(bits(&w.mean_x), bits(&period_means(&t, &x, &edges).unwrap()));
    }
}

#[test]
fn short_cycles_and_edges_outside_the_samples() {
    // 6 samples, two cycles of 1 and 3 samples: NaN area below 3 samples
    let t = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
    let x = [0.0, 1.0, 0.0, -1.0, 0.0, 1.0];
    let f = [0.5, 1.0, 0.0, -1.0, -0.5, 1.0];
    let kt = [0.5, 1.5, 4.5];
    let kp = [0.0, 1.0, 2.0];
    let edges = [-1.0, 0.5, 9.0];
    let w = fold_window(&t, &x, &f, &kt, &kp, 2, 2, &edges).unwrap();
    assert_eq!(w.bounds, vec![1, 2, 5]);
    assert!(w.energy[0].is_nan());
    let a = loop_areas(&x, &f, &[2, 5]).unwrap()[0];
    assert!((w.energy[1] - a).abs() < 1e-15);
    assert_eq!(w.mean_f, period_means(&t, &f, &edges).unwrap());
}

#[test]
fn bad_input_is_an_error() {
    let (t, x, f) = signal(2000, 1, 1.0);
    let (kt, kp) = knots(&t, 1.0, 1);
    let e = [kt[0], kt[2]];
    assert!(fold_window(&t, &x, &f, &kt, &kp, 8, 1, &e).is_ok());
    assert!(fold_window(&t, &x[1..], &f, &kt, &kp, 8, 1, &e).is_err());
    assert!(fold_window(&t, &x, &f, &kt, &kp, 0, 1, &e).is_err());
    assert!(fold_window(&t, &x, &f, &kt[..1], &kp[..1], 8, 1, &e).is_err());
    assert!(fold_window(&t, &x, &f, &kt, &kp, 8, 0, &e).is_err());
    let mut tb = t.clone();
    tb[5] = tb[4];
    assert!(fold_window(&tb, &x, &f, &kt, &kp, 8, 1, &e).is_err());
    let mut xb = x.clone();
    xb[7] = f64::NAN;
    assert!(fold_window(&t, &xb, &f, &kt, &kp, 8, 1, &e).is_err());
    assert!(fold_window(&t, &x, &f, &kt, &kp, 8, 1, &[e[1], e[0]]).is_err());
    // areas beyond the double range: an error, not inf
    let big: Vec<f64> = x.iter().map(|v| v * 1e300).collect();
    let bigf: Vec<f64> = f.iter().map(|v| v * 1e300).collect();
    assert!(matches!(
        fold_window(&t, &big, &bigf, &kt, &kp, 8, 1, &e),
        Err(CoreError::OutOfRange { .. })
    ));
}

/// The order statistics ranks of `tail_percentiles` for `n` samples (0.5 and 99.5 %).
fn tail_ranks(n: usize) -> Vec<usize> {
    let (a, b) = ((n - 1) / 200, (n - 1) * 199 / 200);
    vec![a, a + 1, b, b + 1]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// The fused pass equals the passes it stands for: `detrend_pair_into`'s samples bit for
    /// bit, `order_stats` of the detrended x exactly (long windows: from the tails; short
    /// ones: the whole sample), the fold's check numbers exactly, so that a fold of the scan
    /// is bit for bit the fold that checks its samples itself.
    #[test]
    fn the_scanned_pass_equals_the_separate_passes(
        seed in 0u64..1000, n in prop::sample::select(vec![40usize, 5000, 40_000, 70_001]),
        s_f in -1e3f64..1e3, s_x in -1e-3f64..1e-3, n_cyc in 1usize..4,
        scale in prop::sample::select(vec![1.0, 1e-6, 1e150]),
    ) {
        let (t, x, f) = signal(n, seed, scale);
        let tm = t[n / 2];
        let (mut ef, mut ex) = (vec![0.0; n], vec![0.0; n]);
        detrend_pair_into(&t, tm, (&f, s_f), (&x, s_x), (&mut ef, &mut ex)).unwrap();
        let ranks = tail_ranks(n);
        let (mut of, mut ox) = (vec![0.0; n], vec![0.0; n]);
        let scan = detrend_pair_scan_into(&t, tm, (&f, s_f), (&x, s_x), (&mut of, &mut ox), &ranks)
            .unwrap();
        prop_assert!(of.iter().zip(&ef).all(|(a, b)| a.to_bits() == b.to_bits()));
        prop_assert!(ox.iter().zip(&ex).all(|(a, b)| a.to_bits() == b.to_bits()));
        prop_assert_eq!(&scan.order_stats, &crate::select::order_stats(&ex, &ranks).unwrap());
        prop_assert!(scan.clean);
        let [sx, sf, fm] = check_samples(&t, &ex, &ef, &[]).unwrap();
        prop_assert_eq!(
            [scan.max_abs_x, scan.max_abs_f, scan.force_centre].map(f64::to_bits),
            [sx, sf, fm].map(f64::to_bits)
        );
        let period = 2.0 * std::f64::consts::PI / 6.0;
        if n >= 5000 {
            let (kt, kp) = knots(&t, period, n_cyc);
            let edges: Vec<f64> = kt.iter().step_by(2).copied().collect();
            let a = fold_window(&t, &ox, &of, &kt, &kp, 16, n_cyc, &edges).unwrap();
            let b = fold_window_scanned(&t, &ox, &of, (&kt, &kp), (16, n_cyc), &edges, &scan)
                .unwrap();
            // bit for bit (NaN == NaN by bits)
            prop_assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }
}

#[test]
fn the_scan_finds_what_the_fold_check_refuses() {
    let (t, x, f) = signal(3000, 7, 1.0);
    let tm = t[0];
    let run = |t: &[f64], x: &[f64], f: &[f64]| {
        let n = t.len();
        let (mut of, mut ox) = (vec![0.0; n], vec![0.0; n]);
        detrend_pair_scan_into(t, tm, (f, 0.5), (x, 1e-3), (&mut of, &mut ox), &[]).unwrap()
    };
    assert!(run(&t, &x, &f).clean);
    assert!(run(&t, &x, &f).order_stats.is_empty());
    for (k, bad) in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY]
        .into_iter()
        .enumerate()
    {
        let mut xb = x.clone();
        xb[1234 + k] = bad;
        assert!(!run(&t, &xb, &f).clean);
        let mut fb = f.clone();
        fb[2999] = bad;
        assert!(!run(&t, &x, &fb).clean);
        let mut tb = t.clone();
        tb[0] = bad;
        assert!(!run(&tb, &x, &f).clean);
    }
    // t not strictly increasing: a repeat, a step back, at a block's edge
    for i in [1, 2048, 2999] {
        let mut tb = t.clone();
        tb[i] = tb[i - 1];
        assert!(!run(&tb, &x, &f).clean);
        tb[i] = tb[i - 1] - 1e-3;
        assert!(!run(&tb, &x, &f).clean);
    }
    assert!(!run(&t[..1], &x[..1], &f[..1]).clean);
    // a scan that is not clean, or of other samples, is no stand-in for the fold's check
    let mut xb = x.clone();
    xb[5] = f64::NAN;
    let bad = run(&t, &xb, &f);
    let (kt, kp) = knots(&t, 1.0, 1);
    assert!(fold_window_scanned(&t, &x, &f, (&kt, &kp), (8, 1), &[], &bad).is_err());
    let other = run(&t[..2000], &x[..2000], &f[..2000]);
    assert!(fold_window_scanned(&t, &x, &f, (&kt, &kp), (8, 1), &[], &other).is_err());
    let ok = run(&t, &x, &f);
    assert!(fold_window_scanned(&t, &x, &f, (&kt, &kp), (8, 1), &[], &ok).is_ok());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// A fold without period edges (what `track`'s windows ask for: they keep no period
    /// means) gives every other number of the fold with edges bit for bit, and no means;
    /// the edges' means do not depend on where the integrals stop after the last edge.
    #[test]
    fn a_fold_without_edges_is_the_fold_less_its_period_means(
        seed in 0u64..1000, n_bins in 4usize..40, n_cyc in 1usize..5, start in 0usize..300,
    ) {
        let (t, x, f) = signal(4000, seed, 1.0);
        let period = 2.0 * std::f64::consts::PI / 6.0;
        let (kt, kp) = knots(&t[start..], period, n_cyc);
        let edges: Vec<f64> = kt.iter().step_by(2).copied().collect();
        let with = fold_window(&t, &x, &f, &kt, &kp, n_bins, n_cyc, &edges).unwrap();
        let without = fold_window(&t, &x, &f, &kt, &kp, n_bins, n_cyc, &[]).unwrap();
        prop_assert!(without.mean_f.is_empty() && without.mean_x.is_empty());
        prop_assert_eq!(with.mean_f.len(), n_cyc);
        let bits = |v: &[f64]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
        for (a, b) in [
            (&with.count, &without.count),
            (&with.sum_x, &without.sum_x),
            (&with.sum_f, &without.sum_f),
            (&with.sum_phase, &without.sum_phase),
            (&with.sum_phase2, &without.sum_phase2),
            (&with.sum_xx, &without.sum_xx),
            (&with.sum_t, &without.sum_t),
            (&with.x_std, &without.x_std),
            (&with.f_std, &without.f_std),
            (&with.energy, &without.energy),
            (&with.sens_f, &without.sens_f),
            (&with.sens_x, &without.sens_x),
            (&with.amplitude, &without.amplitude),
            (&with.force_range, &without.force_range),
        ] {
            prop_assert_eq!(bits(a), bits(b));
        }
        prop_assert_eq!(&with.first, &without.first);
        prop_assert_eq!(&with.bounds, &without.bounds);
        // the period means with edges are those of the separate kernel, bit for bit
        let pf = period_means(&t, &f, &edges).unwrap();
        let px = period_means(&t, &x, &edges).unwrap();
        prop_assert_eq!(bits(&with.mean_f), bits(&pf));
        prop_assert_eq!(bits(&with.mean_x), bits(&px));
    }
}

/// Every number of two folds equal bit for bit (NaN's bits too).
fn bits_equal(a: &WindowFold, b: &WindowFold) -> Result<(), String> {
    let pairs: [(&str, &[f64], &[f64]); 16] = [
        ("count", &a.count, &b.count),
        ("sum_x", &a.sum_x, &b.sum_x),
        ("sum_f", &a.sum_f, &b.sum_f),
        ("sum_phase", &a.sum_phase, &b.sum_phase),
        ("sum_phase2", &a.sum_phase2, &b.sum_phase2),
        ("sum_xx", &a.sum_xx, &b.sum_xx),
        ("sum_t", &a.sum_t, &b.sum_t),
        ("x_std", &a.x_std, &b.x_std),
        ("f_std", &a.f_std, &b.f_std),
        ("energy", &a.energy, &b.energy),
        ("sens_f", &a.sens_f, &b.sens_f),
        ("sens_x", &a.sens_x, &b.sens_x),
        ("amplitude", &a.amplitude, &b.amplitude),
        ("force_range", &a.force_range, &b.force_range),
        ("mean_f", &a.mean_f, &b.mean_f),
        ("mean_x", &a.mean_x, &b.mean_x),
    ];
    for (name, u, v) in pairs {
        let same = u.len() == v.len() && u.iter().zip(v).all(|(p, q)| p.to_bits() == q.to_bits());
        if !same {
            return Err(format!("{name}: {u:?} != {v:?}"));
        }
    }
    if a.first != b.first || a.bounds != b.bounds {
        return Err(format!(
            "first/bounds {:?} {:?} != {:?} {:?}",
            a.first, a.bounds, b.first, b.bounds
        ));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// The fold's pass compiled for each SIMD level this CPU has gives the generic build's
    /// numbers bit for bit: irregular sampling and knots (phases held at a knot, empty
    /// bins), cycles of a few to a thousand samples (the loop areas' blocks of terms and
    /// their remainders), with and without period edges.
    #[test]
    fn every_simd_level_folds_as_the_generic_build(
        seed in 0u64..1_000_000, n_bins in 1usize..40, n_cyc in 1usize..8,
        n in 3usize..4000, n_knots in 2usize..30, with_edges in any::<bool>(),
    ) {
        let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(11);
        let mut u = move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut t = Vec::with_capacity(n);
        let mut v = 0.0;
        for _ in 0..n {
            v += 0.05 + u();
            t.push(v);
        }
        let x: Vec<f64> = t.iter().map(|&ti| (0.01 * ti).sin() + 0.1 * u()).collect();
        let f: Vec<f64> = t.iter().map(|&ti| (0.01 * ti + 0.5).cos() + 0.1 * u()).collect();
        let span = t[n - 1] - t[0];
        let mut kt: Vec<f64> = (0..n_knots)
            .map(|_| {
                if u() < 0.3 {
                    t[(u() * n as f64) as usize % n]
                } else {
                    t[0] - 0.1 * span + 1.2 * span * u()
                }
            })
            .collect();
        kt.sort_by(f64::total_cmp);
        kt.dedup();
        prop_assume!(kt.len() >= 2);
        let mut kp: Vec<f64> = (0..kt.len())
            .map(|_| if u() < 0.2 { 0.0 } else { u() * n_cyc as f64 })
            .collect();
        kp.sort_by(f64::total_cmp);
        kp[0] = if u() < 0.5 { 0.0 } else { kp[0] };
        let edges: Vec<f64> = if with_edges {
            kt.iter().step_by(2).copied().collect()
        } else {
            Vec::new()
        };
        let args = ((&t[..], &x[..], &f[..]), (&kt[..], &kp[..]), (n_bins, n_cyc));
        let want = fold_window_at(crate::simd::Level::Generic, args.0, args.1, args.2, &edges, None);
        for l in crate::simd::Level::ALL.into_iter().filter(|l| l.supported()) {
            let got = fold_window_at(l, args.0, args.1, args.2, &edges, None);
            match (&want, &got) {
                (Ok(a), Ok(b)) => {
                    let r = bits_equal(a, b);
                    prop_assert!(r.is_ok(), "level {}: {}", l.name(), r.unwrap_err());
                }
                (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
                _ => prop_assert!(false, "level {}: {:?} / {:?}", l.name(), got.is_ok(), want.is_ok()),
            }
        }
    }
}

/// [`cycle_area`] as it was before its terms were computed by blocks (one loop over four
/// shifted slices in lanes): the reference the blocked sums must equal bit for bit.
#[allow(clippy::arithmetic_side_effects)]
fn cycle_area_reference(
    x: &[f64],
    f: &[f64],
    ux: f64,
    uf: f64,
    fm: f64,
    scale: f64,
) -> (f64, f64, f64) {
    let m = x.len().min(f.len());
    if m < 3 {
        return (f64::NAN, 0.0, 0.0);
    }
    let (x, f) = (&x[..m], &f[..m]);
    // the shoelace terms 0.5·(F[i-1] + F[i])·(x[i] - x[i-1]) of the scaled samples, i >= 1
    let term = |xp: f64, xs: f64, fp: f64, fs: f64| {
        let (xp, xs, fp, fs) = (xp * ux, xs * ux, fp * uf - fm, fs * uf - fm);
        0.5 * (fp + fs) * (xs - xp)
    };
    let (mut s, mut c) = ([0.0_f64; LANES], [0.0_f64; LANES]);
    let (xa, xb, fa, fb) = (&x[..m - 1], &x[1..], &f[..m - 1], &f[1..]);
    let mut it = xa
        .chunks_exact(LANES)
        .zip(xb.chunks_exact(LANES))
        .zip(fa.chunks_exact(LANES))
        .zip(fb.chunks_exact(LANES));
    for (((xa, xb), fa), fb) in &mut it {
        for k in 0..LANES {
            let v = term(xa[k], xb[k], fa[k], fb[k]);
            // two-sum: t + e = s + v exactly
            let t = s[k] + v;
            let bb = t - s[k];
            c[k] += (s[k] - (t - bb)) + (v - bb);
            s[k] = t;
        }
    }
    let mut a = Neumaier::default();
    for &v in &s {
        a.add(v);
    }
    a.comp += c.iter().sum::<f64>();
    let done = (m - 1) / LANES * LANES;
    for i in done..m - 1 {
        a.add(term(xa[i], xb[i], fa[i], fb[i]));
    }
    // the closing term, last sample to first
    a.add(term(x[m - 1], x[0], f[m - 1], f[0]));
    // each sample's neighbours i - 1 and i + 1 as four slices of one length
    let (xa, xb, fa, fb) = (&x[..m - 2], &x[2..], &f[..m - 2], &f[2..]);
    let (mut sf, mut sx) = ([0.0_f64; LANES], [0.0_f64; LANES]);
    let mut it = xa
        .chunks_exact(LANES)
        .zip(xb.chunks_exact(LANES))
        .zip(fa.chunks_exact(LANES))
        .zip(fb.chunks_exact(LANES));
    for (((xa, xb), fa), fb) in &mut it {
        for k in 0..LANES {
            let cf = 0.5 * (xa[k] - xb[k]);
            let cx = 0.5 * (fb[k] - fa[k]);
            sf[k] += cf * cf;
            sx[k] += cx * cx;
        }
    }
    let (mut sf, mut sx) = (
        (sf[0] + sf[1]) + (sf[2] + sf[3]),
        (sx[0] + sx[1]) + (sx[2] + sx[3]),
    );
    for i in (m - 2) / LANES * LANES..m - 2 {
        let cf = 0.5 * (xa[i] - xb[i]);
        let cx = 0.5 * (fb[i] - fa[i]);
        sf += cf * cf;
        sx += cx * cx;
    }
    // the first sample (neighbours: the last and the second), then the last (the one before
    // it and the first)
    let (c0f, c0x) = (0.5 * (x[m - 1] - x[1]), 0.5 * (f[1] - f[m - 1]));
    let (c1f, c1x) = (0.5 * (x[m - 2] - x[0]), 0.5 * (f[0] - f[m - 2]));
    (
        (a.sum + a.comp) * scale,
        sf + c0f * c0f + c1f * c1f,
        sx + c0x * c0x + c1x * c1x,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// The loop area and its sensitivities of one cycle by blocks of terms are the
    /// sample-by-lane sums' bit for bit (lengths around the block and lane bounds).
    #[test]
    fn cycle_area_by_blocks_is_the_lane_sum(
        seed in 0u64..1_000_000, m in 0usize..300, fm in -2.0f64..2.0,
    ) {
        let (_, x, f) = signal(m.max(1), seed, 1e-3);
        let (x, f) = (&x[..m], &f[..m]);
        let (ux, uf) = (1.0 / 1e-3, 1.0 / 1.5);
        let a = cycle_area(x, f, ux, uf, fm, 1.5e-3);
        let b = cycle_area_reference(x, f, ux, uf, fm, 1.5e-3);
        prop_assert_eq!(a.0.to_bits(), b.0.to_bits());
        prop_assert_eq!(a.1.to_bits(), b.1.to_bits());
        prop_assert_eq!(a.2.to_bits(), b.2.to_bits());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// The detrending scan compiled for each SIMD level this CPU has gives the generic
    /// build's samples, order statistics and scan numbers bit for bit, a non-finite or
    /// non-increasing sample included (then `clean` is false at every level).
    #[test]
    fn every_simd_level_scans_as_the_generic_build(
        seed in 0u64..1000, n in prop::sample::select(vec![2usize, 7, 40, 5000, 70_001]),
        s_f in -1e3f64..1e3, s_x in -1e-3f64..1e-3, bad in 0u8..4,
    ) {
        let (mut t, mut x, f) = signal(n, seed, 1e-3);
        let k = (seed as usize) % n;
        match bad {
            1 => x[k] = f64::NAN,
            2 => t[k] = f64::INFINITY,
            3 if k > 0 => t[k] = t[k - 1],
            _ => {}
        }
        let tm = t[n / 2];
        let ranks = if n > 1000 { tail_ranks(n) } else { Vec::new() };
        let (mut gf, mut gx) = (vec![0.0; n], vec![0.0; n]);
        let g = detrend_pair_scan_at(
            crate::simd::Level::Generic, &t, tm, (&f, s_f), (&x, s_x), (&mut gf, &mut gx), &ranks,
        );
        for l in crate::simd::Level::ALL.into_iter().filter(|l| l.supported()) {
            let (mut of, mut ox) = (vec![0.0; n], vec![0.0; n]);
            let s = detrend_pair_scan_at(l, &t, tm, (&f, s_f), (&x, s_x), (&mut of, &mut ox), &ranks);
            prop_assert_eq!(format!("{s:?}"), format!("{g:?}"), "level {}", l.name());
            prop_assert!(of.iter().zip(&gf).all(|(a, b)| a.to_bits() == b.to_bits()));
            prop_assert!(ox.iter().zip(&gx).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// The scan of a sampled axis made as the pass goes equals, at every SIMD level, the scan
    /// of `fill_time`'s axis read from memory: the detrended samples bit for bit, the order
    /// statistics and scan numbers; an axis that stops increasing (a step lost against the
    /// start time) or overflows is not clean in either.
    #[test]
    fn a_sampled_axis_scans_as_its_filled_axis(
        seed in 0u64..1000, n in prop::sample::select(vec![2usize, 7, 40, 5000, 70_001]),
        offset in prop::sample::select(vec![0u64, 1, 32_767, 2_000_003, 1 << 40]),
        axis in 0u8..4, s_f in -1e3f64..1e3, s_x in -1e-3f64..1e-3,
    ) {
        let (_t, x, f) = signal(n, seed, 1e-3);
        let (t0, dt) = match axis {
            0 => (0.0, 1e-4),
            1 => (-3.25, 1.0 / 3.0),
            2 => (1e9, 1e-9), // stops increasing
            _ => (1.0, 1e300), // overflows
        };
        let mut t = vec![0.0; n];
        crate::stream::fill_time(&mut t, t0, dt, offset).unwrap();
        let tm = t[n / 2];
        let ranks = if n > 1000 { tail_ranks(n) } else { Vec::new() };
        for l in crate::simd::Level::ALL.into_iter().filter(|l| l.supported()) {
            let (mut gf, mut gx) = (vec![0.0; n], vec![0.0; n]);
            let g = detrend_pair_scan_at(l, &t, tm, (&f, s_f), (&x, s_x), (&mut gf, &mut gx), &ranks);
            let (mut of, mut ox) = (vec![0.0; n], vec![0.0; n]);
            let s = detrend_pair_scan_uniform_at(
                l, (t0, dt, offset), tm, (&f, s_f), (&x, s_x), (&mut of, &mut ox), &ranks,
            );
            prop_assert_eq!(format!("{s:?}"), format!("{g:?}"), "level {}", l.name());
            prop_assert!(of.iter().zip(&gf).all(|(a, b)| a.to_bits() == b.to_bits()));
            prop_assert!(ox.iter().zip(&gx).all(|(a, b)| a.to_bits() == b.to_bits()));
            if axis == 2 {
                prop_assert!(!s.as_ref().is_ok_and(|s| s.clean));
            }
        }
    }
}

#[test]
fn a_sampled_axis_past_exact_indices_is_refused() {
    let (x, f) = (vec![1.0; 4], vec![2.0; 4]);
    let (mut of, mut ox) = (vec![0.0; 4], vec![0.0; 4]);
    let r = detrend_pair_scan_uniform_into(
        (0.0, 1.0, (1 << 53) - 2),
        0.0,
        (&f, 0.0),
        (&x, 0.0),
        (&mut of, &mut ox),
        &[],
    );
    assert!(matches!(r, Err(CoreError::TooLong { .. })));
}
