//! Criterion benchmark of the normal-contact integrator: the nonlinear model (Table 2 k_s(δ),
//! ψ = 0.0887, ω = 1 rad/s) over a sampled sine at 256 samples per period, rtol 1e-8.
//! The scipy comparison lives in `bench_normal.py`.

use std::f64::consts::PI;

use contactlab_core::normal::{simulate, ContactModel, Forcing, Interp, Options, Stiffness};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

fn bench_simulate(c: &mut Criterion) {
    let model = ContactModel::new(
        Stiffness::Delta(vec![1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30]),
        0.0887,
        1.0,
    )
    .expect("valid model");
    let mut group = c.benchmark_group("normal_simulate");
    group.sample_size(10);
    for &n in &[100_000_usize, 1_000_000] {
        let dt = 2.0 * PI / 256.0;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let p: Vec<f64> = t.iter().map(|&v| 0.4e6 * v.sin()).collect();
        let forcing = Forcing::new(&t, &p, None, Interp::Cubic).expect("valid forcing");
        let opts = Options {
            rtol: 1e-8,
            atol: 1e-8 * 0.4e6 / 1.32596e12,
            ..Options::default()
        };
        let mut delta = vec![0.0; n];
        let mut vel = vec![0.0; n];
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                simulate(&model, &forcing, 0.0, &opts, &mut delta, &mut vel).expect("solves")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench_simulate);
criterion_main!(benches);
