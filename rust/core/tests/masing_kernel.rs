//! The blocked, vectorisable force kernel against the plain reference loop of the benchmark
//! (independent code: index stack, libm exp), the anchored branch rule, and the branch memory.

use contactlab_core::curve::{one_minus_exp_neg, Backbone, Exponential};
use contactlab_core::masing::{
    branch_memory, masing_force, masing_force_rule, run, BranchRule, Closure, MasingState,
};
use proptest::prelude::*;

#[path = "../../../benches/masing_reference.rs"]
mod reference;

#[test]
fn one_minus_exp_neg_is_accurate_everywhere() {
    let mut worst = 0.0_f64;
    let mut z = 1e-300_f64;
    while z < 800.0 {
        let want = if z < 0.5 {
            -(-z).exp_m1()
        } else {
            1.0 - (-z).exp()
        };
        worst = worst.max((one_minus_exp_neg(z) / want - 1.0).abs());
        z *= 1.001_3;
    }
    // Densely where the power of two changes (|r| at its largest at (k + 1/2) ln2) and
    // over the k = 0 and k = -1 ranges.
    for i in 1..200_000 {
        let z = f64::from(i) * 1e-4;
        let want = if z < 0.5 {
            -(-z).exp_m1()
        } else {
            1.0 - (-z).exp()
        };
        worst = worst.max((one_minus_exp_neg(z) / want - 1.0).abs());
    }
    assert!(worst < 1e-15, "worst relative error {worst:e}"); // a few ulp
    eprintln!("one_minus_exp_neg: worst relative error against libm {worst:.2e}");
    assert_eq!(one_minus_exp_neg(0.0), 0.0);
    assert_eq!(one_minus_exp_neg(1e6), 1.0);
}

fn walk() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.0f64..1.0, 1..3000).prop_map(|steps| {
        let mut x = 0.0;
        steps
            .into_iter()
            .map(|s| {
                x += s * 1e-5;
                x
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn kernel_matches_the_reference_loop(x in walk(), lam in 1.5f64..2.5) {
        let (h0, ac) = (40.0, 4.0e4);
        let c = Exponential::new(h0, ac).unwrap();
        let mut out = vec![0.0; x.len()];
        masing_force(&c, lam, &x, &mut out, &mut MasingState::default()).unwrap();
        let mut want = vec![0.0; x.len()];
        reference::reference_force(h0, ac, lam, &x, &mut want, &mut Vec::new());
        for (a, b) in out.iter().zip(&want) {
            prop_assert!((a - b).abs() <= 1e-12 * h0, "{} vs {}", a, b);
        }
    }

    #[test]
    fn anchored_rule_is_masing_at_lambda_2_and_closes_loops(x in walk(), lam in 1.2f64..3.0) {
        let c = Exponential::new(40.0, 4.0e4).unwrap();
        let mut a = vec![0.0; x.len()];
        let mut b = vec![0.0; x.len()];
        masing_force(&c, 2.0, &x, &mut a, &mut MasingState::default()).unwrap();
        let rule = BranchRule::Anchored(2.0);
        masing_force_rule(&c, rule, &x, &mut b, &mut MasingState::default()).unwrap();
        for (p, q) in a.iter().zip(&b) {
            prop_assert!((p - q).abs() <= 1e-12 * 40.0);
        }
        // Any λ: chunked equals one pass, and coming back to the first reversal's mirror
        // point lands on the virgin curve (the anchored branch ends at its target).
        let rule = BranchRule::Anchored(lam);
        let cut = x.len() / 3;
        let mut whole = vec![0.0; x.len()];
        masing_force_rule(&c, rule, &x, &mut whole, &mut MasingState::default()).unwrap();
        let mut st = MasingState::default();
        let mut parts = vec![0.0; x.len()];
        masing_force_rule(&c, rule, &x[..cut], &mut parts[..cut], &mut st).unwrap();
        masing_force_rule(&c, rule, &x[cut..], &mut parts[cut..], &mut st).unwrap();
        prop_assert_eq!(&whole, &parts);
        let big = x.iter().fold(0.0f64, |m, v| m.max(v.abs())) * 1.5 + 1e-6;
        let mut o = [0.0; 2];
        masing_force_rule(&c, rule, &[big, -big], &mut o, &mut st).unwrap();
        prop_assert!((o[1] - c.eval(-big)).abs() <= 1e-12 * 40.0);
    }

    #[test]
    fn branch_memory_matches_the_force_kernels_stack(x in walk()) {
        let c = Exponential::new(40.0, 4.0e4).unwrap();
        let (mut anchor, mut target) = (vec![0; x.len()], vec![0; x.len()]);
        let mut st = MasingState::default();
        branch_memory(&x, &mut anchor, &mut target, &mut st).unwrap();
        // The anchor of the last sample is the force kernel's top reversal.
        let mut fs = MasingState::default();
        masing_force(&c, 2.0, &x, &mut vec![0.0; x.len()], &mut fs).unwrap();
        let last = x.len() - 1;
        match fs.stack.len() {
            0 => prop_assert_eq!((anchor[last], target[last]), (-1, -1)),
            1 => prop_assert_eq!((anchor[last], target[last]),
                                 (fs.stack[0].index as i64, -1 - fs.stack[0].index as i64)),
            n => prop_assert_eq!((anchor[last], target[last]),
                                 (fs.stack[n - 1].index as i64, fs.stack[n - 2].index as i64)),
        }
        prop_assert_eq!(st.stack.len(), fs.stack.len());
    }
}

/// Signals that mix what the kernel treats differently: stretches where the input reverses
/// every sample or two, smooth stretches, repeated values, large jumps that close several
/// loops or rejoin the virgin curve; long enough for several blocks of 512.
fn mixed() -> impl Strategy<Value = Vec<f64>> {
    let piece = prop_oneof![
        // random walk on a grid (exact repeats of earlier extremes)
        (prop::collection::vec(prop::bool::ANY, 1..700), 1u32..4).prop_map(|(b, k)| (
            0,
            b.iter()
                .map(|&u| if u { 1.0 } else { -1.0 } * f64::from(k))
                .collect::<Vec<_>>()
        )),
        // smooth: a sine stretch
        (50usize..900, 0.5f64..30.0)
            .prop_map(|(n, a)| (1, (0..n).map(|i| a * (i as f64 * 0.02).sin()).collect())),
        // held value
        (1usize..20).prop_map(|n| (2, vec![0.0; n])),
        // jump
        (-60.0f64..60.0).prop_map(|j| (3, vec![j])),
    ];
    prop::collection::vec(piece, 1..8).prop_map(|pieces| {
        let mut x = Vec::new();
        let mut level = 0.0_f64;
        for (kind, v) in pieces {
            for d in v {
                level = match kind {
                    0 => level + d,
                    1 => level + d * 0.05,
                    2 => level,
                    _ => d,
                };
                x.push(level * 1e-6);
            }
        }
        x
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The force kernel (deferred reversal forces, branch registers, run table) against the
    /// operator's stepping code, which evaluates every reversal force on the spot (taken when
    /// an observer watches closures): bit for bit, in one pass and chunked.
    #[test]
    fn kernel_equals_the_eager_stepper_bit_for_bit(x in mixed(), cut in 0usize..2000) {
        let c = Exponential::new(40.0, 4.0e4).unwrap();
        let mut fast = vec![0.0; x.len()];
        let mut sf = MasingState::default();
        masing_force(&c, 2.0, &x, &mut fast, &mut sf).unwrap();
        let mut slow = vec![0.0; x.len()];
        let mut ss = MasingState::default();
        let mut closures = 0_usize;
        let mut count = |_: Closure| closures += 1;
        run(&c, 2.0, &x, Some(&mut slow), &mut ss, &mut count).unwrap();
        prop_assert_eq!(&fast, &slow);
        prop_assert_eq!(&sf, &ss);
        let cut = cut.min(x.len());
        let mut parts = vec![0.0; x.len()];
        let mut st = MasingState::default();
        masing_force(&c, 2.0, &x[..cut], &mut parts[..cut], &mut st).unwrap();
        masing_force(&c, 2.0, &x[cut..], &mut parts[cut..], &mut st).unwrap();
        prop_assert_eq!(&fast, &parts);
        prop_assert_eq!(&sf, &st);
        let mut want = vec![0.0; x.len()];
        reference::reference_force(40.0, 4.0e4, 2.0, &x, &mut want, &mut Vec::new());
        for (a, b) in fast.iter().zip(&want) {
            prop_assert!((a - b).abs() <= 1e-12 * 40.0, "{} vs {}", a, b);
        }
    }
}

#[test]
fn states_the_kernel_cannot_continue_take_the_stepping_code() {
    // A hand-made state that has moved but counts no samples (its first reversal would be
    // sample -1), and one whose reversal index lies beyond its count.
    let c = Exponential::new(40.0, 4.0e4).unwrap();
    let x = [1e-5, 0.5e-5, 2e-5, -1e-5];
    for v in [
        vec![2e-5, 10.0, 1.0, 0.0],
        vec![1e-5, 5.0, -1.0, 3.0, 3e-5, 20.0, 9.0],
    ] {
        let st0 = MasingState::from_slice(&v).unwrap();
        let mut a = [0.0; 4];
        let mut sa = st0.clone();
        masing_force(&c, 2.0, &x, &mut a, &mut sa).unwrap();
        let mut b = [0.0; 4];
        let mut sb = st0.clone();
        run(&c, 2.0, &x, Some(&mut b), &mut sb, &mut |_: Closure| {}).unwrap();
        assert_eq!(a, b);
        assert_eq!(sa, sb);
        assert!(a.iter().all(|h| h.is_finite()));
    }
}

/// Long stretches that reverse every sample or two (the kernel's dense path takes the block
/// after one with many branch changes), with what that path leaves to its rare branches mixed
/// in: repeated values, walks back onto the virgin curve and down to the first reversal's
/// branch, and jumps that close several loops at once.
fn dense() -> impl Strategy<Value = Vec<f64>> {
    let step = prop_oneof![
        8 => prop::bool::ANY.prop_map(|b| if b { 1.0 } else { -1.0 }),
        1 => Just(0.0),
        1 => (-40.0f64..40.0).prop_map(|j| j * 1.5),
    ];
    (prop::collection::vec(step, 600..4000), 0.5f64..3.0).prop_map(|(steps, k)| {
        let mut x = 0.0_f64;
        steps
            .into_iter()
            .map(|d| {
                // |d| > 1: a jump to a level (which may close many loops), else a step
                x = if d.abs() > 1.0 { d } else { x + d * k };
                x * 1e-6
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The dense path (branch-free first pass) against the eager stepper: bit for bit, in one
    /// pass and in two chunks (a cut moves the blocks, and so which path takes which samples).
    #[test]
    fn dense_blocks_equal_the_eager_stepper_bit_for_bit(x in dense(), cut in 0usize..4000) {
        let c = Exponential::new(40.0, 4.0e4).unwrap();
        let mut fast = vec![0.0; x.len()];
        let mut sf = MasingState::default();
        masing_force(&c, 2.0, &x, &mut fast, &mut sf).unwrap();
        let mut slow = vec![0.0; x.len()];
        let mut ss = MasingState::default();
        run(&c, 2.0, &x, Some(&mut slow), &mut ss, &mut |_: Closure| {}).unwrap();
        prop_assert_eq!(&fast, &slow);
        prop_assert_eq!(&sf, &ss);
        let cut = cut.min(x.len());
        let mut parts = vec![0.0; x.len()];
        let mut st = MasingState::default();
        masing_force(&c, 2.0, &x[..cut], &mut parts[..cut], &mut st).unwrap();
        masing_force(&c, 2.0, &x[cut..], &mut parts[cut..], &mut st).unwrap();
        prop_assert_eq!(&fast, &parts);
        prop_assert_eq!(&sf, &st);
        let mut want = vec![0.0; x.len()];
        reference::reference_force(40.0, 4.0e4, 2.0, &x, &mut want, &mut Vec::new());
        for (a, b) in fast.iter().zip(&want) {
            prop_assert!((a - b).abs() <= 1e-12 * 40.0, "{} vs {}", a, b);
        }
    }
}
