use std::hint::black_box;
use std::time::Instant;

#[inline(never)]
fn scalar(t: &[f64], x: &[f64], f: &[f64], slope: f64, k_lo: f64, p_lo: f64, c_lo: f64, nbf: f64, g_hi: f64, st: &mut [f64; 9]) -> usize {
    let [mut s0, mut s1, mut s2, mut s3, mut s4, mut s5, mut cx, mut cf, mut cp] = *st;
    let mut i = 0;
    let n = t.len();
    while i < n {
        let ti = t[i];
        if ti >= 1e300 { break; }
        let ph = slope * (ti - k_lo) + p_lo;
        let frac = ph - c_lo;
        if frac * nbf >= g_hi { break; }
        let (xi, fi) = (x[i], f[i]);
        s0 += xi; s1 += fi; s2 += frac; s3 += frac * frac; s4 += xi * xi; s5 += ti;
        cx += xi; cf += fi; cp += frac;
        i += 1;
    }
    *st = [s0, s1, s2, s3, s4, s5, cx, cf, cp];
    i
}

#[inline(never)]
fn lanes(t: &[f64], x: &[f64], f: &[f64], slope: f64, k_lo: f64, p_lo: f64, c_lo: f64, nbf: f64, g_hi: f64, st: &mut [f64; 9]) -> usize {
    let mut s = [st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7]];
    let mut cp = st[8];
    let mut i = 0;
    let n = t.len();
    while i < n {
        let ti = t[i];
        if ti >= 1e300 { break; }
        let ph = slope * (ti - k_lo) + p_lo;
        let frac = ph - c_lo;
        if frac * nbf >= g_hi { break; }
        let (xi, fi) = (x[i], f[i]);
        let v = [xi, fi, frac, frac * frac, xi * xi, ti, xi, fi];
        for l in 0..8 { s[l] += v[l]; }
        cp += frac;
        i += 1;
    }
    *st = [s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], cp];
    i
}

fn main() {
    let n = 1_000_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let x: Vec<f64> = (0..n).map(|i| ((i as f64) * 0.001).sin()).collect();
    let f: Vec<f64> = (0..n).map(|i| ((i as f64) * 0.0013).cos()).collect();
    let mut best = [f64::MAX; 2];
    let mut res = [[0.0; 9]; 2];
    for _ in 0..30 {
        for k in 0..2 {
            let mut st = [0.0; 9];
            let t0 = Instant::now();
            let m = if k == 0 {
                scalar(black_box(&t), &x, &f, black_box(1.0), 0.0, 0.0, 0.0, 1.0, black_box(1e300), &mut st)
            } else {
                lanes(black_box(&t), &x, &f, black_box(1.0), 0.0, 0.0, 0.0, 1.0, black_box(1e300), &mut st)
            };
            let e = t0.elapsed().as_secs_f64();
            assert_eq!(m, n);
            best[k] = best[k].min(e);
            res[k] = st;
        }
    }
    let same = res[0].iter().zip(&res[1]).all(|(a, b)| a.to_bits() == b.to_bits());
    println!("scalar {:.3} ns/sample, lanes {:.3} ns/sample, bit-identical {}", best[0] / n as f64 * 1e9, best[1] / n as f64 * 1e9, same);
}
