//! Masing kernel (`masing_force`) against a plain std-Rust loop of the same rules
//! (`masing_reference.rs`: index stack, libm exp, output buffer reused) on 1e7 samples of a
//! sine, band-limited noise and a random walk. Both run in the same process, interleaved
//! (reference, kernel, reference, ...), best of `REPEAT`; the ratio reference/kernel is the
//! speed-up (required >= 1.0 on every signal, goal 1.3). Build for generic x86-64 (no
//! target-cpu flags), as shipped wheels are.
//!
//! Run: `cargo bench -p contactlab-core --bench masing` (`-- --n 1000000 --repeat 5`).

use contactlab_core::curve::Exponential;
use contactlab_core::masing::{masing_force, MasingState};
use std::hint::black_box;
use std::time::Instant;

#[path = "masing_reference.rs"]
mod reference;
#[path = "signals.rs"]
mod signals;

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse::<f64>().ok())
        .map_or(default, |v| v as usize)
}

fn main() {
    let n = arg("--n", 10_000_000);
    let repeat = arg("--repeat", 15).max(1);
    let (h0, ac) = (40.0, 4.0e4);
    let curve = Exponential::new(h0, ac).unwrap();
    let cases = [
        ("sine", signals::sine(n, 40e-6)),
        ("band_limited_noise", signals::band_limited(n, 20e-6, 7)),
        ("random_walk", signals::random_walk(n, 0.5e-6, 11)),
    ];
    let mut out = vec![0.0; n];
    let mut out_ref = vec![0.0; n];
    let mut stack = Vec::new();
    println!("n = {n:.0e} samples, best of {repeat} interleaved repeats (generic build)");
    println!(
        "{:<20}{:>14}{:>14}{:>9}{:>14}",
        "signal", "kernel Ms/s", "ref Ms/s", "ratio", "max rel diff"
    );
    let mut worst = f64::INFINITY;
    for (name, x) in &cases {
        let (mut t_k, mut t_r) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..repeat {
            let t0 = Instant::now();
            reference::reference_force(h0, ac, 2.0, black_box(x), &mut out_ref, &mut stack);
            black_box(&out_ref);
            t_r = t_r.min(t0.elapsed().as_secs_f64());
            let t0 = Instant::now();
            let mut st = MasingState::default();
            masing_force(&curve, 2.0, black_box(x), &mut out, &mut st).unwrap();
            black_box(&out);
            t_k = t_k.min(t0.elapsed().as_secs_f64());
        }
        let diff = out
            .iter()
            .zip(&out_ref)
            .map(|(a, b)| (a - b).abs() / h0)
            .fold(0.0_f64, f64::max);
        let ratio = t_r / t_k;
        worst = worst.min(ratio);
        println!(
            "{name:<20}{:>14.1}{:>14.1}{ratio:>9.2}{diff:>14.1e}",
            n as f64 / t_k / 1e6,
            n as f64 / t_r / 1e6,
        );
    }
    println!(
        "worst ratio {worst:.2} (required >= 1.00, goal 1.30): {}",
        if worst >= 1.0 { "ok" } else { "BELOW" }
    );
}
