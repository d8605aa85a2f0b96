//! AFL++ target: every public kernel of `contactlab-core` on bytes decoded as arbitrary f64
//! bit patterns (NaN, ±inf, denormals, ±0, 1e±300 included) and lengths 0..=64.
//!
//! Invariants (a violation aborts, which AFL++ records as a crash): no panic; when every
//! input is finite and the kernel returns `Ok`, its output holds no NaN. For the streaming
//! reversal detector, two chunks give what one pass gives and a failed push leaves the state
//! as it was; phase-fold counts agree between bins and cells; branch-memory indices point at
//! samples already seen.

use contactlab_core::normal::{
    cycles, poly, simulate, ContactModel, Forcing, Interp, KelvinVoigt, Options, Stiffness,
};
use contactlab_core::fold::{fold_phase, FoldSums};
use contactlab_core::loop_area::loop_areas;
use contactlab_core::reversal::Schmitt;
use contactlab_core::{
    branch_memory, cycle_energies, loop_area, masing_force, masing_force_rule, Backbone,
    BranchRule, Exponential, MasingState, Tabulated,
};

/// Decodes the fuzz input: bytes become choices and f64 values, zero-padded at the end.
struct Input<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Input<'_> {
    fn byte(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }
    fn f64(&mut self) -> f64 {
        // half the time one of the values kernels must survive, else any bit pattern
        const SPECIAL: [f64; 12] = [
            0.0, -0.0, 1.0, 1e-300, 5e-324, 1e300, f64::MAX, f64::NAN, f64::INFINITY, -1e300,
            2.0, 1e-12,
        ];
        let tag = self.byte();
        if tag & 1 == 0 {
            return SPECIAL[usize::from(tag >> 1) % SPECIAL.len()];
        }
        let mut b = [0u8; 8];
        for x in &mut b {
            *x = self.byte();
        }
        f64::from_le_bytes(b)
    }
    fn vec(&mut self) -> Vec<f64> {
        let n = usize::from(self.byte() % 65);
        (0..n).map(|_| self.f64()).collect()
    }
}

fn finite(xs: &[f64]) -> bool {
    xs.iter().all(|v| v.is_finite())
}

fn no_nan(what: &str, xs: &[f64]) {
    if let Some(i) = xs.iter().position(|v| v.is_nan()) {
        panic!("{what}[{i}] is NaN for finite input");
    }
}

fn masing<C: Backbone>(c: &C, scale: f64, x: &[f64], state: &[f64], ok_in: bool) {
    let mut st = MasingState::from_slice(state).unwrap_or_default();
    let mut out = vec![0.0; x.len()];
    if masing_force(c, scale, x, &mut out, &mut st).is_ok() && ok_in {
        no_nan("masing_force", &out);
        no_nan("state", &st.to_vec());
    }
    if let Ok(cy) = cycle_energies(c, scale, x, &mut MasingState::default()) {
        if ok_in {
            let e: Vec<f64> = cy.iter().map(|c| c.energy).collect();
            no_nan("cycle energy", &e);
        }
    }
    for &u in x {
        let v = [c.eval(u), c.slope(u), c.chord_area(u)];
        if ok_in {
            no_nan("backbone/slope/chord_area", &v);
        }
    }
}

fn one(data: &[u8]) {
    let mut b = Input { data, pos: 0 };
    let op = b.byte() % 11;
    let (p1, p2, p3) = (b.f64(), b.f64(), b.f64());
    let x = b.vec();
    let y = b.vec();
    let ok_in = finite(&[p1, p2, p3]) && finite(&x) && finite(&y);
    match op {
        0 => {
            if let Ok(c) = Exponential::new(p1, p2) {
                masing(&c, p3, &x, &y, ok_in);
            }
        }
        1 => {
            if let Ok(c) = Tabulated::new(&x, &y) {
                let z = b.vec();
                masing(&c, p3, &z, &[], ok_in && finite(&z));
            }
        }
        2 => {
            let n = x.len().min(y.len());
            if let Ok(a) = loop_area(&x[..n], &y[..n]) {
                if ok_in {
                    no_nan("loop_area", &[a]);
                }
            }
        }
        3 => {
            let stiff = match b.byte() % 3 {
                0 => Stiffness::Constant(p1),
                1 => Stiffness::Delta(y.clone()),
                _ => Stiffness::Pressure(y.clone()),
            };
            let (Ok(model), Ok(forcing)) = (
                ContactModel::new(stiff, p2, p3),
                Forcing::new(&x, &y, None, Interp::Cubic),
            ) else {
                return;
            };
            let opts = Options {
                rtol: b.f64(),
                atol: b.f64(),
                first_step: None,
                max_steps: 2000,
            };
            let d0 = b.f64();
            let mut d = vec![0.0; forcing.len()];
            let mut v = vec![0.0; forcing.len()];
            if let Ok(out) = simulate(&model, &forcing, d0, &opts, &mut d, &mut v) {
                if ok_in && out.status.code() == 0 && finite(&[opts.rtol, opts.atol, d0]) {
                    no_nan("simulate delta", &d);
                    no_nan("simulate velocity", &v);
                }
            }
            if let Ok(e) = model.equilibrium(p1) {
                if ok_in {
                    no_nan("equilibrium", &[e]);
                }
            }
        }
        4 => {
            if let Ok(kv) = KelvinVoigt::new(p1, p2, p3) {
                let mut d = vec![0.0; x.len()];
                let mut v = vec![0.0; x.len()];
                let pa = b.f64();
                if kv.steady_state(pa, &x, &mut d, &mut v).is_ok() && ok_in && pa.is_finite() {
                    no_nan("kv delta", &d);
                    no_nan("kv velocity", &v);
                    no_nan("kv analytic", &[kv.amplitude(pa), kv.phase(), kv.loop_energy(pa)]);
                }
            }
        }
        5 => {
            let n = x.len().min(y.len());
            let deg = usize::from(b.byte() % 12);
            if let Ok(c) = poly::fit(&x[..n], &y[..n], deg, None) {
                if ok_in {
                    no_nan("poly fit", &c);
                }
            }
            let r = poly::roots_in(&y, p1, p2, 64);
            let (xm, fm) = poly::min_on(&y, p1, p2);
            if ok_in && p1 < p2 {
                no_nan("roots_in", &r);
                no_nan("min_on", &[xm, fm]);
            }
        }
        6 => {
            let (nc, nb) = (usize::from(b.byte() % 9), usize::from(b.byte() % 65));
            let mut out = vec![0.0; nc * nb];
            if cycles::fold_cycles(&x, p1, p2, nc, nb, &mut out).is_ok() && ok_in {
                no_nan("fold_cycles", &out);
            }
        }
        7 => schmitt(&mut b, p1, p2, &x, &y, ok_in),
        8 => fold(&mut b, &x, &y, ok_in),
        9 => {
            // cycle bounds from bytes: any order, any value (beyond the signal too)
            let n = x.len().min(y.len());
            let bounds: Vec<usize> = (0..b.byte() % 9).map(|_| usize::from(b.byte())).collect();
            if let Ok(a) = loop_areas(&x[..n], &y[..n], &bounds) {
                assert_eq!(a.len(), bounds.len().saturating_sub(1), "loop_areas count");
                for (w, v) in bounds.windows(2).zip(&a) {
                    if ok_in && w[1] - w[0] >= 3 {
                        no_nan("loop_areas", &[*v]);
                    }
                }
            }
        }
        _ => rules(&mut b, p1, p2, p3, &x, &y, ok_in),
    }
}

/// The reversal detector: any centre/threshold, a value signal or none, pushed in two chunks
/// cut anywhere, must give what one pass gives (or the same error, leaving the state as is).
fn schmitt(b: &mut Input<'_>, centre: f64, thr: f64, x: &[f64], y: &[f64], ok_in: bool) {
    let Ok(mut one) = Schmitt::new(centre, thr) else {
        return;
    };
    let value = if b.byte() & 1 == 0 { None } else { Some(y) };
    let mut whole = Vec::new();
    let r1 = one.push(x, value, &mut whole);
    let cut = usize::from(b.byte()).min(x.len());
    let Ok(mut two) = Schmitt::new(centre, thr) else {
        return;
    };
    let before = two.clone();
    let mut parts = Vec::new();
    let head = value.map(|v| &v[..cut.min(v.len())]);
    match two.push(&x[..cut], head, &mut parts) {
        Ok(()) => {
            let tail = value.map(|v| &v[cut.min(v.len())..]);
            let r2 = two.push(&x[cut..], tail, &mut parts);
            if r1.is_ok() && r2.is_ok() {
                assert_eq!(whole, parts, "Schmitt: chunks differ from one pass");
                assert_eq!(one.open, two.open, "Schmitt: open excursion differs");
            }
        }
        Err(_) => assert_eq!(two, before, "Schmitt: a failed push changed the state"),
    }
    if ok_in && r1.is_ok() {
        for e in &whole {
            assert!(e.start <= e.extreme, "excursion extreme before its start");
            assert!(e.start <= e.last_beyond, "excursion ends before its start");
            no_nan("excursion extreme", &[e.extreme_value]);
        }
    }
}

/// Phase fold: knots from the input (often unsorted or out of range), any bin/cycle counts.
fn fold(b: &mut Input<'_>, x: &[f64], y: &[f64], ok_in: bool) {
    let n = x.len().min(y.len());
    let (nb, nc) = (usize::from(b.byte() % 17), usize::from(b.byte() % 9));
    let Ok(mut sums) = FoldSums::new(nb, nc) else {
        return;
    };
    let nk = usize::from(b.byte() % 6);
    let kt: Vec<f64> = (0..nk).map(|_| b.f64()).collect();
    let kp: Vec<f64> = (0..nk).map(|_| b.f64()).collect();
    let t: Vec<f64> = (0..n).map(|_| b.f64()).collect();
    let ok = ok_in && finite(&kt) && finite(&kp) && finite(&t);
    if fold_phase(&t, &x[..n], &y[..n], 0, &kt, &kp, &mut sums).is_ok() && ok {
        no_nan("fold count", &sums.count);
        no_nan("fold cycle count", &sums.cycle_count);
        let total: f64 = sums.count.iter().sum();
        let cells: f64 = sums.cycle_count.iter().sum();
        assert!(total <= n as f64 && (total - cells).abs() < 0.5, "fold counts disagree");
    }
}

/// The branch rules (scaled or anchored λ) and the branch memory on the same input: memory
/// indices point at samples up to the current one (or -1 / the mirror code `-1 - j`).
fn rules(b: &mut Input<'_>, p1: f64, p2: f64, lambda: f64, x: &[f64], y: &[f64], ok_in: bool) {
    let rule = if b.byte() & 1 == 0 {
        BranchRule::Scaled(lambda)
    } else {
        BranchRule::Anchored(lambda)
    };
    let mut st = MasingState::from_slice(y).unwrap_or_default();
    let st0 = st.clone();
    let mut out = vec![0.0; x.len()];
    if let Ok(c) = Exponential::new(p1, p2) {
        match masing_force_rule(&c, rule, x, &mut out, &mut st) {
            Ok(()) if ok_in => no_nan("masing_force_rule", &out),
            Ok(()) => {}
            Err(_) => assert_eq!(st, st0, "masing_force_rule: a failure changed the state"),
        }
    }
    let mut st = MasingState::default();
    let (mut anchor, mut target) = (vec![0_i64; x.len()], vec![0_i64; x.len()]);
    if branch_memory(x, &mut anchor, &mut target, &mut st).is_ok() {
        for (i, (&a, &t)) in anchor.iter().zip(&target).enumerate() {
            let i = i64::try_from(i).unwrap_or(i64::MAX);
            assert!((-1..=i).contains(&a), "branch_memory anchor {a} at {i}");
            assert!((-1 - i..=i).contains(&t), "branch_memory target {t} at {i}");
        }
    }
}

fn main() {
    afl::fuzz!(|data: &[u8]| {
        one(data);
    });
}
