//! The per-window reversal search's kernels against references in the same run: ns per
//! sample and the ratios. `Schmitt::push` (blocks of an open excursion on its side of the
//! band take a vectorised fast path) against a pass that only reads the samples (their
//! finite check, `check_finite`: the floor of any pass over them); `select::order_stats` of
//! the four order statistics the 0.5 and 99.5 percentiles interpolate (subsample thresholds,
//! one gathering pass over both tails) against `select_nth_unstable` of a copy of the whole
//! sample for the same ranks (what a plain selection costs). A window of 2^20 samples of a
//! 10 Hz sine at 10 kHz with noise (what `analyze` searches); each timed `--repeat` times,
//! alternately, medians and minima printed.
//!
//! Run: `cargo bench -p contactlab-core --bench reversals` (`-- --n 1048576 --repeat 31`).

use contactlab_core::error::check_finite;
use contactlab_core::reversal::Schmitt;
use contactlab_core::select::order_stats;
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

fn time<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let a = Instant::now();
    let r = f();
    (a.elapsed().as_secs_f64(), r)
}

fn main() {
    let n = arg("--n", 1 << 20);
    let repeat = arg("--repeat", 31).max(1);
    let mut s: u64 = 29;
    let mut noise = move || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let w = 2.0 * std::f64::consts::PI / 1000.0;
    let x: Vec<f64> = (0..n)
        .map(|i| 20e-6 * ((w * i as f64).sin() + 0.01 * noise()))
        .collect();
    let q = [0.005, 0.995].map(|p| (n - 1) as f64 * p);
    let ranks: Vec<usize> = q
        .iter()
        .flat_map(|&v| [v.floor() as usize, v.floor() as usize + 1])
        .collect();
    let (mut tp, mut tc, mut to, mut ts) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut keep = 0.0;
    for _ in 0..repeat {
        let (d, done) = time(|| {
            let mut st = Schmitt::new(0.0, 10e-6).expect("detector");
            let mut done = Vec::new();
            st.push(black_box(&x), None, &mut done).expect("push");
            done
        });
        tp.push(d);
        keep += done.len() as f64;
        let (d, r) = time(|| check_finite("x", black_box(&x)));
        tc.push(d);
        keep += f64::from(u8::from(r.is_ok()));
        let (d, v) = time(|| order_stats(black_box(&x), &ranks).expect("order stats"));
        to.push(d);
        keep += v[0];
        let (d, v) = time(|| {
            let mut all = black_box(&x).clone();
            ranks
                .iter()
                .map(|&r| *all.select_nth_unstable_by(r, f64::total_cmp).1)
                .collect::<Vec<f64>>()
        });
        ts.push(d);
        keep += v[0];
    }
    black_box(keep);
    let ns = |v: f64| v * 1e9 / n as f64;
    let [(pm, pmin), (cm, cmin), (om, omin), (sm, smin)] =
        [&mut tp, &mut tc, &mut to, &mut ts].map(|v| stats(v));
    println!("n = {n}, {repeat} repeats (median / min ns per sample)");
    println!("Schmitt::push         {:7.2} / {:7.2}", ns(pm), ns(pmin));
    println!("check_finite          {:7.2} / {:7.2}", ns(cm), ns(cmin));
    println!(
        "push / check_finite   {:7.2} / {:7.2}",
        pm / cm,
        pmin / cmin
    );
    println!("order_stats (4)       {:7.2} / {:7.2}", ns(om), ns(omin));
    println!("copy + select (4)     {:7.2} / {:7.2}", ns(sm), ns(smin));
    println!(
        "order_stats / select  {:7.2} / {:7.2}",
        om / sm,
        omin / smin
    );
}
