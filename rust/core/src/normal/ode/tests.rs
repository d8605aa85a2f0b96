use super::super::forcing::Interp;
use super::super::model::Stiffness;
use super::*;
use std::f64::consts::PI;

fn sine(n: usize, per: usize, w: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let dt = 2.0 * PI / w / per as f64;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let p = t.iter().map(|&v| 0.4 * (w * v).sin()).collect();
    let d = t.iter().map(|&v| 0.4 * w * (w * v).cos()).collect();
    (t, p, d)
}

#[test]
fn kelvin_voigt_reaches_analytic_steady_state() {
    let (k, psi, w) = (1.206, 0.0887, 1.0);
    let m = ContactModel::new(Stiffness::Constant(k), psi, w).unwrap();
    // 512 samples per period: the cubic interpolant's own error (~(ωΔt)⁴/384) is then
    // small enough that δ' = (2πω/ψ)(p/k − δ), which amplifies δ errors by 2π/ψ, is
    // within 1e-8 too.
    let (t, p, d) = sine(512 * 6 + 1, 512, w);
    let fo = Forcing::new(&t, &p, Some(&d), Interp::Cubic).unwrap();
    let mut y = vec![0.0; t.len()];
    let mut v = vec![0.0; t.len()];
    let opts = Options {
        rtol: 1e-10,
        atol: 1e-16,
        ..Options::default()
    };
    let out = simulate(&m, &fo, 0.0, &opts, &mut y, &mut v).unwrap();
    assert_eq!(out.status, Status::Success);
    let g = psi / (2.0 * PI);
    let amp = 0.4 / k / (1.0 + g * g).sqrt();
    let phi = g.atan();
    let (mut ed, mut ev) = (0.0_f64, 0.0_f64);
    for i in 512 * 2..t.len() {
        let exact = amp * (w * t[i] - phi).sin();
        ed = ed.max((y[i] - exact).abs() / amp);
        let vexact = amp * w * (w * t[i] - phi).cos();
        ev = ev.max((v[i] - vexact).abs() / (amp * w));
    }
    assert!(ed < 1e-8 && ev < 1e-8, "relative error {ed} {ev}");
}

#[test]
fn order_four_convergence() {
    // Fixed large sample interval, tight tolerance off: compare two coarse tolerances.
    let m = ContactModel::new(
        Stiffness::Delta(vec![1.32596, 1.59811, 2.92127, 2.87416]),
        0.0887,
        1.0,
    )
    .unwrap();
    let (t, p, d) = sine(256 * 3 + 1, 256, 1.0);
    let fo = Forcing::new(&t, &p, Some(&d), Interp::Cubic).unwrap();
    let run = |rtol: f64| {
        let mut y = vec![0.0; t.len()];
        let mut v = vec![0.0; t.len()];
        let o = Options {
            rtol,
            atol: rtol * 1e-3,
            ..Options::default()
        };
        let out = simulate(&m, &fo, 0.0, &o, &mut y, &mut v).unwrap();
        (y, out)
    };
    let (yref, _) = run(1e-13);
    for rtol in [1e-6, 1e-8, 1e-10] {
        let (y, out) = run(rtol);
        let err = y
            .iter()
            .zip(&yref)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let scale = yref.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        assert!(
            err / scale < 50.0 * rtol,
            "rtol {rtol}: err {}",
            err / scale
        );
        assert!(out.stats.n_accepted >= (t.len() - 1) as u64);
    }
}

#[test]
fn taylor_matches_rodas4_on_noisy_input_and_a_far_start() {
    // Table 2 centre curve (SI), 1 % noise on p, started 0.3 µm off equilibrium: the
    // Taylor route (split where the start-up needs it) against RODAS4, both at rtol 1e-11.
    let m = ContactModel::new(
        Stiffness::Delta(vec![1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30]),
        0.0887,
        1.0,
    )
    .unwrap();
    let (t, mut p, _) = sine(256 * 3 + 1, 256, 1.0);
    let mut state: u64 = 7;
    for v in &mut p {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        *v = *v * 1e6 + 0.4e6 * 0.01 * 3.46 * u;
    }
    let fo = Forcing::new(&t, &p, None, Interp::Cubic).unwrap();
    let scale = 0.4e6 / 1.32596e12;
    let o = Options {
        rtol: 1e-11,
        atol: 1e-11 * scale,
        ..Options::default()
    };
    let run = |method| {
        let (mut y, mut v) = (vec![0.0; t.len()], vec![0.0; t.len()]);
        let out = simulate_with(&m, &fo, 0.3e-6, &o, method, &mut y, &mut v).unwrap();
        assert_eq!(out.status, Status::Success);
        (y, v, out)
    };
    let (ya, va, oa) = run(Method::Auto);
    let (yr, vr, _) = run(Method::Rodas4);
    let dmax = yr.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let vmax = vr.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    for i in 0..t.len() {
        assert!((ya[i] - yr[i]).abs() < 1e-9 * dmax, "δ at {i}");
        assert!((va[i] - vr[i]).abs() < 1e-8 * vmax, "δ' at {i}");
    }
    assert_eq!(oa.stats.njev, 0, "every interval by Taylor steps");
    assert!(oa.stats.n_rejected > 0, "the far start was split");
}

#[test]
fn stiff_limit_is_stable_on_the_sample_grid() {
    // ψ tiny: time constant 1e-6 of the sample interval; the L-stable method must not blow up.
    let m = ContactModel::new(Stiffness::Constant(2.0), 1e-7, 1.0).unwrap();
    let (t, p, d) = sine(513, 64, 1.0);
    let fo = Forcing::new(&t, &p, Some(&d), Interp::Cubic).unwrap();
    let mut y = vec![0.0; t.len()];
    let mut v = vec![0.0; t.len()];
    let out = simulate(&m, &fo, 1.0, &Options::default(), &mut y, &mut v).unwrap();
    assert_eq!(out.status, Status::Success);
    for i in 64..t.len() {
        assert!((y[i] - p[i] / 2.0).abs() < 1e-6);
    }
}

#[test]
fn leaving_the_domain_returns_the_partial_solution() {
    // k_s(δ) = 1 + 5e6 δ vanishes at δ = -0.2e-6 inside the response; a loose tolerance
    // lets an accepted step land beyond it.
    let m = ContactModel::new(Stiffness::Delta(vec![1e12, 5e18]), 0.1, 1.0).unwrap();
    let w = 1.0;
    let per = 16;
    let n = 2 * per + 1;
    let dt = 2.0 * PI / w / per as f64;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let p: Vec<f64> = t.iter().map(|&v| 0.4e6 * (w * v).sin()).collect();
    let fo = Forcing::new(&t, &p, None, Interp::Linear).unwrap();
    let mut y = vec![f64::NAN; n];
    let mut v = vec![f64::NAN; n];
    let o = Options {
        rtol: 0.1,
        atol: 1e-8,
        ..Options::default()
    };
    let out = simulate(&m, &fo, 0.0, &o, &mut y, &mut v).unwrap();
    let Status::NonPositiveStiffness {
        name, at, value, ..
    } = out.status
    else {
        panic!("expected NonPositiveStiffness, got {:?}", out.status);
    };
    assert_eq!(name, "delta");
    assert!(at < -0.2e-6 && value <= 0.0);
    assert_eq!(out.status.code(), -1);
    assert!(out.status.message().contains("not positive"));
    assert!(out.n_out > 1 && out.n_out < n);
    // Everything reported lies inside the domain and was computed.
    for &d in &y[..out.n_out] {
        assert!(d.is_finite() && 1e12 + 5e18 * d > 0.0);
    }
}

#[test]
fn starting_outside_the_domain_is_an_error() {
    let m = ContactModel::new(Stiffness::Delta(vec![1e12, 5e18]), 0.1, 1.0).unwrap();
    let (t, p, _) = sine(33, 16, 1.0);
    let fo = Forcing::new(&t, &p, None, Interp::Linear).unwrap();
    let (mut y, mut v) = (vec![0.0; t.len()], vec![0.0; t.len()]);
    let r = simulate(&m, &fo, -1e-6, &Options::default(), &mut y, &mut v);
    assert!(matches!(r, Err(CoreError::NonPositiveStiffness { .. })));
}

#[test]
fn max_steps_reports_failure() {
    let m = ContactModel::new(Stiffness::Constant(2.0), 0.1, 1.0).unwrap();
    let (t, p, _) = sine(100, 64, 1.0);
    let fo = Forcing::new(&t, &p, None, Interp::Linear).unwrap();
    let mut y = vec![0.0; t.len()];
    let mut v = vec![0.0; t.len()];
    let o = Options {
        max_steps: 10,
        ..Options::default()
    };
    let out = simulate(&m, &fo, 0.0, &o, &mut y, &mut v).unwrap();
    assert!(matches!(out.status, Status::MaxSteps { .. }));
    assert!(out.n_out < t.len());
}
