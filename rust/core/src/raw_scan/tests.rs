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
