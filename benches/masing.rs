//! Criterion benchmark of the Masing operator on 1e7 samples, beside a reference loop that only
//! evaluates `exp()` once per sample (measured in the same run, so ratios are meaningful).
//!
//! Targets (one core): >= 75 Msamples/s sine, >= 60 band-limited noise, >= 42 random walk.
//! Run: `cargo bench -p contactlab-core --bench masing`.

use contactlab_core::curve::Exponential;
use contactlab_core::masing::{masing_force, MasingState};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;

#[path = "signals.rs"]
mod signals;

const N: usize = 10_000_000;

fn bench(c: &mut Criterion) {
    // Aluminium-like parameters; amplitudes put the signals well into the curved part.
    let curve = Exponential::new(40.0, 4.0e4).unwrap();
    let cases = [
        ("sine", signals::sine(N, 40e-6)),
        ("band_limited_noise", signals::band_limited(N, 20e-6, 7)),
        ("random_walk", signals::random_walk(N, 0.5e-6, 11)),
    ];
    let mut g = c.benchmark_group("masing_1e7");
    g.sample_size(10);
    g.throughput(Throughput::Elements(N as u64));
    let mut out = vec![0.0; N];
    g.bench_function("reference_exp_loop", |b| {
        let x = &cases[0].1;
        b.iter(|| {
            for (o, &v) in out.iter_mut().zip(x.iter()) {
                *o = (-4.0e4 * v).exp();
            }
            black_box(&out);
        });
    });
    for (name, x) in &cases {
        g.bench_with_input(BenchmarkId::new("masing_force", name), x, |b, x| {
            b.iter(|| {
                let mut st = MasingState::default();
                masing_force(&curve, 2.0, black_box(x), &mut out, &mut st).unwrap();
                black_box(&out);
            });
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
