use super::*;
use crate::select::order_stats;
use proptest::prelude::*;

/// `n` samples: t increasing with uneven steps, x a noisy sine, F another.
fn samples(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    let mut u = move || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut t = Vec::with_capacity(n);
    let mut v = 3.7;
    for _ in 0..n {
        t.push(v);
        v += 1e-4 * (0.5 + u());
    }
    let x: Vec<f64> = t.iter().map(|&v| (60.0 * v).sin() + 0.01 * u()).collect();
    let f: Vec<f64> = t
        .iter()
        .map(|&v| 40.0 * (60.0 * v + 0.3).sin() + u())
        .collect();
    (t, x, f)
}

/// Edges: some before the first sample, some on samples, some between, some past the last.
fn edges(t: &[f64], k: usize, seed: u64) -> Vec<f64> {
    let n = t.len();
    let mut e = vec![t[0] - 1.0, t[0]];
    for i in 0..k {
        let j = (seed as usize).wrapping_mul(7919).wrapping_add(i * 104_729) % n;
        e.push(t[j]);
        if j + 1 < n {
            e.push(0.5 * (t[j] + t[j + 1]));
        }
    }
    e.push(t[n - 1]);
    e.push(t[n - 1] + 1.0);
    e.sort_by(f64::total_cmp);
    e
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// The fused pass's order statistics are `order_stats`'s, and the period means resumed
    /// from its checkpoints are `period_means_pair`'s, bit for bit (short samples selected
    /// whole, long ones gathered from their tails; edges before, on, between and past the
    /// samples).
    #[test]
    fn the_fused_pass_equals_the_separate_kernels(
        seed in 0u64..1000,
        n in prop::sample::select(vec![2usize, 3, 64, 65, 1000, 40_000, 70_001]),
        k in 0usize..60,
    ) {
        let (t, x, f) = samples(n, seed);
        let ranks = [0, n / 200, n / 2, n - 1 - n / 200, n - 1];
        let scan = order_stats_trapezoids(&x, &t, &f, &ranks).unwrap();
        prop_assert!(scan.t_ok);
        prop_assert_eq!(bits(&scan.order_stats), bits(&order_stats(&x, &ranks).unwrap()));
        let e = edges(&t, k, seed);
        let (gf, gx) = period_means_pair_resumed(&t, &f, &x, &e, &scan).unwrap();
        let (wf, wx) = period_means_pair(&t, &f, &x, &e).unwrap();
        prop_assert_eq!(bits(&gf), bits(&wf));
        prop_assert_eq!(bits(&gx), bits(&wx));
    }
}

/// A time axis that is not increasing, or edges that go back, or a scan of other samples:
/// the resumed means are `period_means_pair`'s own (its errors name the fault).
#[test]
fn faults_are_named_as_period_means_pair_names_them() {
    let (mut t, x, f) = samples(5000, 3);
    let e = edges(&t, 20, 3);
    let scan = order_stats_trapezoids(&x, &t, &f, &[1, 4000]).unwrap();
    // another axis of the same length: the walk is not resumed
    let t2: Vec<f64> = t.iter().map(|v| v + 1.0).collect();
    let got = period_means_pair_resumed(&t2, &f, &x, &e, &scan).unwrap();
    assert_eq!(got, period_means_pair(&t2, &f, &x, &e).unwrap());
    // edges going back
    let mut back = e.clone();
    back.swap(3, 4);
    let got = period_means_pair_resumed(&t, &f, &x, &back, &scan);
    let want = period_means_pair(&t, &f, &x, &back);
    assert_eq!(format!("{got:?}"), format!("{want:?}"));
    assert!(got.is_err());
    // t not increasing
    t[2500] = t[2499];
    let scan = order_stats_trapezoids(&x, &t, &f, &[1, 4000]).unwrap();
    assert!(!scan.t_ok);
    let got = period_means_pair_resumed(&t, &f, &x, &e, &scan);
    let want = period_means_pair(&t, &f, &x, &e);
    assert_eq!(format!("{got:?}"), format!("{want:?}"));
    assert!(got.is_err());
    // t not finite
    t[2500] = f64::NAN;
    let scan = order_stats_trapezoids(&x, &t, &f, &[1, 4000]).unwrap();
    assert!(!scan.t_ok);
    assert!(period_means_pair_resumed(&t, &f, &x, &e, &scan).is_err());
}

#[test]
fn bad_input_is_an_error() {
    assert!(order_stats_trapezoids(&[], &[], &[], &[0]).is_err());
    assert!(order_stats_trapezoids(&[1.0, 2.0], &[1.0], &[1.0, 2.0], &[0]).is_err());
    assert!(order_stats_trapezoids(&[1.0, 2.0], &[1.0, 2.0], &[1.0, 2.0], &[2]).is_err());
    let scan = order_stats_trapezoids(&[1.0], &[1.0], &[1.0], &[0]).unwrap();
    assert!(period_means_pair_resumed(&[1.0], &[1.0], &[1.0], &[1.0], &scan).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// The uniform axis made in the pass is `fill_time`'s, bit for bit, and the scan is
    /// `order_stats_trapezoids`' of that axis (the checkpoints, tails and flags), whatever
    /// the window's length against the axis blocks (one block, a block and a sample, many).
    #[test]
    fn the_uniform_pass_equals_fill_time_then_the_scan(
        seed in 0u64..1000,
        n in prop::sample::select(vec![2usize, 3, 64, 65, 4095, 4096, 4097, 8193, 40_000, 70_001]),
        offset in prop::sample::select(vec![0u64, 1, 977, 123_456_789]),
    ) {
        let (_t, x, f) = samples(n, seed);
        let (t0, dt) = (0.125 + seed as f64 * 1e-3, 1e-4);
        let mut t_ref = vec![0.0; n];
        crate::stream::fill_time(&mut t_ref, t0, dt, offset).unwrap();
        let ranks = if n > 8 { vec![1, 2, n - 3, n - 2] } else { vec![0, n - 1] };
        let want = order_stats_trapezoids(&x, &t_ref, &f, &ranks).unwrap();
        let mut t_out = vec![f64::NAN; n];
        let got = order_stats_trapezoids_uniform(&x, &f, (t0, dt, offset), &mut t_out, &ranks)
            .unwrap();
        prop_assert_eq!(bits(&t_out), bits(&t_ref));
        prop_assert_eq!(bits(&got.order_stats), bits(&want.order_stats));
        prop_assert_eq!(bits(&got.cf), bits(&want.cf));
        prop_assert_eq!(bits(&got.cx), bits(&want.cx));
        prop_assert_eq!(bits(&got.ct), bits(&want.ct));
        prop_assert_eq!(got.t_ok, want.t_ok);
        prop_assert_eq!(got.n, want.n);
        prop_assert_eq!(got.t_ends.0.to_bits(), want.t_ends.0.to_bits());
        prop_assert_eq!(got.t_ends.1.to_bits(), want.t_ends.1.to_bits());
    }
}

/// An axis that stops increasing (a step below the precision of t0) is not `t_ok`, as the
/// scan of the filled axis says; an axis past 2^53 samples and a `t_out` of another length
/// are refused.
#[test]
fn the_uniform_pass_checks_its_axis() {
    let (_t, x, f) = samples(5000, 3);
    let n = x.len();
    let mut t_out = vec![0.0; n];
    // dt far below t0's spacing: consecutive samples get equal times
    let got = order_stats_trapezoids_uniform(&x, &f, (1e12, 1e-9, 0), &mut t_out, &[3]).unwrap();
    let want = order_stats_trapezoids(&x, &t_out, &f, &[3]).unwrap();
    assert!(!got.t_ok);
    assert_eq!(got.t_ok, want.t_ok);
    assert!(order_stats_trapezoids_uniform(&x, &f, (0.0, 1.0, 1 << 53), &mut t_out, &[3]).is_err());
    let mut short = vec![0.0; n - 1];
    assert!(order_stats_trapezoids_uniform(&x, &f, (0.0, 1.0, 0), &mut short, &[3]).is_err());
}
