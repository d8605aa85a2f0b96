//! Masing kernel (`masing_force`) against a plain std-Rust loop of the same rules
//! (`masing_reference.rs`: index stack, libm exp, output buffer reused) on 1e7 samples of a
//! sine, band-limited noise and a random walk. Build for generic x86-64 (no target-cpu flags),
//! as shipped wheels are; both are compiled into this one binary with the bench profile.
//!
//! The machine may be shared, and a 1e7-sample pass (tens of ms) is almost always preempted
//! somewhere. So each signal is run in pieces of `--piece` samples (both sides carry their
//! state from piece to piece, so the work is that of one pass), and each piece is timed
//! `--repeat` times, reference and kernel alternately and in alternating order. A piece's
//! time is its median (and its minimum) over the repeats; a signal's time is the sum over its
//! pieces. The ratio reference/kernel is the speed-up (required >= 1.0 on every signal, goal
//! 1.3), given for the medians and for the minima. The outputs of the last repeat are
//! compared (max |difference| / h0).
//!
//! The pre-pass of the split kernel (`masing::split::split_each`: the memory rules with no
//! curve evaluation, what cutting a channel into independent pieces costs) is timed the same
//! way on the same pieces from the same states: `pre ns` and `pre/kern` (the wall speed-up of
//! one channel on two threads is at most `2 - pre/kern`).
//!
//! Run: `cargo bench -p contactlab-core --bench masing`
//! (`-- --n 1000000 --repeat 15 --piece 100000 --signal random_walk`).
//!
//! On a heavily loaded machine even the per-piece medians drift (the two sides suffer
//! differently from a busy sibling hyperthread). The CPU-time split from a sampling profiler
//! does not: `perf record -e cpu-clock BINARY --signal S`, then `perf report --sort sym`, and
//! add `reference_piece` + libm's `exp`/`expm1` symbols against `kernel_piece` +
//! `contactlab_core::*` symbols.

use contactlab_core::curve::Exponential;
use contactlab_core::masing::split::{split_each, Walked};
use contactlab_core::masing::{masing_force, MasingState};
use std::hint::black_box;
use std::time::Instant;

#[path = "masing_reference.rs"]
mod reference;
#[path = "signals.rs"]
mod signals;

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn num(name: &str, default: usize) -> usize {
    arg(name)
        .and_then(|v| v.parse::<f64>().ok())
        .map_or(default, |v| v as usize)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// One piece through the reference (not inlined: a profiler can tell the two sides apart).
#[inline(never)]
fn reference_piece(rf: &mut reference::Reference, x: &[f64], out: &mut [f64], p: Range) {
    rf.run(40.0, 4.0e4, 2.0, black_box(x), out, p);
    black_box(out);
}

/// One piece through the kernel, continuing from `st`.
#[inline(never)]
fn kernel_piece(c: &Exponential, x: &[f64], out: &mut [f64], p: Range, st: &mut MasingState) {
    masing_force(c, 2.0, black_box(&x[p.clone()]), &mut out[p], st).unwrap();
    black_box(out);
}

/// The split kernel's pre-pass over one piece from `st` (one piece: no boundary inside).
#[inline(never)]
fn prepass_piece(c: &Exponential, x: &[f64], p: Range, st: &MasingState) -> usize {
    let w = split_each(c, 2.0, black_box(&x[p]), st, usize::MAX, |_, _| true).unwrap();
    match black_box(w) {
        Walked::Ended(e) => e.stack.len(),
        Walked::Whole | Walked::Stopped => 0,
    }
}

type Range = std::ops::Range<usize>;

fn main() {
    let n = num("--n", 10_000_000);
    let repeat = num("--repeat", 15).max(1);
    let piece = num("--piece", 100_000).max(1);
    let only = arg("--signal");
    let h0 = 40.0;
    let curve = Exponential::new(h0, 4.0e4).unwrap();
    let cases: Vec<(&str, Vec<f64>)> = [
        (
            "sine",
            (|n| signals::sine(n, 40e-6)) as fn(usize) -> Vec<f64>,
        ),
        ("band_limited_noise", |n| signals::band_limited(n, 20e-6, 7)),
        ("random_walk", |n| signals::random_walk(n, 0.5e-6, 11)),
    ]
    .into_iter()
    .filter(|(name, _)| only.as_deref().is_none_or(|o| o == *name))
    .map(|(name, f)| (name, f(n)))
    .collect();
    let mut out = vec![0.0; n];
    let mut out_ref = vec![0.0; n];
    let mut rf = reference::Reference::default();
    let pieces: Vec<Range> = (0..n)
        .step_by(piece)
        .map(|a| a..(a + piece).min(n))
        .collect();
    println!(
        "n = {n:.0e} samples in pieces of {piece:.0e}; per piece median (min) of {repeat} \
         interleaved repeats, summed; generic build"
    );
    println!(
        "{:<20}{:>12}{:>12}{:>9}{:>12}{:>12}{:>9}{:>13}{:>9}{:>10}",
        "signal",
        "kern ns",
        "ref ns",
        "ratio",
        "kern min",
        "ref min",
        "ratio",
        "max |d|/h0",
        "pre ns",
        "pre/kern"
    );
    let mut worst = f64::INFINITY;
    for (name, x) in &cases {
        let mut t_k = vec![vec![0.0; repeat]; pieces.len()];
        let mut t_r = vec![vec![0.0; repeat]; pieces.len()];
        let mut t_p = vec![vec![0.0; repeat]; pieces.len()];
        for r in 0..repeat {
            let mut st = MasingState::default();
            rf.reset();
            for (k, p) in pieces.iter().enumerate() {
                let before = st.clone();
                let t0 = Instant::now();
                prepass_piece(&curve, x, p.clone(), &before);
                t_p[k][r] = t0.elapsed().as_secs_f64();
                let mut time_ref = || {
                    let t0 = Instant::now();
                    reference_piece(&mut rf, x, &mut out_ref, p.clone());
                    t0.elapsed().as_secs_f64()
                };
                let mut time_kernel = || {
                    let t0 = Instant::now();
                    kernel_piece(&curve, x, &mut out, p.clone(), &mut st);
                    t0.elapsed().as_secs_f64()
                };
                if (r + k) % 2 == 0 {
                    t_r[k][r] = time_ref();
                    t_k[k][r] = time_kernel();
                } else {
                    t_k[k][r] = time_kernel();
                    t_r[k][r] = time_ref();
                }
            }
        }
        let total = |t: &mut [Vec<f64>], f: fn(&mut [f64]) -> f64| -> f64 {
            t.iter_mut().map(|v| f(v)).sum::<f64>()
        };
        let min = |v: &mut [f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let (k_med, r_med) = (total(&mut t_k, median), total(&mut t_r, median));
        let (k_min, r_min) = (total(&mut t_k, min), total(&mut t_r, min));
        let p_med = total(&mut t_p, median);
        let diff = out
            .iter()
            .zip(&out_ref)
            .map(|(a, b)| (a - b).abs() / h0)
            .fold(0.0_f64, f64::max);
        let ratio = r_med / k_med;
        worst = worst.min(ratio);
        let ns = |t: f64| t / n as f64 * 1e9;
        println!(
            "{name:<20}{:>12.2}{:>12.2}{ratio:>9.2}{:>12.2}{:>12.2}{:>9.2}{diff:>13.1e}{:>9.2}{:>10.3}",
            ns(k_med),
            ns(r_med),
            ns(k_min),
            ns(r_min),
            r_min / k_min,
            ns(p_med),
            p_med / k_med,
        );
    }
    println!(
        "worst median ratio {worst:.2} (required >= 1.00, goal 1.30): {}",
        if worst >= 1.0 { "ok" } else { "BELOW" }
    );
}
