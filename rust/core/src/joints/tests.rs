use super::*;
use proptest::prelude::*;

fn laws() -> Vec<AnyLaw> {
    let j = |k: f64, fs: f64| AnyLaw::build("jenkins", &[k, fs], vec![]).unwrap();
    let kv = |k: f64| AnyLaw::build("kelvin_voigt", &[k, 0.0], vec![]).unwrap();
    let lugre =
        || AnyLaw::build("lugre", &[1e5, 300.0, 10.0, 4.0, 5.0, 1e-3, 2.0], vec![]).unwrap();
    vec![
        j(1e4, 5.0),
        AnyLaw::build("iwan", &[1e4, 5.0], vec![]).unwrap(),
        AnyLaw::build("segalman", &[5.0, 1e4, -0.5, 0.1], vec![]).unwrap(),
        AnyLaw::build("masing", &[5.0, 3e3, 2.0], vec![]).unwrap(),
        AnyLaw::build("maxwell_slip", &[1e4, 2e4, 2.0, 3.0], vec![]).unwrap(),
        AnyLaw::build(
            "gms",
            &[1e4, 2e4, 0.4, 0.6, 4.0, 5.0, 1e-3, 1e4, 2.0, 0.0],
            vec![],
        )
        .unwrap(),
        AnyLaw::build("dahl", &[1e4, 5.0, 1.0], vec![]).unwrap(),
        AnyLaw::build("dahl", &[1e4, 5.0, 0.5], vec![]).unwrap(),
        AnyLaw::build("dahl", &[1e4, 5.0, 2.0], vec![]).unwrap(),
        lugre(),
        AnyLaw::build("bouc_wen", &[1e4, 1e-3, 0.5, 0.5, 1.5], vec![]).unwrap(),
        AnyLaw::build("series", &[], vec![kv(5e4), j(1e4, 5.0)]).unwrap(),
        AnyLaw::build("series", &[], vec![kv(5e4), lugre()]).unwrap(),
        AnyLaw::build(
            "parallel",
            &[100.0, 1.0],
            vec![AnyLaw::build("backlash", &[2e-4], vec![j(1e4, 5.0)]).unwrap()],
        )
        .unwrap(),
    ]
}

fn sine(amp: f64, n_per: usize, periods: usize) -> (Vec<f64>, Vec<f64>) {
    let n = n_per * periods + 1;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / n_per as f64).collect();
    let x = t
        .iter()
        .map(|&t| amp * (2.0 * std::f64::consts::PI * t).sin())
        .collect();
    (t, x)
}

fn last_cycle_energy(x: &[f64], f: &[f64], n_per: usize) -> f64 {
    let s = x.len() - n_per - 1;
    (s..x.len() - 1)
        .map(|i| 0.5 * (f[i] + f[i + 1]) * (x[i + 1] - x[i]))
        .sum()
}

#[test]
fn jenkins_energy_per_cycle_is_the_closed_form() {
    let law = AnyLaw::build("jenkins", &[1e4, 5.0], vec![]).unwrap();
    for amp in [8e-4, 1e-3, 3e-3] {
        let (t, x) = sine(amp, 4000, 2);
        let f = force(&law, Some(&t), &x, 0.0).unwrap();
        let e = last_cycle_energy(&x, &f, 4000);
        let closed = 4.0 * 5.0 * (amp - 5.0 / 1e4);
        assert!((e - closed).abs() < 2e-5 * closed, "{e} {closed}");
    }
}

#[test]
fn segalman_energy_per_cycle_is_the_power_law() {
    let (f_s, k_t, chi, beta) = (5.0, 1e4, -0.5, 0.3);
    let law = AnyLaw::build("segalman", &[f_s, k_t, chi, beta], vec![]).unwrap();
    let AnyLaw::Segalman(ms) = &law else {
        panic!("segalman")
    };
    let c = ms.curve;
    let r = c.c * (chi + 1.0) * (chi + 2.0);
    for share in [0.05, 0.2, 0.5] {
        let amp = share * c.phi_max;
        let (t, x) = sine(amp, 4000, 2);
        let f = force(&law, Some(&t), &x, 0.0).unwrap();
        let e = last_cycle_energy(&x, &f, 4000);
        let closed = 4.0 * r * amp.powf(chi + 3.0) / ((chi + 2.0) * (chi + 3.0));
        assert!((e - closed).abs() < 1e-5 * closed, "{e} {closed}");
    }
}

#[test]
fn lugre_steady_sliding_is_the_stribeck_curve() {
    let law = AnyLaw::build("lugre", &[1e6, 500.0, 20.0, 4.0, 5.0, 1e-3, 2.0], vec![]).unwrap();
    for v in [2e-4, 1e-3, -3e-3] {
        let t: Vec<f64> = (0..2001).map(|i| i as f64 / 2000.0).collect();
        let x: Vec<f64> = t.iter().map(|&t| v * t).collect();
        let f = force(&law, Some(&t), &x, 0.0).unwrap();
        let g = 4.0 + (-(v / 1e-3_f64).powi(2)).exp();
        let expect = g * v.signum() + 20.0 * v;
        assert!((f[2000] - expect).abs() < 1e-10 * expect.abs());
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    assert!(AnyLaw::build("jenkins", &[-1.0, 5.0], vec![]).is_err());
    assert!(AnyLaw::build("jenkins", &[1.0], vec![]).is_err());
    assert!(AnyLaw::build("nope", &[], vec![]).is_err());
    assert!(AnyLaw::build("segalman", &[1.0, 1.0, -1.0, 0.0], vec![]).is_err());
    assert!(AnyLaw::build("series", &[], vec![]).is_err());
    assert!(AnyLaw::build("gms", &[1.0, 2.0, 3.0], vec![]).is_err());
    assert!(AnyLaw::build("maxwell_slip", &[], vec![]).is_err());
    let lugre = AnyLaw::build("lugre", &[1e5, 1.0, 1.0, 4.0, 5.0, 1e-3, 2.0], vec![]).unwrap();
    assert!(force(&lugre, None, &[0.0, 1.0], 0.0).is_err());
    assert!(matches!(
        force(&lugre, Some(&[0.0, 1.0, 1.0]), &[0.0, 1.0, 2.0], 0.0),
        Err(CoreError::NotIncreasing { index: 2, .. })
    ));
    assert!(matches!(
        force(&lugre, Some(&[0.0, 1.0]), &[0.0, f64::NAN], 0.0),
        Err(CoreError::NonFinite { index: 1, .. })
    ));
    assert!(force(&lugre, Some(&[0.0]), &[0.0, 1.0], 0.0).is_err());
    let mut op = Operator::new(lugre, 0.0).unwrap();
    let mut out = [0.0; 2];
    op.push(Some(&[0.0, 1.0]), &[0.0, 1e-4], &mut out).unwrap();
    assert!(op.push(Some(&[1.0, 2.0]), &[0.0, 1e-4], &mut out).is_err());
    // an error leaves the state as it was
    op.push(Some(&[2.0, 3.0]), &[0.0, 1e-4], &mut out).unwrap();
}

#[test]
fn flat_encoding_builds_the_same_law() {
    // Parallel(k=100, c=1; Backlash(2e-4; Jenkins(1e4, 5)))
    let flat = [
        10.0, 2.0, 100.0, 1.0, 1.0, 12.0, 1.0, 2e-4, 1.0, 0.0, 2.0, 1e4, 5.0, 0.0,
    ];
    let law = AnyLaw::from_flat(&flat).unwrap();
    assert_eq!(law, laws()[13]);
    for bad in [
        &flat[..5],
        &[13.0, 0.0, 0.0][..],
        &[0.0, 2.0, 1.0, 1.0, 0.0, 7.0][..],
        &[0.0, 2.5, 1.0, 1.0, 0.0][..],
        &[0.0, f64::NAN][..],
    ] {
        assert!(AnyLaw::from_flat(bad).is_err(), "{bad:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn chunked_equals_one_pass(which in 0usize..14, steps in prop::collection::vec((1e-4f64..1e-3, -1e-4f64..1e-4), 2..200), cut in 0usize..200) {
        let law = &laws()[which];
        let mut t = Vec::new();
        let mut x = Vec::new();
        let (mut tc, mut xc) = (0.0, 0.0);
        for (dt, dx) in &steps {
            tc += dt;
            xc += dx;
            t.push(tc);
            x.push(xc);
        }
        let whole = force(law, Some(&t), &x, 0.0).unwrap();
        let c = cut.min(x.len());
        let mut op = Operator::new(law.clone(), 0.0).unwrap();
        let mut a = vec![0.0; c];
        let mut b = vec![0.0; x.len() - c];
        op.push(Some(&t[..c]), &x[..c], &mut a).unwrap();
        op.push(Some(&t[c..]), &x[c..], &mut b).unwrap();
        a.extend(b);
        prop_assert_eq!(a, whole);
    }

    #[test]
    fn odd_symmetry(which in 0usize..14, steps in prop::collection::vec((1e-4f64..1e-3, -3e-4f64..3e-4), 2..200)) {
        let law = &laws()[which];
        let (mut tc, mut xc) = (0.0, 0.0);
        let mut t = Vec::new();
        let mut x = Vec::new();
        for (dt, dx) in &steps {
            tc += dt;
            xc += dx;
            t.push(tc);
            x.push(xc);
        }
        let neg: Vec<f64> = x.iter().map(|v| -v).collect();
        let fp = force(law, Some(&t), &x, 0.0).unwrap();
        let fm = force(law, Some(&t), &neg, 0.0).unwrap();
        for (a, b) in fp.iter().zip(&fm) {
            prop_assert!((a + b).abs() <= 1e-12 * (1.0 + a.abs()), "{} {}", a, b);
        }
    }

    #[test]
    fn dissipation_per_cycle_is_not_negative(which in 0usize..14, amp in 1e-5f64..5e-3, off in -1e-3f64..1e-3) {
        // not the generalised Maxwell-slip model: a sliding element's force rises towards a
        // higher Stribeck limit as the motion slows without doing the matching work (F_i
        // moves in time, not with displacement), which the next sticking phase returns
        // elastically: a known lack of passivity of the model (-2e-3 of F A found here)
        prop_assume!(which != 5);
        let law = &laws()[which];
        let n = 400usize;
        let t: Vec<f64> = (0..=3 * n).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = (0..=3 * n)
            .map(|i| off + amp * (2.0 * std::f64::consts::PI * i as f64 / n as f64).sin())
            .collect();
        let f = force(law, Some(&t), &x, 0.0).unwrap();
        let e = last_cycle_energy(&x, &f, n);
        let scale = f.iter().fold(0.0f64, |m, v| m.max(v.abs())) * amp;
        prop_assert!(e >= -1e-9 * scale - 1e-300, "{}", e);
    }
}
