//! Every SIMD level the CPU has gives the generic path's forces bit for bit, and all of
//! them the plain loop's (the anchor's rules with libm `exp`) to 1e-12 of h0.
use super::*;
use crate::curve::Exponential;

fn uniform(seed: u64, n: usize) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            2.0 * ((s >> 11) as f64 / 9_007_199_254_740_992.0) - 1.0
        })
        .collect()
}

/// Sine (long runs), band-limited noise (runs of ~6), random walk (runs of ~2), and a
/// mix with zero-length steps, held values, jumps that close several loops, and a drift.
fn signals(n: usize) -> Vec<Vec<f64>> {
    let sine: Vec<f64> = (0..n)
        .map(|i| 0.8 * (std::f64::consts::TAU * (i % 700) as f64 / 700.0).sin())
        .collect();
    let e = uniform(1, n);
    let mut band = vec![0.0; n];
    let a1 = 2.0 * 0.95 * (std::f64::consts::TAU / 40.0).cos();
    for i in 2..n {
        band[i] = a1 * band[i - 1] - 0.9025 * band[i - 2] + 0.06 * e[i];
    }
    let e = uniform(2, n);
    let mut walk = vec![0.0; n];
    for i in 1..n {
        walk[i] = 0.999 * walk[i - 1] + 0.05 * e[i];
    }
    let e = uniform(3, n);
    let mixed: Vec<f64> = (0..n)
        .map(|i| {
            let held = (i / 3) as f64; // every value thrice: zero-length steps
            let jump = if i % 997 == 0 { 3.0 * e[i] } else { 0.0 };
            0.4 * (held * 0.05).sin() + 0.1 * e[i].round() + jump + 1e-5 * i as f64
        })
        .collect();
    vec![sine, band, walk, mixed]
}

/// The anchor's scalar loop (`masing_anchor.rs`, `masing`) for branch scale `lam`.
fn plain(h0: f64, ac: f64, lam: f64, x: &[f64]) -> Vec<f64> {
    let (mut xr, mut hr): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    let (mut xp, mut hp, mut d) = (0.0_f64, 0.0_f64, 0.0_f64);
    let f = |u: f64| (h0 * -(-ac * u.abs()).exp_m1()).copysign(u);
    x.iter()
        .map(|&xi| {
            if xi != xp {
                let s = if xi > xp { 1.0 } else { -1.0 };
                if s != d {
                    if d != 0.0 {
                        xr.push(xp);
                        hr.push(hp);
                    }
                    d = s;
                }
                while let Some(&top) = xr.last() {
                    let k = xr.len();
                    let t = if k >= 2 { xr[k - 2] } else { -top };
                    if s * (xi - t) < 0.0 {
                        break;
                    }
                    let nk = k.saturating_sub(2);
                    xr.truncate(nk);
                    hr.truncate(nk);
                }
                hp = match (xr.last(), hr.last()) {
                    (Some(&a), Some(&b)) => b + lam * f((xi - a) / lam),
                    _ => f(xi),
                };
                xp = xi;
            }
            hp
        })
        .collect()
}

#[test]
fn every_level_gives_the_generic_forces_bit_for_bit() {
    let (h0, ac) = (1.0, 3.0);
    let c = Exponential::new(h0, ac).unwrap_or_else(|_| unreachable!());
    for (k, x) in signals(20_000).iter().enumerate() {
        for lam in [2.0, 1.7] {
            let run_at = |level: Level, cut: usize| {
                let mut out = vec![0.0; x.len()];
                let mut st = MasingState::default();
                let (a, b) = x.split_at(cut);
                let (oa, ob) = out.split_at_mut(cut);
                assert_eq!(scaled_force(level, &c, lam, a, oa, &mut st), Forces::Finite);
                assert_eq!(scaled_force(level, &c, lam, b, ob, &mut st), Forces::Finite);
                (out, st)
            };
            let (want, want_st) = run_at(Level::Generic, x.len());
            let reference = plain(h0, ac, lam, x);
            let worst = want
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                worst <= 1e-12 * h0,
                "signal {k}, lam {lam}: {worst:e} from the loop"
            );
            for level in Level::ALL.into_iter().filter(|l| l.supported()) {
                for cut in [x.len(), 777, 5_000] {
                    let (got, st) = run_at(level, cut);
                    let same = got
                        .iter()
                        .zip(&want)
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(same, "signal {k}, level {}, cut {cut}", level.name());
                    assert_eq!(st, want_st);
                }
            }
        }
    }
}

#[test]
fn a_non_finite_input_stops_the_kernel_at_every_level() {
    let c = Exponential::new(1.0, 3.0).unwrap_or_else(|_| unreachable!());
    for level in Level::ALL.into_iter().filter(|l| l.supported()) {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut x: Vec<f64> = (0..3000).map(|i| (i as f64 * 0.01).sin()).collect();
            x[2100] = bad;
            let mut out = vec![0.0; x.len()];
            let mut st = MasingState::default();
            let r = scaled_force(level, &c, 2.0, &x, &mut out, &mut st);
            assert_eq!(r, Forces::BadInput, "level {}", level.name());
        }
    }
}

/// The dense path checks its block after its first pass: a non-finite input anywhere in a
/// dense block (a random walk's, or band-limited noise's) still stops the kernel, at every
/// level, and the blocks before it are the forces of the input without it.
#[test]
fn a_non_finite_input_in_a_dense_block_stops_the_kernel_at_every_level() {
    let c = Exponential::new(1.0, 3.0).unwrap_or_else(|_| unreachable!());
    let sig = signals(4 * BLOCK);
    for level in Level::ALL.into_iter().filter(|l| l.supported()) {
        for x0 in &sig[1..3] {
            let mut good = vec![0.0; x0.len()];
            let mut st = MasingState::default();
            let r = scaled_force(level, &c, 2.0, x0, &mut good, &mut st);
            assert_eq!(r, Forces::Finite);
            // in the first dense block (the second), at its first, a middle and its last
            // sample, and in a later one
            for at in [BLOCK, BLOCK + 1, BLOCK + 300, 2 * BLOCK - 1, 3 * BLOCK + 7] {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut x = x0.clone();
                    x[at] = bad;
                    let mut out = vec![0.0; x.len()];
                    let mut st = MasingState::default();
                    let r = scaled_force(level, &c, 2.0, &x, &mut out, &mut st);
                    assert_eq!(r, Forces::BadInput, "level {}, at {at}", level.name());
                    let done = at / BLOCK * BLOCK;
                    let same = out[..done]
                        .iter()
                        .zip(&good)
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(same, "level {}, at {at}", level.name());
                }
            }
        }
    }
}
