//! Joint-law kernels (`contactlab_core::joints::Operator::push`: input checks, the law's
//! generic loop, the output check) against a plain Rust loop of the same law written out
//! here (no checks, no `Option` time, no trait), in the same run, on the same signal: a
//! 5 Hz sine of slowly varying amplitude plus a random walk, sampled at 10 kHz (reversals
//! of all sizes). Both sides write into a reused buffer; each is timed `--repeat` times,
//! alternately, and the median is reported (M samples/s), with the ratio plain/kernel (1.0:
//! the kernel is as fast as a bare loop) and the largest difference of their forces.
//!
//! Targets (issue 30): Dahl and LuGre >= 50 M samples/s, Maxwell-slip with 10 elements
//! >= 10 M samples/s, Iwan (Segalman) >= 20 M samples/s.
//!
//! Run: `cargo bench -p contactlab-core --bench joints` (`-- --n 2000000 --repeat 11`).

use contactlab_core::joints::{AnyLaw, Operator};
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

/// CPU time of this thread, s (`/proc/thread-self/schedstat`: nanoseconds on a CPU), so a
/// loaded machine's preemption does not count; `None` where the file is absent.
fn cpu_time() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// Wall and CPU seconds of `f`.
fn timed(f: impl FnOnce()) -> (f64, f64) {
    let c0 = cpu_time();
    let s = Instant::now();
    f();
    let wall = s.elapsed().as_secs_f64();
    let cpu = match (c0, cpu_time()) {
        (Some(a), Some(b)) => b - a,
        _ => wall,
    };
    (wall, cpu)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A xorshift generator (the bench needs no crate for its signal).
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The signal of `--signal <path>`: `2 n` little-endian f64, the times then the
/// displacements (written by `benches/speed_joints.py`, which times the Python path on the
/// same arrays).
fn signal_file() -> Option<(Vec<f64>, Vec<f64>)> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .iter()
        .position(|a| a == "--signal")
        .and_then(|i| args.get(i + 1))?;
    let bytes = std::fs::read(path).expect("--signal: cannot read the file");
    let v: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let (t, x) = v.split_at(v.len() / 2);
    Some((t.to_vec(), x.to_vec()))
}

fn signal(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut walk = 0.0;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let x = t
        .iter()
        .map(|&t| {
            walk += (rng.uniform() - 0.5) * 4e-7;
            let tau = std::f64::consts::TAU;
            1e-3 * (tau * 5.0 * t).sin() * (1.0 + 0.5 * (tau * 0.3 * t).sin()) + walk
        })
        .collect();
    (t, x)
}

fn plain_dahl(sigma0: f64, fc: f64, x: &[f64], out: &mut [f64]) {
    let a = sigma0 / fc;
    let (mut xp, mut f) = (0.0f64, 0.0f64);
    for (o, &xi) in out.iter_mut().zip(x) {
        let dx = xi - xp;
        xp = xi;
        if dx != 0.0 {
            let s = if dx > 0.0 { 1.0 } else { -1.0 };
            let y = 1.0 - s * f / fc;
            f = s * fc * (1.0 - y * (-a * dx.abs()).exp());
        }
        *o = f;
    }
}

fn plain_lugre(p: [f64; 6], t: &[f64], x: &[f64], out: &mut [f64]) {
    let [s0, s1, s2, fc, fs, vs] = p;
    let (mut xp, mut tp, mut z) = (0.0f64, f64::NAN, 0.0f64);
    for ((o, &xi), &ti) in out.iter_mut().zip(x).zip(t) {
        let dx = xi - xp;
        let (v, g) = if tp.is_nan() {
            (0.0, fs)
        } else {
            let v = dx / (ti - tp);
            let r = v / vs;
            let p = r * r;
            (
                v,
                if p > 48.0 {
                    fc
                } else {
                    fc + (fs - fc) * (-p).exp()
                },
            )
        };
        xp = xi;
        tp = ti;
        if dx != 0.0 {
            let zss = if dx > 0.0 { g / s0 } else { -g / s0 };
            z = zss + (z - zss) * (-s0 * dx.abs() / g).exp();
        }
        let zdot = v - s0 * v.abs() * z / g;
        *o = s0 * z + s1 * zdot + s2 * v;
    }
}

fn plain_maxwell(k: &[f64], fs: &[f64], x: &[f64], out: &mut [f64]) {
    let mut z = vec![0.0; k.len()];
    for (o, &xi) in out.iter_mut().zip(x) {
        let mut total = 0.0;
        for ((&k, &fs), z) in k.iter().zip(fs).zip(z.iter_mut()) {
            let f = k * (xi - *z);
            total += if f > fs {
                *z = xi - fs / k;
                fs
            } else if f < -fs {
                *z = xi + fs / k;
                -fs
            } else {
                f
            };
        }
        *o = total;
    }
}

/// Segalman's continuous Iwan model by Masing's rules with a reversal stack.
fn plain_segalman(f_s: f64, k_t: f64, chi: f64, beta: f64, x: &[f64], out: &mut [f64]) {
    let pm = f_s * (1.0 + beta) / (k_t * (beta + (chi + 1.0) / (chi + 2.0)));
    let r = f_s * (chi + 1.0) / (pm.powf(chi + 2.0) * (beta + (chi + 1.0) / (chi + 2.0)));
    let c = r / ((chi + 1.0) * (chi + 2.0));
    let n = chi + 2.0;
    let f = |u: f64| {
        let a = u.abs();
        let v = if a >= pm {
            f_s
        } else {
            k_t * a - c * a.powf(n)
        };
        if u >= 0.0 {
            v
        } else {
            -v
        }
    };
    let mut stack: Vec<(f64, f64)> = Vec::new();
    let (mut xp, mut fp, mut dir) = (0.0f64, 0.0f64, 0.0f64);
    for (o, &xi) in out.iter_mut().zip(x) {
        let dx = xi - xp;
        if dx != 0.0 {
            let s = if dx > 0.0 { 1.0 } else { -1.0 };
            if dir != 0.0 && s != dir {
                stack.push((xp, fp));
            }
            dir = s;
            loop {
                let m = stack.len();
                if m >= 2 && (xi - stack[m - 2].0) * s >= 0.0 {
                    stack.truncate(m - 2);
                } else if m == 1 && (xi + stack[0].0) * s >= 0.0 {
                    stack.clear();
                } else {
                    break;
                }
            }
            fp = match stack.last() {
                Some(&(xr, fr)) => fr + 2.0 * f(0.5 * (xi - xr)),
                None => f(xi),
            };
            xp = xi;
        }
        *o = fp;
    }
}

type Plain<'a> = Box<dyn Fn(&[f64], &mut [f64]) + 'a>;

fn main() {
    let repeat = arg("--repeat", 9).max(1);
    let (t, x) = signal_file().unwrap_or_else(|| signal(arg("--n", 2_000_000)));
    let n = x.len();
    let k10: Vec<f64> = (0..10).map(|i| 1e4 * (1.0 + 0.1 * i as f64)).collect();
    let fs10: Vec<f64> = (0..10).map(|i| 0.5 * (1.0 + i as f64)).collect();
    let mut p10 = k10.clone();
    p10.extend(&fs10);
    let lugre_p = [1e6, 300.0, 10.0, 4.0, 5.0, 1e-3];
    let cases: Vec<(&str, AnyLaw, bool, Plain, f64)> = vec![
        (
            "dahl",
            AnyLaw::build("dahl", &[1e4, 5.0, 1.0], vec![]).unwrap(),
            false,
            Box::new(|x, o| plain_dahl(1e4, 5.0, x, o)),
            50.0,
        ),
        (
            "lugre",
            AnyLaw::build("lugre", &[1e6, 300.0, 10.0, 4.0, 5.0, 1e-3, 2.0], vec![]).unwrap(),
            true,
            Box::new(|x, o| plain_lugre(lugre_p, &t, x, o)),
            50.0,
        ),
        (
            "maxwell_slip 10",
            AnyLaw::build("maxwell_slip", &p10, vec![]).unwrap(),
            false,
            Box::new(|x, o| plain_maxwell(&k10, &fs10, x, o)),
            10.0,
        ),
        (
            "segalman (exact)",
            AnyLaw::build("segalman", &[5.0, 1e4, -0.5, 0.2], vec![]).unwrap(),
            false,
            Box::new(|x, o| plain_segalman(5.0, 1e4, -0.5, 0.2, x, o)),
            20.0,
        ),
    ];
    println!(
        "{n} samples, median of {repeat} (M samples/s by CPU time of the thread; wall in brackets)"
    );
    println!(
        "{:<18} {:>10} {:>10} {:>10} {:>10} {:>7} {:>7} {:>9}",
        "law", "kernel", "(wall)", "plain", "(wall)", "ratio", "target", "max |dF|"
    );
    let mut out_k = vec![0.0; n];
    let mut out_p = vec![0.0; n];
    for (name, law, timed_law, plain, target) in cases {
        let (mut tk, mut tp, mut ck, mut cp) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for r in 0..repeat {
            let mut op = Operator::new(law.clone(), 0.0).unwrap();
            let ts = if timed_law { Some(&t[..]) } else { None };
            let mut run_kernel = |out: &mut [f64]| {
                timed(|| {
                    op.push(ts, black_box(&x), out).unwrap();
                    black_box(&out);
                })
            };
            let run_plain = |out: &mut [f64]| {
                timed(|| {
                    plain(black_box(&x), out);
                    black_box(&out);
                })
            };
            let (k, p) = if r % 2 == 0 {
                let k = run_kernel(&mut out_k);
                (k, run_plain(&mut out_p))
            } else {
                let p = run_plain(&mut out_p);
                (run_kernel(&mut out_k), p)
            };
            tk.push(k.0);
            ck.push(k.1);
            tp.push(p.0);
            cp.push(p.1);
        }
        let (mk, mp) = (median(tk), median(tp));
        let (mck, mcp) = (median(ck), median(cp));
        let diff = out_k
            .iter()
            .zip(&out_p)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!(
            "{:<18} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>7.2} {:>7.0} {:>9.1e}",
            name,
            n as f64 / mck / 1e6,
            n as f64 / mk / 1e6,
            n as f64 / mcp / 1e6,
            n as f64 / mp / 1e6,
            mcp / mck,
            target,
            diff
        );
    }
}
