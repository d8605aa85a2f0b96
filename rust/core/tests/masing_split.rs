//! A channel split into pieces ([`split`]) and run on several threads ([`force_channels`])
//! against the serial kernel: forces and final states bit for bit, over random signals
//! (reversals at piece edges included: pieces of 1 to 40 samples, and 300 to 2000 so that
//! the pre-pass takes its dense path on whole blocks), start states, piece
//! lengths and thread counts, for both curve kinds and both branch rules.

use contactlab_core::curve::{Exponential, Tabulated};
use contactlab_core::masing::channels::{force_channels, Channel, Model};
use contactlab_core::masing::split::{force_piece, split, split_each, Walked};
use contactlab_core::masing::{masing_force, masing_force_rule, BranchRule, MasingState};
use contactlab_core::CoreError;
use proptest::prelude::*;

/// Random walks on a grid (exact repeats of extremes, zero steps), smooth stretches and
/// jumps that close several loops or rejoin the virgin curve.
fn signal() -> impl Strategy<Value = Vec<f64>> {
    let step = prop_oneof![
        6 => prop::bool::ANY.prop_map(|b| if b { 1.0 } else { -1.0 }),
        1 => Just(0.0),
        1 => (-40.0f64..40.0).prop_map(|j| j * 1.5),
        2 => (0.0f64..1.0).prop_map(|p| 1e3 + p),
    ];
    (prop::collection::vec(step, 1..2500), 0.5f64..3.0).prop_map(|(steps, k)| {
        let (mut x, mut phase) = (0.0_f64, 0.0_f64);
        steps
            .into_iter()
            .map(|d| {
                if d >= 1e3 {
                    // a sine-like smooth stretch sample
                    phase += 0.05;
                    x += k * (phase.sin() + (d - 1e3) * 0.1);
                } else if d.abs() > 1.0 {
                    x = d;
                } else {
                    x += d * k;
                }
                x * 1e-6
            })
            .collect()
    })
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|a| a.to_bits()).collect()
}

fn state_bits(s: &MasingState) -> Vec<u64> {
    bits(&s.to_vec())
}

fn serial<C: contactlab_core::Backbone>(
    c: &C,
    rule: BranchRule,
    x: &[f64],
    st: &MasingState,
) -> (Vec<f64>, MasingState) {
    let mut out = vec![0.0; x.len()];
    let mut s = st.clone();
    masing_force_rule(c, rule, x, &mut out, &mut s).unwrap();
    (out, s)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Pieces run one after another from the split's states equal the serial kernel, and the
    /// split's end state is the serial one.
    #[test]
    fn pieces_equal_the_serial_kernel_bit_for_bit(
        x in signal(), prefix in 0usize..600, piece in prop_oneof![1usize..40, 300usize..2000],
        lam in 1.5f64..2.5,
    ) {
        let c = Exponential::new(40.0, 4.0e4).unwrap();
        // a start state from a prefix of the signal (the origin when empty)
        let cut = prefix.min(x.len());
        let (_, st0) = serial(&c, BranchRule::Scaled(lam), &x[..cut], &MasingState::default());
        let x = &x[cut..];
        let (want, want_end) = serial(&c, BranchRule::Scaled(lam), x, &st0);
        let sp = split(&c, lam, x, &st0, piece).unwrap().unwrap();
        prop_assert_eq!(sp.pieces[0].1.clone(), st0.clone());
        let mut got = vec![f64::NAN; x.len()];
        let offs: Vec<usize> = sp.pieces.iter().map(|p| p.0).chain([x.len()]).collect();
        for (k, (off, st)) in sp.pieces.iter().enumerate() {
            let mut st = st.clone();
            let end = offs[k + 1];
            prop_assert!(force_piece(&c, lam, &x[*off..end], &mut got[*off..end], &mut st).unwrap());
            // each piece ends in the next piece's start state
            if k + 1 < sp.pieces.len() {
                prop_assert_eq!(state_bits(&st), state_bits(&sp.pieces[k + 1].1));
            } else {
                prop_assert_eq!(state_bits(&st), state_bits(&want_end));
            }
        }
        prop_assert_eq!(bits(&got), bits(&want));
        prop_assert_eq!(state_bits(&sp.end), state_bits(&want_end));
    }

    /// A pre-pass stopped at any boundary: the pieces before it and the rest as one piece
    /// equal the serial kernel, and the rest ends in the serial end state.
    #[test]
    fn a_stopped_prepass_leaves_a_last_piece_to_the_end(
        x in signal(), piece in 1usize..60, stop_at in 0usize..40,
    ) {
        let c = Exponential::new(40.0, 4.0e4).unwrap();
        let st0 = MasingState::default();
        let (want, want_end) = serial(&c, BranchRule::Scaled(2.0), &x, &st0);
        let mut pieces = Vec::new();
        let walked = split_each(&c, 2.0, &x, &st0, piece, |off, st| {
            pieces.push((off, st));
            pieces.len() <= stop_at
        })
        .unwrap();
        let stopped = walked == Walked::Stopped;
        prop_assert!(stopped || matches!(walked, Walked::Ended(_)));
        let offs: Vec<usize> = pieces.iter().map(|p| p.0).chain([x.len()]).collect();
        let mut got = vec![f64::NAN; x.len()];
        let mut last = MasingState::default();
        for (k, (off, st)) in pieces.iter().enumerate() {
            let mut st = st.clone();
            let end = offs[k + 1];
            force_piece(&c, 2.0, &x[*off..end], &mut got[*off..end], &mut st).unwrap();
            last = st;
        }
        prop_assert_eq!(bits(&got), bits(&want));
        prop_assert_eq!(state_bits(&last), state_bits(&want_end));
    }

    /// Several channels (both curves, both rules, own start states) on 1 to 4 threads.
    #[test]
    fn many_channels_on_threads_equal_the_serial_kernel(
        xs in prop::collection::vec(signal(), 1..5), piece in 1usize..40, threads in 1usize..5,
        prefix in 0usize..300,
    ) {
        let e = Exponential::new(40.0, 4.0e4).unwrap();
        let t = Tabulated::new(&[0.0, 1e-5, 3e-5, 1e-4], &[0.0, 0.3, 0.5, 0.55]).unwrap();
        let me = Model { curve: &e, rule: BranchRule::Scaled(2.0) };
        let mt = Model { curve: &t, rule: BranchRule::Scaled(1.7) };
        let ma = Model { curve: &e, rule: BranchRule::Anchored(2.3) };
        let pick: [&dyn Channel; 3] = [&me, &mt, &ma];
        let rules = [BranchRule::Scaled(2.0), BranchRule::Scaled(1.7), BranchRule::Anchored(2.3)];
        let models: Vec<&dyn Channel> = (0..xs.len()).map(|i| pick[i % 3]).collect();
        let mut states = Vec::new();
        let mut sigs = Vec::new();
        let mut want = Vec::new();
        for (i, x) in xs.iter().enumerate() {
            let cut = prefix.min(x.len());
            let st0 = if i % 3 == 1 {
                serial(&t, rules[1], &x[..cut], &MasingState::default()).1
            } else {
                serial(&e, rules[i % 3], &x[..cut], &MasingState::default()).1
            };
            let s = &x[cut..];
            want.push(if i % 3 == 1 { serial(&t, rules[1], s, &st0) } else { serial(&e, rules[i % 3], s, &st0) });
            states.push(st0);
            sigs.push(s);
        }
        let mut outs: Vec<Vec<f64>> = sigs.iter().map(|s| vec![f64::NAN; s.len()]).collect();
        let stats = force_channels(
            &models, &sigs, outs.iter_mut().map(Vec::as_mut_slice).collect(),
            &mut states, threads, piece, true,
        ).unwrap();
        for (i, (w, we)) in want.iter().enumerate() {
            prop_assert_eq!(bits(&outs[i]), bits(w));
            prop_assert_eq!(state_bits(&states[i]), state_bits(we));
        }
        prop_assert!(stats.len() <= threads);
        prop_assert_eq!(stats.iter().map(|s| s.samples).sum::<usize>(), sigs.iter().map(|s| s.len()).sum::<usize>());
    }
}

#[test]
fn a_channel_splits_at_reversals_on_every_edge() {
    // a triangle wave whose reversals fall exactly on piece edges and one sample either side
    let c = Exponential::new(10.0, 2e5).unwrap();
    for piece in [5_usize, 6, 7] {
        let x: Vec<f64> = (0..200_i32)
            .map(|i| {
                let p = i % 12;
                f64::from(if p < 6 { p } else { 12 - p }) * 1e-6 * (1.0 + f64::from(i / 12) * 0.1)
            })
            .collect();
        let (want, we) = serial(&c, BranchRule::Scaled(2.0), &x, &MasingState::default());
        let m = Model {
            curve: &c,
            rule: BranchRule::Scaled(2.0),
        };
        let mut st = vec![MasingState::default()];
        let mut out = vec![0.0; x.len()];
        force_channels(&[&m], &[&x], vec![&mut out], &mut st, 2, piece, false).unwrap();
        assert_eq!(bits(&out), bits(&want));
        assert_eq!(st[0], we);
        let sp = split(&c, 2.0, &x, &MasingState::default(), piece)
            .unwrap()
            .unwrap();
        assert_eq!(sp.pieces.len(), x.len().div_ceil(piece));
    }
}

#[test]
fn errors_name_the_lowest_channel_and_leave_every_state() {
    let c = Tabulated::new(&[0.0, 1.0], &[0.0, 1.7e308]).unwrap();
    let e = Exponential::new(10.0, 2e5).unwrap();
    let good = Model {
        curve: &e,
        rule: BranchRule::Scaled(2.0),
    };
    let over = Model {
        curve: &c,
        rule: BranchRule::Scaled(2.0),
    };
    // channel 1 overflows late (after many pieces), channel 2 has a NaN input
    let mut x1: Vec<f64> = (0..300).map(|i| f64::from(i % 7) * 1e-3).collect();
    x1.extend([1.0, -0.99]);
    let mut x2 = vec![1e-6; 100];
    x2[50] = f64::NAN;
    let x0: Vec<f64> = (0..100).map(|i| f64::from(i) * 1e-7).collect();
    let models: [&dyn Channel; 3] = [&good, &over, &good];
    let (mut o0, mut o1, mut o2) = (vec![0.0; 100], vec![0.0; 302], vec![0.0; 100]);
    let mut states = vec![MasingState::default(); 3];
    let r = force_channels(
        &models,
        &[&x0, &x1, &x2],
        vec![&mut o0, &mut o1, &mut o2],
        &mut states,
        2,
        8,
        false,
    );
    // the serial kernel's error for channel 1: the first non-finite force, by index
    let mut s = MasingState::default();
    let mut o = vec![0.0; 302];
    let want = masing_force(&c, 2.0, &x1, &mut o, &mut s).unwrap_err();
    assert_eq!(r.unwrap_err(), want);
    assert!(states.iter().all(|s| *s == MasingState::default()));
    let r = force_channels(
        &models[2..],
        &[&x2],
        vec![&mut o2],
        &mut states[2..],
        2,
        8,
        false,
    );
    assert!(
        matches!(r, Err(CoreError::NonFinite { index: 50, .. })),
        "{r:?}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Slow input (the pre-pass's grouped test on calm blocks) with reversals, repeats and
    /// closures placed anywhere within its groups of eight.
    #[test]
    fn calm_input_with_events_anywhere_equals_the_serial_kernel(
        period in 600.0f64..4000.0, events in prop::collection::vec((0usize..20_000, -3.0f64..3.0), 0..12),
        piece in prop_oneof![3usize..40, 500usize..5000],
    ) {
        let c = Exponential::new(40.0, 4.0e4).unwrap();
        let mut x: Vec<f64> = (0..20_000)
            .map(|i| 1e-5 * (f64::from(i) * std::f64::consts::TAU / period).sin())
            .collect();
        for (at, v) in events {
            x[at] = if v.abs() < 0.3 { x[at.saturating_sub(1)] } else { v * 1e-5 };
        }
        let (want, want_end) = serial(&c, BranchRule::Scaled(2.0), &x, &MasingState::default());
        let m = Model { curve: &c, rule: BranchRule::Scaled(2.0) };
        let mut st = vec![MasingState::default()];
        let mut out = vec![f64::NAN; x.len()];
        force_channels(&[&m], &[&x], vec![&mut out], &mut st, 2, piece, false).unwrap();
        prop_assert_eq!(bits(&out), bits(&want));
        prop_assert_eq!(state_bits(&st[0]), state_bits(&want_end));
        let sp = split(&c, 2.0, &x, &MasingState::default(), piece).unwrap().unwrap();
        prop_assert_eq!(state_bits(&sp.end), state_bits(&want_end));
    }
}
