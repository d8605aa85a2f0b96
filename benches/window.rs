//! `window::fold_window` (the per-sample pass of a streamed tangential analysis window)
//! against the Masing kernel on the same samples, in the same run: ns per sample of each and
//! their ratio. A window of 2^19 samples of a 10 Hz sine at 10 kHz (1000 samples a cycle,
//! 400 phase bins: what `analyze` folds), with noise on x and F; each pass is timed `--repeat`
//! times, the two alternately, and the medians and minima are printed.
//!
//! Run: `cargo bench -p contactlab-core --bench window` (`-- --n 524288 --repeat 31 --bins 400`).

use contactlab_core::curve::Exponential;
use contactlab_core::masing::{masing_force, MasingState};
use contactlab_core::window::fold_window;
use std::hint::black_box;
use std::time::Instant;

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse::<f64>().ok())
        .map_or(default, |v| v as usize)
}

fn stats(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0])
}

fn main() {
    let n = arg("--n", 1 << 19);
    let repeat = arg("--repeat", 31).max(1);
    let bins = arg("--bins", 400);
    let per_cycle = 1000.0;
    let mut s: u64 = 12;
    let mut noise = move || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let w = 2.0 * std::f64::consts::PI / per_cycle;
    let x: Vec<f64> = (0..n)
        .map(|i| 20e-6 * ((w * i as f64).sin() + 0.002 * noise()))
        .collect();
    let f: Vec<f64> = (0..n)
        .map(|i| 40.0 * ((w * i as f64 + 0.3).sin() + 0.01 * noise()))
        .collect();
    // knots: peaks of the sine at i = per_cycle/4 + k·per_cycle (phase k), valleys half way
    let n_cyc = ((n as f64 - per_cycle / 4.0) / per_cycle).floor() as usize - 1;
    let (mut kt, mut kp) = (Vec::new(), Vec::new());
    for k in 0..=n_cyc {
        let tp = (per_cycle / 4.0 + k as f64 * per_cycle) * 1e-4;
        kt.push(tp);
        kp.push(k as f64);
        if k < n_cyc {
            kt.push(tp + 0.5 * per_cycle * 1e-4);
            kp.push(k as f64 + 0.5);
        }
    }
    let edges: Vec<f64> = kt.iter().step_by(2).copied().collect();
    let curve = Exponential::new(40.0, 4e4).expect("curve");
    let mut out = vec![0.0; n];
    let (mut tf, mut tm) = (Vec::new(), Vec::new());
    let mut keep = 0.0;
    for r in 0..repeat {
        let fold = || {
            let a = Instant::now();
            let wf = fold_window(&t, &x, &f, &kt, &kp, bins, n_cyc, &edges).expect("fold");
            (a.elapsed().as_secs_f64(), wf.energy[0])
        };
        let masing = |out: &mut [f64]| {
            let mut st = MasingState::default();
            let a = Instant::now();
            masing_force(&curve, 2.0, black_box(&x), out, &mut st).expect("masing");
            a.elapsed().as_secs_f64()
        };
        if r % 2 == 0 {
            let (d, e) = fold();
            tf.push(d);
            keep += e;
            tm.push(masing(&mut out));
        } else {
            tm.push(masing(&mut out));
            let (d, e) = fold();
            tf.push(d);
            keep += e;
        }
    }
    black_box((keep, &out));
    let ((fm, fmin), (mm, mmin)) = (stats(&mut tf), stats(&mut tm));
    let ns = |v: f64| v * 1e9 / n as f64;
    println!("n = {n}, {bins} bins, {n_cyc} cycles, {repeat} repeats (median / min ns per sample)");
    println!("fold_window     {:7.2} / {:7.2}", ns(fm), ns(fmin));
    println!("masing_force    {:7.2} / {:7.2}", ns(mm), ns(mmin));
    println!("fold / masing   {:7.2} / {:7.2}", fm / mm, fmin / mmin);
}
